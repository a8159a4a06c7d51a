"""Horizontal spindles (design.md §9.8, ``machine.spindle_axis`` "Y"/"X") against analytic geometry.

Convention under test (physics.SPINDLE_MOUNTS): the tool points along −spindle_axis from the
spindle nose (tip = A − L·axis, status tool_axis = +axis); the probe's own x, y, z at SPOS 0
are the a, o, p axes of the plane whose infeed is the spindle axis: Y spindle (G18) x = +Z,
y = +X, z = +Y; X spindle (G19) x = +Y, y = +Z, z = +X. SPOS φ turns the probe (eccentricity
and lobing) by +φ about +axis (right-hand rule), expected values from scipy rotations.
"""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from sim_helpers import circle_contact_inside, plane_contact, scenario

from app.machine.kinematics import Kinematics
from app.machine.sim import SimulatedMachine

L = 100.0
R_BALL = 2.0
XYZ = ("X", "Y", "Z")
ECC = (0.012, -0.005)
PRE = {"X+": 0.010, "X-": 0.002, "Y+": 0.004, "Y-": 0.007, "Z-": 0.003}
LIMITS = {"X": [-100, 1000], "Y": [-100, 800], "Z": [-500, 100]}
UNIT = {"X": np.array([1.0, 0.0, 0.0]), "Y": np.array([0.0, 1.0, 0.0]), "Z": np.array([0.0, 0.0, 1.0])}
# the probe's x and y at SPOS 0 in MCS (a, o of G18 resp. G19)
PROBE_XY = {"Y": (UNIT["Z"], UNIT["X"]), "X": (UNIT["Y"], UNIT["Z"])}
BLOCK_ORIGIN = np.array([300.0, 200.0, -150.0])
BLOCK = (200.0, 120.0, 60.0)


def _scenario(axis: str, frame: str | None = None, **overrides):
    probe = {"t": 9, "ball_diameter": 2 * R_BALL, "length": L, "max_deflection": 5.0,
             "eccentricity": list(ECC), "pretravel": PRE}
    if frame is not None:
        probe["pretravel_frame"] = frame
    data = {"machine": {"limits": LIMITS, "latency_s": 0.0, "time_scale": 0.0, "spindle_axis": axis},
            "probe": probe,
            "workpiece": {"pose": {"trans": list(BLOCK_ORIGIN), "rot": [0.0, 0.0, 0.0]},
                          "features": [{"type": "block", "size": list(BLOCK)}]},
            "start": None}
    data.update(overrides)
    return scenario(**data)


def _ecc_mcs(axis: str, spos: float) -> np.ndarray:
    px, py = PROBE_XY[axis]
    e0 = ECC[0] * px + ECC[1] * py
    return Rotation.from_rotvec(np.radians(spos) * UNIT[axis]).apply(e0)


@pytest.mark.parametrize("axis", ["Y", "X"])
@pytest.mark.parametrize("spos", [0.0, 90.0, 180.0, 33.0])
def test_ball_centre_and_tool_axis(axis, spos):
    kin = Kinematics(_scenario(axis))
    a = np.array([400.0, 300.0, -50.0])
    expected = a - L * UNIT[axis] + _ecc_mcs(axis, spos)
    assert kin.ball_centre(a, spos) == pytest.approx(expected, abs=1e-15)
    assert kin.tool_axis(a) == pytest.approx(UNIT[axis], abs=0)
    m = SimulatedMachine(_scenario(axis))
    m.change_tool(9, L)
    st = m.status()
    assert st.tool_axis == tuple(UNIT[axis])
    nose = np.array([st.mcs[k] for k in XYZ])
    assert np.array([st.wcs[k] for k in XYZ]) == pytest.approx(nose - L * UNIT[axis], abs=1e-12)


def test_the_default_start_retracts_along_the_spindle_axis():
    sc = _scenario("Y")
    assert sc.start_position() == {"X": 0.0, "Y": 800.0, "Z": 100.0}
    sc = _scenario("X")
    assert sc.start_position() == {"X": 1000.0, "Y": 0.0, "Z": 100.0}
    assert scenario(start=None).start_position()["Y"] == 0.0           # vertical: as before


def _probe_block_face(axis: str, spos: float, direction: np.ndarray, frame: str | None = None):
    """Probe along ``direction`` onto the axis-parallel block face it meets; (latched, axes0, s)."""
    sc = _scenario(axis, frame)
    m = SimulatedMachine(sc)
    m.spindle_position(spos)
    lx, ly, lz = BLOCK
    mid = BLOCK_ORIGIN + np.array([lx / 2, ly / 2, -lz / 2])
    half = np.array([lx / 2, ly / 2, lz / 2])
    n = -direction
    p_face = mid + n * half
    centre0 = p_face + (R_BALL + 5.0) * n
    axes0 = centre0 - _ecc_mcs(axis, spos) + L * UNIT[axis]
    # approach: retract along the spindle axis, cross, then in (no rapid through the part)
    m.goto({axis: float(sc.limits()[axis][1])})
    m.goto({k: float(v) for k, v in zip(XYZ, axes0, strict=True) if k != axis})
    m.goto({axis: float(axes0["XYZ".index(axis)])})
    r = m.probe(direction, 10.0, 300.0)
    assert r.triggered
    return np.array([r.latched_mcs[k] for k in XYZ]), axes0, plane_contact(centre0, direction, p_face, n, R_BALL)


# the pre-travel key of a machine direction at SPOS 0 and 90 (hand-derived from the mount)
KEYS_Y = {0.0: {"-Y": "Z-", "+X": "Y+", "-X": "Y-", "+Z": "X+", "-Z": "X-"},
          90.0: {"-Y": "Z-", "+X": "X+", "-X": "X-", "+Z": "Y-", "-Z": "Y+"}}
KEYS_X = {0.0: {"-X": "Z-", "+Y": "X+", "-Y": "X-", "+Z": "Y+", "-Z": "Y-"},
          90.0: {"-X": "Z-", "+Y": "Y-", "-Y": "Y+", "+Z": "X+", "-Z": "X-"}}


def _vec(name: str) -> np.ndarray:
    return (1.0 if name[0] == "+" else -1.0) * UNIT[name[1]]


@pytest.mark.parametrize("axis, keys", [("Y", KEYS_Y), ("X", KEYS_X)])
@pytest.mark.parametrize("spos", [0.0, 90.0])
def test_contacts_and_probe_frame_pretravel(axis, keys, spos):
    for name, key in keys[spos].items():
        if name == "+Z":
            continue                                   # the block stands on the table: nothing below it
        latched, axes0, s = _probe_block_face(axis, spos, _vec(name))
        pre = PRE.get(key, PRE["Z-"] if key == "Z+" else 0.0)
        assert latched == pytest.approx(axes0 + (s + pre) * _vec(name), abs=1e-12), name


@pytest.mark.parametrize("axis", ["Y", "X"])
def test_machine_frame_pretravel_stays_with_the_machine_axes(axis):
    for name in ("-" + axis, "+" + ("X" if axis == "Y" else "Y"), "-Z"):
        latched, axes0, s = _probe_block_face(axis, 90.0, _vec(name), frame="machine")
        key = f"{name[1]}{name[0]}"
        pre = PRE.get(key, PRE["Z-"] if key == "Z+" else 0.0)
        assert latched == pytest.approx(axes0 + (s + pre) * _vec(name), abs=1e-12), name


def test_ring_gauge_and_tool_probe_stand_along_the_spindle_axis():
    ring = {"center": [600.0, 300.0, -200.0], "diameter": 25.0, "height": 20.0}
    tp = {"center": [850.0, 300.0, -300.0], "disc_diameter": 20.0, "height": 40.0}
    sc = _scenario("Y", ring_gauge=ring, tool_probe=tp, tools=[{"t": 1, "length": 85.0, "radius": 5.0}],
                   probe={"t": 9, "ball_diameter": 4.0, "length": L, "max_deflection": 5.0})
    m = SimulatedMachine(sc)
    # the ball in the bore (the bore reaches from y = 300 back to y = 280), probing in X/Z
    centre = np.array([601.0, 290.0, -199.5])
    for ang in np.linspace(0.0, 2 * np.pi, 7)[:-1]:
        axes = centre + L * UNIT["Y"]
        m.goto({"Y": 800.0})
        m.goto({"X": float(axes[0]), "Z": float(axes[2])})
        m.goto({"Y": float(axes[1])})
        d = np.array([np.cos(ang), 0.0, np.sin(ang)])
        r = m.probe(d, 20.0, 300.0)
        s = circle_contact_inside(centre[[0, 2]], d[[0, 2]], np.array([600.0, -200.0]), 12.5 - R_BALL)
        assert np.array([r.latched_mcs[k] for k in XYZ]) == pytest.approx(axes + s * d, abs=1e-9)
    # the ring's front face from +Y beside the bore
    axes = np.array([600.0 + 20.0, 310.0, -200.0]) + L * UNIT["Y"]
    m.goto({"Y": 800.0})
    m.goto({"X": float(axes[0]), "Z": float(axes[2])})
    m.goto({"Y": float(axes[1])})
    r = m.probe([0, -1, 0], 20.0, 300.0)
    assert r.latched_mcs["Y"] == pytest.approx(axes[1] - (10.0 - R_BALL), abs=1e-9)
    # a cutter (tip = A − 85·ŷ) onto the tool probe's face along −Y, then onto its side along +X
    m.goto({"Y": 800.0})
    m.change_tool(1, 85.0)
    m.goto({"X": 850.0, "Z": -300.0})
    m.goto({"Y": 300.0 + 85.0 + 10.0})
    r = m.probe([0, -1, 0], 20.0, 300.0)
    assert r.latched_mcs["Y"] == pytest.approx(300.0 + 85.0, abs=1e-9)
    m.goto({"Y": 800.0})
    m.goto({"X": 850.0 - 10.0 - 5.0 - 8.0, "Z": -300.0})
    m.goto({"Y": 300.0 - 10.0 + 85.0})
    r = m.probe([1, 0, 0], 20.0, 300.0)
    assert r.latched_mcs["X"] == pytest.approx(850.0 - 10.0 - 5.0, abs=1e-9)
    circles = {c["kind"]: c for c in m.scene_geometry()["circles"]}
    assert circles["ring_bore"]["axis"] == [0.0, 1.0, 0.0] and circles["tool_probe"]["axis"] == [0.0, 1.0, 0.0]


def test_machine_view_and_retract_follow_the_spindle_axis():
    m = SimulatedMachine(_scenario("X"))
    geo = m.scene_geometry()
    assert geo["probe"]["axis"] == [1.0, 0.0, 0.0]
    st = m.status()
    nose = np.array([st.mcs[k] for k in XYZ])
    assert geo["probe"]["tip"] == pytest.approx(nose - L * UNIT["X"] + _ecc_mcs("X", 0.0), abs=1e-12)
    m.goto({"X": 500.0})
    assert m.retract_tool_axis(50.0).mcs["X"] == pytest.approx(550.0)
    assert m.retract_tool_axis().mcs["X"] == pytest.approx(1000.0)


def test_spindle_axis_validation():
    with pytest.raises(ValueError, match="machine.spindle_axis"):
        scenario(machine={"spindle_axis": "W"})
    with pytest.raises(ValueError, match="machine.spindle_axis"):
        scenario(machine={"spindle_axis": "y"})
    with pytest.raises(ValueError, match="machine.spindle_axis"):
        scenario(machine={"spindle_axis": "Y", "kinematics": {"type": "swivel_head", "axes": ["A", "B"]}},
                 rotary_axes={"A": {}, "B": {}})
    assert scenario().machine.spindle_axis == "Z"

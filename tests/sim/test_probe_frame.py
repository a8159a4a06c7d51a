"""Pre-travel in the probe's own frame (design.md §9.8): the lobing turns with SPOS like the eccentricity.

Convention under test (physics.probe_rotation): the probe frame -> MCS is R = R_head·M·Rz(φ),
φ = SPOS counter-clockwise about the spindle axis seen from the spindle (the eccentricity's
e(φ) = Rz(φ)·e_true); a travel d in MCS reads Rᵀ·d in the probe's frame and its pre-travel is
p(Rᵀ·d) = Σ (Rᵀd)_i²·p(axis_i, sign). So at SPOS 90° the probe's +X points along machine +Y: a
move along machine +Y switches after p(X+), a move along machine +X after p(Y−).
Expected values here come from hand-written tables and scipy rotations, not the simulator.
"""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from sim_helpers import plane_contact, scenario

from app.machine.physics import pretravel_along, pretravel_in_probe, probe_rotation
from app.machine.sim import SimulatedMachine

L = 100.0
R_BALL = 2.0
XYZ = ("X", "Y", "Z")
PRE = {"X+": 0.010, "X-": 0.002, "Y+": 0.004, "Y-": 0.007, "Z-": 0.001}
ECC = np.array([0.012, -0.005])
BLOCK_ORIGIN = np.array([300.0, 200.0, -150.0])        # top-front-left corner, block not turned
BLOCK = (200.0, 120.0, 60.0)

# SPOS -> machine travel direction -> the probe's own direction it is in (which key acts)
KEY_AT = {
    0.0: {"+X": "X+", "+Y": "Y+", "-X": "X-", "-Y": "Y-"},
    90.0: {"+X": "Y-", "+Y": "X+", "-X": "Y+", "-Y": "X-"},
    180.0: {"+X": "X-", "+Y": "Y-", "-X": "X+", "-Y": "Y+"},
    270.0: {"+X": "Y+", "+Y": "X-", "-X": "Y-", "-Y": "X+"},
}
UNIT = {"+X": (1.0, 0.0), "-X": (-1.0, 0.0), "+Y": (0.0, 1.0), "-Y": (0.0, -1.0)}


def _scenario(frame: str | None = None, ecc=ECC):
    probe = {"t": 9, "ball_diameter": 2 * R_BALL, "length": L, "max_deflection": 5.0,
             "pretravel": PRE, "eccentricity": list(ecc)}
    if frame is not None:
        probe["pretravel_frame"] = frame
    return scenario(probe=probe, workpiece={"pose": {"trans": list(BLOCK_ORIGIN), "rot": [0.0, 0.0, 0.0]},
                                            "features": [{"type": "block", "size": list(BLOCK)}]})


def _face(direction: str) -> tuple[np.ndarray, np.ndarray]:
    """The block face a move in ``direction`` meets from outside: a point on it (mid-height) and
    its outward normal."""
    lx, ly, lz = BLOCK
    mid = BLOCK_ORIGIN + np.array([lx / 2, ly / 2, -lz / 2])
    u = np.array([*UNIT[direction], 0.0])
    half = np.array([lx / 2, ly / 2, 0.0])
    return mid - u * half, -u


def _travel(m, axes) -> None:
    """Across above everything, then down (a straight rapid through the block is a collision)."""
    m.goto({"X": float(axes[0]), "Y": float(axes[1])})
    m.goto({"Z": float(axes[2])})


def _probe(sc, spos: float, direction: str, gap: float = 5.0):
    """Probe ``direction`` onto its face from ``gap`` mm; (latched axes, start axes, s_contact)."""
    m = SimulatedMachine(sc)
    m.spindle_position(spos)
    e = Rotation.from_euler("z", spos, degrees=True).apply([*sc.probe.eccentricity, 0.0])
    p_face, n = _face(direction)
    centre0 = p_face + (R_BALL + gap) * n
    axes0 = centre0 - e + np.array([0.0, 0.0, L])
    _travel(m, axes0)
    d = -n
    r = m.probe(d, 3 * gap, 300.0)
    assert r.triggered
    return np.array([r.latched_mcs[a] for a in XYZ]), axes0, plane_contact(centre0, d, p_face, n, R_BALL), d


@pytest.mark.parametrize("spos", [0.0, 90.0, 180.0, 270.0])
@pytest.mark.parametrize("direction", ["+X", "-X", "+Y", "-Y"])
def test_switch_positions_follow_the_turned_lobing(spos, direction):
    latched, axes0, s_contact, d = _probe(_scenario(), spos, direction)
    expected = axes0 + (s_contact + PRE[KEY_AT[spos][direction]]) * d
    assert latched == pytest.approx(expected, abs=1e-12)


@pytest.mark.parametrize("spos", [0.0, 90.0, 180.0, 270.0])
@pytest.mark.parametrize("direction", ["+X", "-X", "+Y", "-Y"])
def test_machine_frame_keeps_the_wave_1_model(spos, direction):
    latched, axes0, s_contact, d = _probe(_scenario("machine"), spos, direction)
    key = {"+X": "X+", "-X": "X-", "+Y": "Y+", "-Y": "Y-"}[direction]
    assert latched == pytest.approx(axes0 + (s_contact + PRE[key]) * d, abs=1e-12)


def test_the_default_is_the_probe_frame():
    assert _scenario().probe.pretravel_frame == "probe"
    assert scenario().probe.pretravel_frame == "probe"


def test_180_degrees_swaps_plus_and_minus_the_0_180_difference_is_2k():
    """The 0°/180° pair sees δ+ and δ− swapped: their difference is 2k = δ+ − δ− per axis."""
    sc = _scenario(ecc=(0.0, 0.0))
    for direction, axis in (("+X", "X"), ("+Y", "Y")):
        at0, _, _, d = _probe(sc, 0.0, direction)
        at180, _, _, _ = _probe(sc, 180.0, direction)
        assert (at0 - at180) @ d == pytest.approx(PRE[f"{axis}+"] - PRE[f"{axis}-"], abs=1e-12)


def test_axial_pretravel_does_not_turn():
    sc = _scenario()
    lx, ly, _ = BLOCK
    top = BLOCK_ORIGIN + np.array([lx / 2, ly / 2, 0.0])
    for spos in (0.0, 37.0, 90.0, 180.0, 270.0):
        m = SimulatedMachine(sc)
        m.spindle_position(spos)
        e = Rotation.from_euler("z", spos, degrees=True).apply([*ECC, 0.0])
        axes0 = top + np.array([0.0, 0.0, R_BALL + 5.0 + L]) - e
        _travel(m, axes0)
        r = m.probe([0, 0, -1], 10.0, 300.0)
        assert r.latched_mcs["Z"] == pytest.approx(axes0[2] - 5.0 - PRE["Z-"], abs=1e-12)


@pytest.mark.parametrize("spos", [0.0, 30.0, 90.0, 135.0, 200.0])
def test_oblique_travel_weights_the_probe_components(spos):
    """p(d) with d in the probe's frame: Σ d_i²·p(axis_i, sign d_i), d_probe = Rz(−φ)·d."""
    theta = 20.0                                       # travel angle in the machine XY plane
    d = np.array([math.cos(math.radians(theta)), math.sin(math.radians(theta)), 0.0])
    a = math.radians(theta - spos)                     # the travel angle seen by the probe
    cx, cy = math.cos(a), math.sin(a)
    expected = cx**2 * PRE["X+" if cx > 0 else "X-"] + cy**2 * PRE["Y+" if cy > 0 else "Y-"]
    assert pretravel_in_probe(d, PRE, probe_rotation(spos)) == pytest.approx(expected, abs=1e-15)


def test_oblique_latch_on_a_face_uses_the_turned_lobing():
    sc = _scenario()
    spos, theta = 90.0, 25.0
    m = SimulatedMachine(sc)
    m.spindle_position(spos)
    e = Rotation.from_euler("z", spos, degrees=True).apply([*ECC, 0.0])
    p_face, n = _face("+X")                            # the left face x = 300, normal −X
    d = np.array([math.cos(math.radians(theta)), math.sin(math.radians(theta)), 0.0])
    centre0 = p_face + (R_BALL + 4.0) * n
    axes0 = centre0 - e + np.array([0.0, 0.0, L])
    _travel(m, axes0)
    r = m.probe(d, 20.0, 300.0)
    a = math.radians(theta - spos)                     # (0.423, −0.906): X+ and Y−
    pre = math.cos(a) ** 2 * PRE["X+"] + math.sin(a) ** 2 * PRE["Y-"]
    expected = axes0 + (plane_contact(centre0, d, p_face, n, R_BALL) + pre) * d
    assert np.array([r.latched_mcs[k] for k in XYZ]) == pytest.approx(expected, abs=1e-12)


def test_swivel_head_and_spos_turn_the_lobing_together():
    head = Rotation.from_euler("y", -30.0, degrees=True).as_matrix()
    rng = np.random.default_rng(4)
    for spos in (0.0, 90.0, 33.0):
        turn = Rotation.from_euler("z", spos, degrees=True).as_matrix()
        for _ in range(10):
            d = rng.normal(size=3)
            d /= np.linalg.norm(d)
            d_probe = turn.T @ head.T @ d
            expected = pretravel_along(d_probe, PRE)
            assert pretravel_in_probe(d, PRE, probe_rotation(spos, None, head)) == pytest.approx(expected, abs=1e-15)

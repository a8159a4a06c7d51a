"""Probe physics through the API (design.md §9.8): any corner on prism parts, planes and spindle
axes, the calibration state of the probe. Truth from the scenario (truthkit, own numpy)."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
from truthkit import Operator, frame_of, scenario

from engine import alarms

DEPTH = -10.0


def prism_part(corner_deg: float, rot_z: float = 7.0) -> dict:
    """A prism whose front-left corner (part origin) has ``corner_deg`` between the front edge
    (+x) and the left edge; the part turned by ``rot_z`` about Z."""
    x4 = 120.0 / math.tan(math.radians(corner_deg))
    data = scenario(rot=(0.0, 0.0, rot_z))
    data["workpiece"]["features"] = [{"type": "prism", "polygon": [[0, 0], [200, 0], [200, 120], [x4, 120]],
                                      "height": 60.0}]
    return copy.deepcopy(data)


@pytest.mark.parametrize("corner_deg", [60.0, 75.0, 105.0, 120.0])
def test_any_corner_is_exact_on_prisms(client, corner_deg):
    op = Operator(client, prism_part(corner_deg))
    op.load()
    op.put_offset("G54", trans=(0.0, 0.0, -7.0))
    op.activate("G500")
    cot = 1.0 / math.tan(math.radians(corner_deg))
    starts = [(20.0, -8.0, DEPTH), (90.0, -8.0, DEPTH),                    # front edge, probing +Y
              (30.0 * cot - 10.0, 30.0, DEPTH), (80.0 * cot - 10.0, 80.0, DEPTH)]   # slanted edge, +X
    answer = op.measure("corner.any", {"kind": "outside", "position": 1, "setpoint": {"X": 0.0, "Y": 0.0}},
                        [op.part.mcs(*s) for s in starts], target="G54")
    assert answer["result"]["corner_angle"] == pytest.approx(corner_deg, abs=1e-6)
    g54 = op.frame("G54")
    corner = op.part.mcs(0.0, 0.0, DEPTH)
    assert np.allclose(g54.to_child(corner)[:2], [0.0, 0.0], atol=1e-6)
    front = g54.dir_to_child(op.part.dir_mcs([1.0, 0.0, 0.0]))
    assert abs(front[1]) < 1e-8                                           # the front edge is G54's X
    assert g54.T[2] == pytest.approx(-7.0, abs=1e-12)


def test_a_plane_whose_infeed_is_not_the_spindle_axis_is_refused(client):
    op = Operator(client, scenario(rot=(0.0, 0.0, 0.0)))
    op.load()
    op.activate("G500")
    op.ok(op.c.put("/api/settings", json={"plane": "G18"}))
    op.ball_to(op.part.mcs(40.0, -12.0, DEPTH))
    session = op.create("edge.set", {"axis": "Y", "direction": "+", "setpoint": 0.0}, "G54")
    machine = op.ok(op.c.get("/api/machine"))
    before = (op.ok(op.c.get("/api/offsets")), op.ok(op.c.get("/api/log")))
    body = op.ok(op.c.post(f"/api/measure/{session['id']}/start", json={}), 409)
    assert body["error"]["message"].startswith(str(alarms.PROBE_PLANE.number))
    assert "spindle axis" in body["error"]["message"]
    assert op.ok(op.c.get("/api/machine"))["mcs"] == machine["mcs"]            # nothing moved
    assert (op.ok(op.c.get("/api/offsets")), op.ok(op.c.get("/api/log"))) == before


@pytest.mark.parametrize("change,code", [({"calibrated_planes": ["G19"]}, alarms.NOT_CALIBRATED_IN_PLANE.number),
                                         ({"calibrated_spindle_angle": 180.0}, None)])
def test_a_probe_calibrated_elsewhere_is_refused(client, change, code):
    op = Operator(client, scenario(rot=(0.0, 0.0, 0.0)))
    op.load()
    record = op.ok(op.c.get("/api/probes/1"))
    op.ok(op.c.put("/api/probes/1", json={**record, "calibrated_radius": True, "calibrated_planes": ["G17"],
                                          "calibrated_spindle_angle": 0.0, "tool": 9, **change}))
    op.ball_to(op.part.mcs(40.0, -12.0, DEPTH))
    session = op.create("edge.set", {"axis": "Y", "direction": "+", "setpoint": 0.0}, "measure_only")
    body = op.ok(op.c.post(f"/api/measure/{session['id']}/start", json={}), 409)
    if code is None:
        assert body["error"]["code"] == "spindle_orientation"
    else:
        assert body["error"]["message"].startswith(str(code))


# --- a horizontal spindle: G18 measures exactly --------------------------------------------------------

def horizontal(axis: str) -> dict:
    data = scenario(rot=(0.0, 0.0, 0.0))
    data["machine"]["spindle_axis"] = axis
    data["machine"]["limits"] = {"X": [-100, 1000], "Y": [-100, 800], "Z": [-500, 100]}
    data.pop("ring_gauge", None)
    data["start"] = {"X": 600.0, "Y": 600.0, "Z": 0.0} if axis == "Y" else {"X": 700.0, "Y": 100.0, "Z": 0.0}
    return copy.deepcopy(data)


def tip_to(op: Operator, axis: str, p) -> None:
    """Ball centre to ``p`` (MCS): back along the spindle axis first, across, then in."""
    unit = {"X": np.array([1.0, 0, 0]), "Y": np.array([0, 1.0, 0])}[axis]
    here = np.array([op.ok(op.c.get("/api/machine"))["mcs"][a] for a in "XYZ"])
    target = np.asarray(p, float) + 100.0 * unit                       # axes = tip + L·axis
    back = {axis: float(max(here["XYZ".index(axis)], target["XYZ".index(axis)]) + 50.0)}
    for move in (back, {a: float(target[i]) for i, a in enumerate("XYZ") if a != axis},
                 {axis: float(target["XYZ".index(axis)])}):
        op.ok(op.c.post("/api/machine/goto", json={**move, "coords": "MCS"}))


def test_g18_on_a_y_spindle_is_exact(client):
    """Block (200 × 120 × 60) at (250, 150, −120): its back face y = 120 (MCS Y 270) faces the
    Y spindle. Set edge along −Y and a right-angled corner in the plane (Z, X) of G18."""
    op = Operator(client, horizontal("Y"))
    op.load()
    op.ok(op.c.put("/api/settings", json={"plane": "G18"}))
    op.activate("G500")
    tip_to(op, "Y", [300.0, 290.0, -150.0])
    session = op.create("edge.set", {"axis": "Y", "direction": "-", "setpoint": 0.0}, "G54")
    answer = op.ok(op.c.post(f"/api/measure/{session['id']}/start", json={}))
    assert answer["result"]["position"]["Y"] == pytest.approx(270.0, abs=1e-9)
    assert frame_of(op.offset("G54")).T[1] == pytest.approx(270.0, abs=1e-9)


def test_g19_on_an_x_spindle_is_exact(client):
    """The block's right face x = 200 (MCS X 450) faces the X spindle; set edge along −X in G19."""
    op = Operator(client, horizontal("X"))
    op.load()
    op.ok(op.c.put("/api/settings", json={"plane": "G19"}))
    op.activate("G500")
    tip_to(op, "X", [470.0, 200.0, -150.0])
    session = op.create("edge.set", {"axis": "X", "direction": "-", "setpoint": 5.0}, "G54")
    answer = op.ok(op.c.post(f"/api/measure/{session['id']}/start", json={}))
    assert answer["result"]["position"]["X"] == pytest.approx(450.0, abs=1e-9)
    assert frame_of(op.offset("G54")).T[0] == pytest.approx(445.0, abs=1e-9)


# --- fits with more points (design.md §9.8) ---------------------------------------------------------

def kinked_part(peak: float = 0.05) -> dict:
    """The front edge rises by ``peak`` to its middle and falls again (a worn or warped edge)."""
    data = scenario(rot=(0.0, 0.0, 0.0))
    data["workpiece"]["features"] = [{"type": "prism", "polygon": [[0, 0], [100, peak], [200, 0], [200, 120],
                                                                   [0, 120]], "height": 60.0}]
    return copy.deepcopy(data)


XS = (20.0, 60.0, 100.0, 140.0, 180.0)


def test_an_edge_of_five_points_reports_its_form_error(client):
    op = Operator(client, kinked_part())
    op.load()
    op.activate("G500")
    params = {"axis": "Y", "direction": "+", "reference_axis": "X", "points": 5}
    answer = op.measure("edge.align", params, [op.part.mcs(x, -8.0, DEPTH) for x in XS], target="measure_only")
    result = answer["result"]
    surface = [0.05 * min(x, 200.0 - x) / 100.0 for x in XS]          # the kinked edge under each point
    assert result["form_error"] == pytest.approx(max(surface) - min(surface), abs=2e-6)
    assert len(result["residuals"]) == 5
    assert result["angle"] == pytest.approx(0.0, abs=1e-6)            # symmetric: the mean line is the axis


def test_max_form_error_refuses_the_write(client):
    op = Operator(client, kinked_part())
    op.load()
    op.activate("G500")
    params = {"axis": "Y", "direction": "+", "reference_axis": "X", "points": 5, "max_form_error": 0.01}
    session = op.create("edge.align", params, "G54")
    for n, x in enumerate(XS, start=1):
        op.ball_to(op.part.mcs(x, -8.0, DEPTH))
        op.start(session["id"], point=n)
    before = (op.offset("G54"), op.ok(op.c.get("/api/log")))
    body = op.ok(op.c.post(f"/api/measure/{session['id']}/calculate"), 409)
    assert body["error"]["code"] == "form_error" and body["error"]["field"] == "max_form_error"
    # nothing written; the refusal keeps its measurement in the answer and in the log (design.md §10.2)
    surface = [0.05 * min(x, 200.0 - x) / 100.0 for x in XS]
    log = op.ok(op.c.get("/api/log"))
    assert op.offset("G54") == before[0] and log[1:] == before[1]
    assert log[0]["status"] == "refused form_error" and log[0]["correction"] is None
    for kept in (body["error"]["result"], log[0]["result"]):
        assert kept["form_error"] == pytest.approx(max(surface) - min(surface), abs=2e-6)


def test_orient_plane_with_five_points(client):
    op = Operator(client, scenario(rot=(1.5, -2.0, 0.0)))
    op.load()
    op.activate("G500")
    starts = [op.part.mcs(x, y, 8.0) for x, y in ((60, 15), (140, 15), (140, 105), (60, 105), (100, 100))]
    answer = op.measure("plane.align", {"points": 5}, starts, target="measure_only")
    assert answer["result"]["alpha"] == pytest.approx(1.5, abs=1e-6)
    assert answer["result"]["beta"] == pytest.approx(-2.0, abs=1e-6)
    assert answer["result"]["form_error"] == pytest.approx(0.0, abs=1e-9)


def test_verify_probes_again_in_the_new_wcs(client):
    op = Operator(client, scenario(rot=(0.0, 0.0, 4.0)))
    op.load()
    op.put_offset("G54", trans=(1.0, 2.0, 0.0))
    op.activate("G54")
    op.ball_to(op.part.mcs(30.3, 24.8, -8.0))                         # in hole 1 (truthkit HOLES[0])
    session = op.create("hole.1", {"diameter": 12.0, "verify": True, "setpoint": {"X": 5.0, "Y": -3.0}}, "G54")
    answer = op.ok(op.c.post(f"/api/measure/{session['id']}/start", json={}))
    verify = answer["verify"]
    assert verify["ok"] is True and verify["wcs"] == "G54"
    assert verify["remaining"]["X"] == pytest.approx(0.0, abs=1e-9)
    assert verify["remaining"]["Y"] == pytest.approx(0.0, abs=1e-9)


def test_verify_into_an_inactive_wo_checks_in_that_frame(client):
    """design.md §10.2: G54 active, G55 written (set-up support: inactive WO). The check probes the
    hole again in G54 and expresses it in G55 as stored now: the remaining deviation is what the
    written G55 leaves, 0 on a noise-free probe; the truth is the hole's centre from the scenario
    taken into G55 by the test's own frame arithmetic."""
    op = Operator(client, scenario(rot=(0.0, 0.0, 4.0)))
    op.load()
    op.put_offset("G54", trans=(1.0, 2.0, 0.0))
    op.put_offset("G55", trans=(-3.0, 7.0, 0.5), rot=(0.0, 0.0, 1.5))
    op.activate("G54")
    op.ball_to(op.part.mcs(30.3, 24.8, -8.0))                         # in hole 1 (truthkit HOLES[0])
    params = {"diameter": 12.0, "verify": True, "setpoint": {"X": 5.0, "Y": -3.0}}
    answer = op.start(op.create("hole.1", params, "G55")["id"])
    assert answer["setup_support"] is not None and answer["activated"] is False
    assert op.ok(op.c.get("/api/machine"))["active_offset"] == "G54"
    truth = op.wcs_pose("G55").to_child(op.part.mcs(30.0, 25.0, -8.0))
    assert truth[:2] == pytest.approx([5.0, -3.0], abs=1e-9)         # G55 was written right ...
    verify = answer["verify"]                                          # ... and the check says so
    assert verify["ok"] is True and verify["wcs"] == "G55" and verify["measured_in"] == "G54"
    assert verify["remaining"] == {"X": pytest.approx(0.0, abs=1e-9), "Y": pytest.approx(0.0, abs=1e-9)}


def test_verify_is_never_silent(client):
    op = Operator(client, scenario(rot=(0.0, 0.0, 4.0)))
    op.load()
    op.activate("G54")
    op.ball_to(op.part.mcs(30.3, 24.8, -8.0))
    answer = op.start(op.create("hole.1", {"diameter": 12.0, "verify": True}, "measure_only")["id"])
    assert answer["verify"] == {"skipped": "measure only: nothing was written to check"}


def test_points_and_verify_only_where_they_fit(client):
    op = Operator(client, scenario())
    op.load()
    for task, params, field in (("corner.right", {"points": 5}, "points"), ("edge.align", {"points": 1}, "points"),
                                ("edge.align", {"points": 13}, "points"), ("corner.right", {"verify": True}, "verify")):
        body = op.ok(op.c.post("/api/measure", json={"task": task, "params": params}), 400)
        assert body["error"]["field"] == field


# --- the calibrated set-up reaches the noise (bench/bench_setup_noise.py prints 30 seeds) -------------

@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_calibrated_setup_within_2um_and_10urad(tmp_path, seed):
    """The design.md §4 example probe (eccentricity, X+ ≠ X− and Y+ ≠ Y− pre-travel turning with
    the probe, 4 ms latency, 0.3 µm noise, wrong nominal length), the part turned 12.5°."""
    from flowkit import Flow, cal_scenario, make_client

    sc = cal_scenario(seed=seed, workpiece__pose={"trans": [250.0, 150.0, -120.0], "rot": [0.0, 0.0, 12.5]})
    with make_client(tmp_path, sc) as client:
        flow = Flow(client, sc)
        flow.calibrate_radius()
        flow.calibrate_length()
        flow.corner_and_z_setup()
        _t, angle, dt = flow.offset_error("G54")
    assert np.linalg.norm(dt) < 0.002 and angle < 10e-6

"""Calibration that does not trust what it can measure (issue [probe-health] item 5), through the
JSON API and the MDA screen's API, against the scenario's truth (flowkit.CAL_SCENARIO).

- a ball entered 0.1 mm small (the tool data) leaves hole and edge at the noise: the ring chords
  measure the ball (the issue measured 12.4 µm hole and 6.2 µm edge error before);
- whether the pre-travel turns with the spindle is decided from the 0°/180° passes (setting
  ``pretravel_frame`` "auto"): the set-up reaches the noise in both simulator models;
- a probe whose length is uncalibrated warns with alarm 65120 on every path (screen/API, a
  cycle in a program) or is refused (setting ``calibration_invalid`` "refuse"): nothing moves,
  nothing is written. The Z error it warns about is the nominal/true length difference.
"""

from __future__ import annotations

import numpy as np
import pytest
from flowkit import Flow, cal_scenario, make_client, ok

NOISE = 0.0003
HOLE, HOLE_D = (100.0, 60.0), 20.0


def part_with_hole(**changes) -> dict:
    sc = cal_scenario(**changes)
    sc["workpiece"]["pose"] = {"trans": [250.0, 150.0, -120.0], "rot": [0.0, 0.0, 0.0]}
    sc["workpiece"]["features"] = [{"type": "block", "size": [200, 120, 60]},
                                   {"type": "hole", "center": list(HOLE), "diameter": HOLE_D, "depth": 30.0}]
    return sc


def hole_and_edge(flow: Flow) -> tuple[dict, float]:
    """Hole 1 and set edge X+ on the part's left face (x = 0), measure only, in G54 = the pose."""
    pose = flow.sc["workpiece"]["pose"]
    ok(flow.c.put("/api/offsets/G54", json={"trans": dict(zip("XYZ", pose["trans"], strict=True)),
                                            "rot": {"X": 0.0, "Y": 0.0, "Z": 0.0}}))
    flow.activate("G54")
    flow.travel(HOLE[0] + 0.4, HOLE[1] - 0.3, -8.0, safe_z=20.0)
    hole = flow.start(flow.create("hole.1", {"diameter": HOLE_D}, "measure_only")["id"])["result"]
    flow.goto(z=20.0)
    flow.travel(-12.0, 30.0, -6.0, safe_z=20.0)
    edge = flow.start(flow.create("edge.set", {"axis": "X", "direction": "+", "setpoint": 0.0}, "measure_only")["id"])
    flow.goto(z=20.0)
    flow.activate("G500")
    return hole, edge["result"]["position"]["X"]


def test_a_ball_entered_wrong_changes_nothing_beyond_the_noise(tmp_path):
    sc = part_with_hole(probe__nominal={"length": 100.2, "ball_diameter": 3.9})
    with make_client(tmp_path, sc) as client:
        flow = Flow(client, sc)
        cal = flow.calibrate_radius()["result"]
        flow.calibrate_length()
        hole, edge_x = hole_and_edge(flow)
        record = ok(client.get("/api/probes/1"))
    assert cal["ball_diameter"]["measured"] is True
    assert cal["ball_diameter"]["value"] == pytest.approx(sc["probe"]["ball_diameter"], abs=0.01)
    assert record["measured_ball_diameter"] == pytest.approx(sc["probe"]["ball_diameter"], abs=0.01)
    assert record["ball_diameter"] == 3.9                        # what was entered stays as entered
    assert abs(hole["diameter"] - HOLE_D) < 5 * NOISE             # was 12.4 µm
    assert np.hypot(hole["center"]["X"] - HOLE[0], hole["center"]["Y"] - HOLE[1]) < 5 * NOISE
    assert abs(edge_x) < 5 * NOISE                                # was 6.2 µm


@pytest.mark.parametrize("frame", ["probe", "machine"])
def test_the_ring_passes_decide_whether_the_pretravel_turns(tmp_path, frame):
    """Setting "auto" (default): the example probe's asymmetric pre-travel, either model of the
    simulator; the corner + Z set-up into G54 then reaches 2 µm / 10 µrad (it missed by 3.3×/6.2×
    the noise bound with the setting the other way)."""
    sc = cal_scenario(seed=1, probe__pretravel_frame=frame,
                      workpiece__pose={"trans": [250.0, 150.0, -120.0], "rot": [0.0, 0.0, 12.5]})
    with make_client(tmp_path, sc) as client:
        flow = Flow(client, sc)
        assert ok(client.get("/api/settings"))["pretravel_frame"] == "auto"
        answer = flow.calibrate_radius()
        decision = answer["result"]["pretravel_frame_decision"]
        assert decision["decided"] is True and decision["frame"] == frame
        assert answer["result"]["pretravel_frame"] == frame
        assert not any("cannot tell" in w for w in answer["warnings"])
        assert ok(client.get("/api/probes/1"))["pretravel_frame"] == frame
        flow.calibrate_length()
        flow.corner_and_z_setup()
        _t, angle, dt = flow.offset_error("G54")
    assert np.linalg.norm(dt) < 0.002 and angle < 10e-6


def test_centre_chords_cannot_tell_and_say_so(tmp_path):
    sc = cal_scenario()
    with make_client(tmp_path, sc) as client:
        flow = Flow(client, sc)
        ok(client.put("/api/settings", json={"cal_chords": False}))
        answer = flow.calibrate_radius()
    assert answer["result"]["pretravel_frame_decision"]["decided"] is False
    assert any("cannot tell whether the pre-travel turns" in w for w in answer["warnings"])


def _edge_z(flow: Flow, status: int = 200) -> dict:
    top = flow.part_to_mcs((100.0, 60.0, 0.0))
    flow.travel(top[0], top[1], top[2] + 4.0)
    session = flow.create("edge.set", {"axis": "Z", "direction": "-", "setpoint": 0.0}, "G54")
    return flow.start(session["id"], status=status)


def test_an_uncalibrated_length_warns_or_refuses(tmp_path):
    sc = cal_scenario()
    top_z = float(Flow(None, sc).part_to_mcs((100.0, 60.0, 0.0))[2])
    with make_client(tmp_path, sc) as client:
        flow = Flow(client, sc)
        flow.calibrate_radius()                                   # the radius only
        warned = _edge_z(flow)
        assert any(w.startswith("65120 ") and "length Z-" in w for w in warned["warnings"])
        # what it warns about: Z is off by (about) the nominal/true length difference
        error = warned["result"]["position"]["Z"] - top_z
        assert abs(error) > 0.5 * abs(sc["probe"]["nominal"]["length"] - sc["probe"]["length"])
        log_before = len(ok(client.get("/api/log")))
        g54_before = ok(client.get("/api/offsets/G54"))

        ok(client.put("/api/settings", json={"calibration_invalid": "refuse"}))
        where = ok(client.get("/api/machine"))["mcs"]
        refused = _edge_z(flow, status=409)
        assert refused["error"]["code"] == "not_calibrated"
        assert refused["error"]["message"].startswith("65120 ")
        assert ok(client.get("/api/machine"))["mcs"] == where              # nothing moved
        assert ok(client.get("/api/offsets/G54")) == g54_before           # nothing written
        assert len(ok(client.get("/api/log"))) == log_before

        flow.calibrate_length()
        calibrated = _edge_z(flow)
        assert calibrated["warnings"] == []
        assert calibrated["result"]["position"]["Z"] == pytest.approx(top_z, abs=5 * NOISE)


def test_a_cycle_in_a_program_warns_or_refuses_too(tmp_path):
    """CYCLE978 in MDA (the issue: the same error, no warning at all)."""
    sc = cal_scenario()
    with make_client(tmp_path, sc) as client:
        flow = Flow(client, sc)
        flow.calibrate_radius()
        top = flow.part_to_mcs((100.0, 60.0, 0.0))
        program = f"_MVAR=0 _SETVAL={top[2]:.4f} _MA=3 _KNUM=0 _FA=6\nCYCLE978"
        flow.travel(top[0], top[1], top[2] + 4.0)
        ran = ok(client.post("/api/nc/run", json={"mda": program}))
        assert ran["state"] == "done"
        message = ok(client.get("/api/nc"))["message"]
        assert message.startswith("65120 CYCLE978") and "length Z-" in message
        ok(client.put("/api/settings", json={"calibration_invalid": "refuse"}))
        where = ok(client.get("/api/machine"))["mcs"]
        refused = ok(client.post("/api/nc/run", json={"mda": program}))
        assert refused["state"] == "alarm" and refused["alarm"]["code"] == 65120
        assert ok(client.get("/api/machine"))["mcs"] == where

"""Trust the probe before its numbers (issue [probe-health] items 3, 4, 8; design.md §10.4), through
the JSON API against the scenario's truth (flowkit.CAL_SCENARIO):

- the repeatability check's 2σ against the scenario's ``noise_sigma`` over many seeds (N = 25:
  within 30 % of 2σ; s²(n−1)/σ² is χ²(24), so about 96 % of the seeds are);
- what is stored (record, history) and what the next measurement says after each event: a
  repeatability above the limit, a collision, a broken probe, a ball change, another scenario's
  probe, the age; warn or refuse per the setting ``calibration_invalid``; results and log entries
  carry the calibration id.
"""

from __future__ import annotations

from datetime import UTC, datetime, timedelta

import numpy as np
import pytest
from flowkit import SAFE_Z, Flow, cal_scenario, make_client, ok


def _above_the_part(flow: Flow, clearance: float = 4.0) -> np.ndarray:
    """The ball above a point of the part's top face (a known face, Z-)."""
    top = flow.part_to_mcs((100.0, 60.0, 0.0))
    flow.travel(top[0], top[1], top[2] + clearance)
    return top


def _repeatability(flow: Flow, n: int = 1, status: int = 200, **body) -> dict:
    return ok(flow.c.post(f"/api/probes/{n}/repeatability", json=body), status)


def test_two_sigma_within_30_percent_of_the_scenarios_for_25_touches(tmp_path):
    """Four noise levels, five seeds each (20 checks of 25 touches)."""
    ratios = []
    with make_client(tmp_path, cal_scenario()) as client:
        for seed, sigma in ((s, sigma) for sigma in (0.0005, 0.001, 0.002, 0.004) for s in range(1, 6)):
            sc = cal_scenario(seed=seed, probe__noise_sigma=sigma)
            ok(client.post("/api/sim/scenario", json=sc))
            flow = Flow(client, sc)
            _above_the_part(flow)
            answer = _repeatability(flow, touches=25, direction="Z-")
            assert answer["n"] == 25 and len(answer["deviations"]["Z-"]) == 25
            ratios.append(answer["two_sigma"] / (2.0 * sigma))
            assert answer["range"] >= answer["two_sigma"] / 2.0
    ratios = np.array(ratios)
    within = np.mean(np.abs(ratios - 1.0) <= 0.3)
    assert within >= 0.85, ratios                       # about 0.7 of 20 expected outside
    assert abs(np.mean(ratios) - 1.0) < 0.1            # E[s]/σ = 0.99 for n = 25; sd of the mean 0.03


def test_no_noise_no_scatter_and_the_probe_returns(tmp_path):
    sc = cal_scenario(probe__noise_sigma=0.0)
    with make_client(tmp_path, sc) as client:
        flow = Flow(client, sc)
        _above_the_part(flow)
        where = ok(client.get("/api/machine"))["mcs"]
        answer = _repeatability(flow)
        assert answer["n"] == 10 and answer["two_sigma"] < 1e-9 and answer["range"] < 1e-9
        assert ok(client.get("/api/machine"))["mcs"] == pytest.approx(where)


def test_bad_input_and_no_face_store_nothing(tmp_path):
    sc = cal_scenario()
    with make_client(tmp_path, sc) as client:
        flow = Flow(client, sc)
        for body, field in (({"touches": 1}, "touches"), ({"direction": "W+"}, "direction"),
                            ({"touches": True}, "touches"), ({"speed": 3}, "speed"),
                            ({"directions": ["X+", "X+"]}, "directions")):
            error = _repeatability(flow, status=422, **body)["error"]
            assert error["field"] == field
        flow.goto(z=SAFE_Z)                                      # nothing below within 10 mm
        assert _repeatability(flow, status=409, distance=10.0)["error"]["code"] == "not_switched"
        assert ok(client.get("/api/probes/1"))["repeatability"] is None
        assert ok(client.get("/api/probes/1/history")) == []


def test_around_the_ring_gauge_per_direction(tmp_path):
    sc = cal_scenario(probe__noise_sigma=0.001)
    with make_client(tmp_path, sc) as client:
        flow = Flow(client, sc)
        cx, cy, top = sc["ring_gauge"]["center"]
        flow.travel(cx, cy, top - 8.0)
        answer = _repeatability(flow, touches=12, directions=["X+", "X-", "Y+", "Y-"], distance=20.0)
        assert set(answer["directions"]) == {"X+", "X-", "Y+", "Y-"}
        assert answer["two_sigma"] == max(d["two_sigma"] for d in answer["directions"].values())
        assert all(0.0 < d["two_sigma"] < 6 * 0.001 for d in answer["directions"].values())


def _edge_z(flow: Flow, status: int = 200) -> dict:
    top = flow.part_to_mcs((100.0, 60.0, 0.0))
    flow.travel(top[0], top[1], top[2] + 4.0)
    session = flow.create("edge.set", {"axis": "Z", "direction": "-", "setpoint": 0.0}, "measure_only")
    answer = flow.start(session["id"], status=status)
    flow.goto(z=SAFE_Z)
    return answer


def _calibrated(flow: Flow) -> dict:
    flow.calibrate_radius()
    flow.calibrate_length()
    record = ok(flow.c.get("/api/probes/1"))
    assert record["valid"] is True and record["invalid_reason"] is None
    return record


def _refused_and_nothing_moved(flow: Flow, code: str, alarm: int) -> None:
    ok(flow.c.put("/api/settings", json={"calibration_invalid": "refuse"}))
    top = flow.part_to_mcs((100.0, 60.0, 0.0))
    flow.travel(top[0], top[1], top[2] + 4.0)
    where = ok(flow.c.get("/api/machine"))["mcs"]
    log_before = len(ok(flow.c.get("/api/log")))
    session = flow.create("edge.set", {"axis": "Z", "direction": "-", "setpoint": 0.0}, "measure_only")
    error = flow.start(session["id"], status=409)["error"]
    assert error["code"] == code and error["message"].startswith(f"{alarm} ")
    assert ok(flow.c.get("/api/machine"))["mcs"] == where
    assert len(ok(flow.c.get("/api/log"))) == log_before
    ok(flow.c.put("/api/settings", json={"calibration_invalid": "warn"}))
    flow.goto(z=SAFE_Z)


def test_results_and_log_entries_carry_the_calibration(tmp_path):
    sc = cal_scenario()
    with make_client(tmp_path, sc) as client:
        flow = Flow(client, sc)
        radius = flow.calibrate_radius()
        length = flow.calibrate_length()
        assert radius["calibration_id"] is not None and length["calibration_id"] != radius["calibration_id"]
        record = ok(client.get("/api/probes/1"))
        assert record["calibration_id"] == length["calibration_id"]
        _above_the_part(flow)
        check = _repeatability(flow)
        answer = _edge_z(flow)
        assert answer["warnings"] == []
        assert answer["calibration_id"] == record["calibration_id"]
        calibration = answer["calibration"]
        assert calibration["at"] == record["calibrated_at"] and calibration["valid"] is True
        assert calibration["repeatability"] == check["two_sigma"]
        entry = ok(client.get(f"/api/log/{answer['log_id']}"))
        assert entry["calibration_id"] == record["calibration_id"]
        assert entry["probe"]["repeatability"]["two_sigma"] == check["two_sigma"]
        calibrations = [e for e in ok(client.get("/api/probes/1/history")) if e["event"] == "calibration"]
        assert [e["id"] for e in calibrations] == [length["calibration_id"], radius["calibration_id"]]


def test_a_repeatability_above_the_limit_warns_or_refuses(tmp_path):
    sc = cal_scenario(probe__noise_sigma=0.003)              # 2σ ≈ 6 µm > the default 2 µm
    with make_client(tmp_path, sc) as client:
        flow = Flow(client, sc)
        _calibrated(flow)
        _above_the_part(flow)
        check = _repeatability(flow, touches=25)
        assert check["exceeded"] is True and check["limit"] == 0.002
        stored = ok(client.get("/api/probes/1"))["repeatability"]
        assert stored["two_sigma"] == check["two_sigma"] and stored["at"] == check["at"]
        assert [e["event"] for e in ok(client.get("/api/probes/1/history"))][0] == "repeatability"
        warned = _edge_z(flow)
        assert any(w.startswith("65122 ") for w in warned["warnings"])
        _refused_and_nothing_moved(flow, "repeatability", 65122)
        ok(client.put("/api/settings", json={"repeatability_limit": 0.02}))
        assert not any(w.startswith("65122 ") for w in _edge_z(flow)["warnings"])


def test_a_collision_makes_the_calibration_invalid(tmp_path):
    sc = cal_scenario()
    with make_client(tmp_path, sc) as client:
        flow = Flow(client, sc)
        before = _calibrated(flow)
        top = _above_the_part(flow)
        # slowly onto the face: the probe switches while positioning (a collision), brakes within its travel
        crash = client.post("/api/machine/goto", json={"Z": float(top[2] + 1.0), "coords": "MCS", "feed": 100.0})
        alarms = ok(client.get("/api/machine"))["alarms"]
        assert [a["code"] for a in alarms] == [61302] and "broken" not in alarms[0]["text"], crash.text
        ok(client.post("/api/machine/reset"))
        record = ok(client.get("/api/probes/1"))
        assert record["valid"] is False and record["invalid_reason"] == "collision"
        assert record["invalidated"]["text"].startswith("61302")
        assert record["calibration_id"] == before["calibration_id"]
        flow.goto(z=SAFE_Z)
        warned = _edge_z(flow)
        assert any(w.startswith("65121 ") for w in warned["warnings"])
        assert warned["calibration"]["valid"] is False
        assert warned["calibration"]["invalid_reason"] == "collision"
        _refused_and_nothing_moved(flow, "calibration_invalid", 65121)
        flow.calibrate_length()
        again = ok(client.get("/api/probes/1"))
        assert again["valid"] is True and again["calibration_id"] != before["calibration_id"]
        assert _edge_z(flow)["warnings"] == []


def test_a_broken_probe_makes_it_invalid(tmp_path):
    sc = cal_scenario()
    with make_client(tmp_path, sc) as client:
        flow = Flow(client, sc)
        _calibrated(flow)
        top = _above_the_part(flow)
        client.post("/api/machine/goto", json={"Z": float(top[2] - 1.0), "coords": "MCS"})     # rapid into it
        assert any("broken" in a["text"] for a in ok(client.get("/api/machine"))["alarms"])
        record = ok(client.get("/api/probes/1"))
        assert record["valid"] is False and record["invalid_reason"] == "broken_probe"
        assert [e["event"] for e in ok(client.get("/api/probes/1/history"))][0] == "invalidated"


def test_a_change_of_the_ball_data_makes_it_invalid(tmp_path):
    sc = cal_scenario()
    with make_client(tmp_path, sc) as client:
        flow = Flow(client, sc)
        record = _calibrated(flow)
        same = {k: v for k, v in record.items() if k not in ("valid", "invalid_reason", "calibration_age_h")}
        assert ok(client.put("/api/probes/1", json=same))["valid"] is True      # nothing changed
        changed = ok(client.put("/api/probes/1", json={**same, "ball_diameter": 3.0}))
        assert changed["valid"] is False and changed["invalid_reason"] == "ball_changed"
        forged = ok(client.put("/api/probes/1", json={**same, "invalidated": None, "calibration_id": 999}))
        assert forged["valid"] is False and forged["calibration_id"] == record["calibration_id"]


def test_another_scenarios_probe_makes_it_invalid(tmp_path):
    sc = cal_scenario()
    with make_client(tmp_path, sc) as client:
        flow = Flow(client, sc)
        _calibrated(flow)
        ok(client.post("/api/sim/scenario", json=sc))                       # the same probe again
        assert ok(client.get("/api/probes/1"))["valid"] is True
        ok(client.post("/api/sim/scenario", json=cal_scenario(probe__length=101.0)))
        record = ok(client.get("/api/probes/1"))
        assert record["valid"] is False and record["invalid_reason"] == "other_probe"


def test_a_calibration_older_than_the_limit_is_invalid(tmp_path):
    sc = cal_scenario()
    with make_client(tmp_path, sc) as client:
        flow = Flow(client, sc)
        record = _calibrated(flow)
        ok(client.put("/api/settings", json={"calibration_max_age_h": 1.0}))
        assert ok(client.get("/api/probes/1"))["valid"] is True
        old = (datetime.now(UTC) - timedelta(hours=2)).isoformat(timespec="seconds")
        same = {k: v for k, v in record.items() if k not in ("valid", "invalid_reason", "calibration_age_h")}
        aged = ok(client.put("/api/probes/1", json={**same, "calibrated_at": old}))
        assert aged["valid"] is False and aged["invalid_reason"] == "age"
        assert aged["calibration_age_h"] == pytest.approx(2.0, abs=0.01)
        assert any(w.startswith("65121 ") for w in _edge_z(flow)["warnings"])
        _refused_and_nothing_moved(flow, "calibration_invalid", 65121)
        ok(client.put("/api/settings", json={"calibration_max_age_h": 0.0}))      # no limit
        assert ok(client.get("/api/probes/1"))["valid"] is True


def test_a_new_ball_in_the_tool_table_makes_it_invalid(tmp_path):
    sc = cal_scenario()
    with make_client(tmp_path, sc) as client:
        flow = Flow(client, sc)
        record = _calibrated(flow)
        t = sc["probe"]["t"]
        assert record["tool"] == t
        ok(client.put(f"/api/tools/{t}", json={"radius": 1.5}))
        changed = ok(client.get("/api/probes/1"))
        assert changed["valid"] is False and changed["invalid_reason"] == "ball_changed"

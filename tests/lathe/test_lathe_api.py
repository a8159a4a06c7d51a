"""The lathe through the JSON API (turning.md §10.2): machine state, tool data, task contract,
variants of each cycle, refusals, and what the milling machine keeps."""

from __future__ import annotations

import json

import pytest
from lathe_kit import LATHE_SCENARIO, TRUE_FACES, Lathe, lathe_scenario, make_client


@pytest.fixture
def lathe(tmp_path):
    with make_client(tmp_path) as client:
        yield Lathe(client)


def test_machine_state_of_a_lathe(lathe):
    st = lathe.status()
    assert st["kind"] == "lathe" and st["plane"] == "G18" and st["diameter_programming"] is True
    assert st["tool"] == 8 and st["tool_lengths"] == {"L1": 40.123, "L2": 100.456}
    assert st["mcs"] == {"X": 600.0, "Y": 0.0, "Z": 800.0}
    assert st["wcs"]["X"] == pytest.approx(2 * (600.0 - 40.123))      # a diameter with DIAMON
    moved = lathe.goto(coords="WCS", X=60.0)                           # Ø60 = radius 30
    assert moved["mcs"]["X"] == pytest.approx(30.0 + 40.123) and moved["wcs"]["X"] == pytest.approx(60.0)
    assert lathe.c.post("/api/machine/goto", json={"Y": 1.0, "coords": "MCS"}).status_code == 422


def test_tool_data_with_sl_l1_l2_and_their_wear(lathe):
    t3 = lathe.ok(lathe.c.get("/api/tools/3"))
    assert (t3["type"], t3["sl"], t3["l1"], t3["l2"], t3["radius"]) == (500, 3, 100.65, 60.32, 2.0)
    assert t3["wear"] == {"length": 0.0, "radius": 0.0, "l1": 0.0, "l2": 0.0}
    put = lathe.ok(lathe.c.put("/api/tools/3", json={"wear": {"l1": 0.01}, "sl": 2}))
    assert put["wear"]["l1"] == 0.01 and put["sl"] == 2 and put["l2"] == 60.32
    assert lathe.c.put("/api/tools/3", json={"sl": 10}).status_code == 422
    lathe.tool(3)
    assert lathe.status()["tool_lengths"] == pytest.approx({"L1": 100.66, "L2": 60.32})
    nc = lathe.c.app.state.services.machine.machine.nc_tools[3]
    assert nc["l1"] == 100.65 and nc["wear"]["l1"] == 0.01 and nc["sl"] == 2


def test_a_milling_tool_reads_as_before(tmp_path):
    from hmi_testdata import TEST_SCENARIO

    path = tmp_path / "mill.json"
    path.write_text(json.dumps(TEST_SCENARIO))
    from fastapi.testclient import TestClient

    from app.config import Settings
    from app.main import create_app

    with TestClient(create_app(Settings(db_path=tmp_path / "hmi.db", scenario_path=path, time_scale=0))) as client:
        tools = client.get("/api/tools").json()
        assert all(set(t) == {"t", "name", "type", "length", "radius", "wear"} for t in tools)
        assert all(set(t["wear"]) == {"length", "radius"} for t in tools)
        assert "kind" not in client.get("/api/machine").json()
        answer = client.post("/api/measure", json={"task": "lathe.point", "params": {"axis": "X", "setpoint": 45}})
        assert answer.status_code == 409 and answer.json()["error"]["code"] == "not_a_lathe"
        # a lathe scenario loaded at run time builds the simulated lathe (and resets the data)
        loaded = client.post("/api/sim/scenario", json=LATHE_SCENARIO)
        assert loaded.status_code == 200, loaded.text
        assert loaded.json()["kind"] == "lathe" and loaded.json()["tool"] == 8
        assert {t["t"] for t in client.get("/api/tools").json()} == {1, 3, 7, 8}
        back = client.post("/api/sim/scenario", json={**TEST_SCENARIO, "reset_data": True})
        assert back.status_code == 200 and "kind" not in back.json()


@pytest.mark.parametrize("task, params, field", [
    ("lathe.toolprobe.calibrate", {}, "axis"),
    ("lathe.tool.measure", {"axis": "X", "compensation": "both"}, "compensation"),
    ("lathe.probe.groove", {"groove": {"number": 1}, "axis": "X", "direction": "+", "skew": True}, "skew"),
    ("lathe.point", {"axis": "X", "setpoint": 45, "tolerance": {"setpoint": 44}}, "tolerance.setpoint"),
    ("lathe.point", {"axis": "X", "setpoint": 45, "target": {"tool": 1, "edge": 2}}, "target.edge"),
    ("lathe.two_point", {"axis": "X", "setpoint": 45}, "zone"),
])
def test_invalid_params_name_the_field(lathe, task, params, field):
    answer = lathe.c.post("/api/measure", json={"task": task, "params": params})
    assert answer.status_code == 400 and answer.json()["error"]["field"] == field, answer.text


def test_targets_and_the_milling_tasks_on_a_lathe(lathe):
    c = lathe.c
    unknown = c.post("/api/measure", json={"task": "lathe.point", "params": {"axis": "Z", "setpoint": 60},
                                           "target": "G599"})
    assert unknown.status_code == 400 and unknown.json()["error"]["code"] == "invalid_target"
    session = lathe.ok(c.post("/api/measure", json={"task": "lathe.point", "params": {"axis": "Z", "setpoint": 60},
                                                    "target": "G54"}))
    assert session["target"] == "G54" and session["params"]["target"] == "G54"
    tool = lathe.ok(c.post("/api/measure", json={"task": "lathe.point", "params": {
        "axis": "X", "setpoint": 45, "target": {"tool": 1, "correct": "l1"}}}))
    assert tool["target"] == {"tool": 1, "edge": 1, "correct": "l1", "mode": "wear", "inverse": False}
    milling = c.post("/api/measure", json={"task": "edge.set", "params": {"axis": "X", "direction": "-"}})
    assert milling.status_code == 409 and milling.json()["error"]["code"] == "lathe"


def test_a_turning_tool_cannot_measure_the_workpiece(lathe):
    """CYCLE974 with a turning tool (SL 3) active: 61315 at NC Start, nothing moved or written."""
    lathe.tool(1)
    before = lathe.status()["mcs"]
    answer = lathe.task("lathe.point", {"axis": "X", "setpoint": 45}, code=409)
    assert "61315" in answer["error"]["message"]
    assert lathe.status()["mcs"] == before


def test_incremental_variants(lathe):
    """1-C / 2-D: the tool placed by hand in front of the face, the nose centre on the probe
    centre; incremental calibration and measuring (no tolerance checks), back to the start."""
    lathe.tool(7)
    lathe.tip_to(7, 430.0, 205.0)                   # 1-C: X430 above the probe, S on the Z centre 210
    answer = lathe.task("lathe.toolprobe.calibrate", {"axis": "X", "incremental": True, "direction": "-",
                                                      "measuring_path": 20})
    assert answer["result"]["trigger"]["X-"] == pytest.approx(400.25, abs=1e-9)
    assert lathe.status()["mcs"]["X"] == pytest.approx(430.0 + 10.0)      # back at the start
    lathe.tool(3)
    lathe.tip_to(3, 430.0, 208.0)
    answer = lathe.task("lathe.tool.measure", {"axis": "X", "incremental": True, "direction": "-",
                                               "measuring_path": 20})
    assert answer["result"]["length"]["L1"]["actual"] == pytest.approx(100.70, abs=1e-9)
    assert lathe.lengths(3)[0] == pytest.approx(100.70, abs=1e-9)


def test_workpiece_related_tool_probe_and_tool_measuring(lathe):
    """_MVAR=10/11 (SW 6.3): the faces in the WCS (G54 Z 10 -> Z faces 10 lower), stored in _TPW."""
    lathe.ok(lathe.c.put("/api/offsets/G54", json={"trans": {"Z": 10.0}}))
    lathe.ok(lathe.c.post("/api/machine/activate", json={"offset": "G54"}))
    lathe.ok(lathe.c.put("/api/tool-probes/1", json={"trigger": {"Z-": 220, "Z+": 200, "X-": 400, "X+": 380},
                                                    "workpiece_trigger": {"Z-": 210, "Z+": 190, "X-": 400,
                                                                          "X+": 380}}))
    lathe.tool(7)
    lathe.tip_to(7, 420.0, 240.0)
    answer = lathe.task("lathe.toolprobe.calibrate", {"axis": "Z", "reference": "workpiece", "measuring_path": 1,
                                                      "tolerance": {"safe_area": 1}})
    assert answer["correction"]["target"] == "TPW1"
    record = lathe.ok(lathe.c.get("/api/tool-probes/1"))
    assert record["workpiece_trigger"]["Z-"] == pytest.approx(TRUE_FACES["Z-"] - 10.0, abs=1e-9)
    assert record["trigger"]["Z-"] == 220.0                                 # _TP untouched
    lathe.tool(3)
    lathe.tip_to(3, 420.0, 240.0)
    answer = lathe.task("lathe.tool.measure", {"axis": "Z", "reference": "workpiece", "measuring_path": 1,
                                               "tolerance": {"safe_area": 1}})
    # the X faces of _TPW are rough (400/380): the nose centre misses the Z centre by 0.025, no matter for Z
    assert answer["result"]["length"]["L2"]["actual"] == pytest.approx(60.30 + (TRUE_FACES["Z-"] - 10.0 - 210.35),
                                                                       abs=1e-9)


def test_empirical_value_in_tool_measuring(lathe):
    """_EVNUM: L_meas := L_meas − EV (turning.md §2.4)."""
    lathe.calibrate_tool_probe()
    lathe.ok(lathe.c.put("/api/memories/ev/4", json={"value": 0.01}))
    lathe.tool(3)
    lathe.tip_to(3, 420.0, 240.0)
    answer = lathe.task("lathe.tool.measure", {"axis": "X", "measuring_path": 1,
                                               "tolerance": {"safe_area": 1, "evnum": 4}})
    assert answer["result"]["length"]["L1"]["actual"] == pytest.approx(100.70 - 0.01, abs=1e-9)
    assert answer["result"]["empirical_value"] == 0.01


def test_probe_calibration_on_a_surface(lathe):
    """CYCLE973 _MVAR=0 (4-B-like): the face Z 60 (W on the chuck face): t(Z−) = 2.995."""
    lathe.ball_to(20.0, 80.0)
    answer = lathe.task("lathe.probe.surface", {"axis": "Z", "direction": "-", "setpoint": 60, "measuring_path": 3,
                                                "tolerance": {"safe_area": 4}})
    assert answer["result"]["trigger"]["Z-"] == pytest.approx(2.995, abs=1e-9)
    assert lathe.ok(lathe.c.get("/api/probes/1"))["trigger"]["Z-"] == pytest.approx(2.995, abs=1e-9)


def test_grooves_spos_log_and_audit(lathe):
    c = lathe.c
    assert lathe.ok(c.get("/api/lathe/grooves/1")) == {"number": 1, "x_minus": 50.054, "x_plus": 60.123,
                                                       "bottom_z": 15.021, "z_minus": 10.0, "z_plus": 20.0,
                                                       "top_x": 120.0, "bottom_x": 110.0}
    assert lathe.ok(c.put("/api/lathe/grooves/2", json={"x_minus": 1.0, "x_plus": 2.0}))["x_plus"] == 2.0
    assert c.put("/api/lathe/grooves/4", json={}).status_code == 422
    assert c.put("/api/lathe/grooves/2", json={"width": 3}).status_code == 422
    assert lathe.spos(90.0)["spindle_angle"] == 90.0
    assert c.post("/api/lathe/spos", json={"angle": 400.0}).status_code == 422
    out = lathe.calibrate_probe_in_groove()
    entry = lathe.ok(c.get(f"/api/log/{out['X']['log_id']}"))
    assert entry["task"] == "lathe.probe.groove" and entry["result"]["probe"]["wp"][8] == pytest.approx(0.004)
    assert entry["raw"]["P1"] and entry["correction"]["target"] == "WP1"
    lathe.ok(c.put("/api/offsets/G54", json={"trans": {"Z": 0.5}}))
    lathe.ok(c.post("/api/machine/activate", json={"offset": "G54"}))
    lathe.ball_to(40.0, 80.0, coords="WCS")
    lathe.task("lathe.point", {"axis": "Z", "setpoint": 60, "measuring_path": 2}, target="G54")
    audit = lathe.ok(c.get("/api/audit"))
    rows = audit if isinstance(audit, list) else audit.get("entries") or audit.get("items") or []
    assert any(r.get("offset") == "G54" and r.get("source") == "measure" for r in rows), audit


def test_the_lathe_demo_scenario_is_the_readme_one():
    from app.machine.scenario import lathe_demo_scenario

    demo = lathe_demo_scenario()
    assert demo.kind == "lathe" and demo.workpiece.eccentricity == (0.030, 0.0)
    assert {t.t for t in demo.tools} == {1, 3, 7} and demo.probe.nominal.l1 == 40.123
    assert lathe_scenario()["machine"]["kind"] == "lathe"

"""The tool probe's calibration validity (issue [probe-health] item 6, design.md §10.4): a cutter
that runs onto the tool probe while positioning, and the age, make its calibration invalid; tool
measuring then warns (65121) or is refused per ``calibration_invalid``; results carry the tool
probe's calibration id. The scenario and operator moves of tests/flows/test_tool_measuring_truth.py.
"""

from __future__ import annotations

import json
from datetime import UTC, datetime, timedelta

import pytest
from fastapi.testclient import TestClient
from test_tool_measuring_truth import CUTTER_T, SCENARIO, TP_CENTER, Api, ok


@pytest.fixture
def api(tmp_path):
    from app.config import Settings
    from app.main import create_app

    path = tmp_path / "scenario.json"
    path.write_text(json.dumps(SCENARIO))
    with TestClient(create_app(Settings(db_path=tmp_path / "hmi.db", scenario_path=path, time_scale=0))) as c:
        yield Api(c)


def _calibrated(api: Api) -> dict:
    answer = api.calibrate()
    record = ok(api.c.get("/api/tool-probes/1"))
    assert record["valid"] is True and record["calibration_id"] == answer["calibration_id"] is not None
    return record


def test_tool_measuring_carries_the_tool_probes_calibration(api):
    record = _calibrated(api)
    answer = api.length(CUTTER_T)
    # no calibration warning; only the start guard's note that tool measuring is not modelled (issue 24 §1)
    assert [w for w in answer["warnings"] if not w.startswith("Start guard: tool measuring")] == []
    assert answer["calibration_id"] == record["calibration_id"]
    assert answer["calibration"]["probe"] == "tool" and answer["calibration"]["valid"] is True
    assert ok(api.c.get(f"/api/log/{answer['log_id']}"))["calibration_id"] == record["calibration_id"]


def test_a_cutter_onto_the_tool_probe_makes_it_invalid(api):
    record = _calibrated(api)
    api.place(CUTTER_T, 0.4, 0.3, 7.0)
    length = api.tool(CUTTER_T)["length"]
    crash = api.c.post("/api/machine/goto", json={"Z": TP_CENTER[2] + length - 1.0, "coords": "MCS",
                                                  "feed": 100.0})
    assert crash.status_code == 409 and "tool probe" in crash.text, crash.text
    ok(api.c.post("/api/machine/reset"))
    invalid = ok(api.c.get("/api/tool-probes/1"))
    assert invalid["valid"] is False and invalid["invalid_reason"] == "collision"
    assert ok(api.c.get("/api/probes/1"))["invalidated"] is None          # the workpiece probe was not in it
    warned = api.length(CUTTER_T)
    assert any(w.startswith("65121 ") for w in warned["warnings"])
    api.settings(calibration_invalid="refuse")
    api.place(CUTTER_T, 0.4, 0.3, 7.0)
    where = ok(api.c.get("/api/machine"))["mcs"]
    session = ok(api.c.post("/api/measure", json={"task": "tool.length", "params": {}}))
    error = ok(api.c.post(f"/api/measure/{session['id']}/start", json={}), 409)["error"]
    assert error["code"] == "calibration_invalid" and error["message"].startswith("65121 ")
    assert ok(api.c.get("/api/machine"))["mcs"] == where
    again = api.calibrate()
    assert again["calibration_id"] != record["calibration_id"]
    assert ok(api.c.get("/api/tool-probes/1"))["valid"] is True


def test_an_old_tool_probe_calibration_is_invalid(api):
    record = _calibrated(api)
    api.settings(calibration_max_age_h=8.0)
    old = (datetime.now(UTC) - timedelta(hours=9)).isoformat(timespec="seconds")
    same = {k: v for k, v in record.items() if k not in ("valid", "invalid_reason", "calibration_age_h")}
    aged = ok(api.c.put("/api/tool-probes/1", json={**same, "calibrated_at": old}))
    assert aged["valid"] is False and aged["invalid_reason"] == "age"
    assert any(w.startswith("65121 ") for w in api.length(CUTTER_T)["warnings"])

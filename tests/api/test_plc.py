"""PLC interface DB19.DBB43 (spec/jog-measuring.md §3.2) and the readiness checklist (§1.6 [I]).

Truth: the simple test scenario (axis-parallel block, corner at MCS X 250 / Y 150, 200 x 120 mm,
top face Z -120; probe T9 in the spindle, no noise): "Distance 2 edges" in X measures 200 mm.
"""

from __future__ import annotations

import pytest
from hmi_testdata import BLOCK_TOP_Z, PROBE_LENGTH, TEST_SCENARIO

BLOCK_X0 = TEST_SCENARIO["workpiece"]["pose"]["trans"][0]
BLOCK_LX = TEST_SCENARIO["workpiece"]["features"][0]["size"][0]
P1_START = (BLOCK_X0 - 12.0, 210.0, BLOCK_TOP_Z - 10.0)            # left of the block, probing +X
P2_START = (BLOCK_X0 + BLOCK_LX + 12.0, 210.0, BLOCK_TOP_Z - 10.0)  # right of it, probing -X


def ok(response) -> dict:
    assert response.status_code == 200, response.text
    return response.json()


def ball_to(client, p) -> None:
    x, y, z = p
    for target in ({"Z": 0.0}, {"X": x, "Y": y}, {"Z": z + PROBE_LENGTH}):
        ok(client.post("/api/machine/goto", json={**target, "coords": "MCS"}))


def db19(client) -> dict:
    return ok(client.get("/api/plc/db19"))


def put_bit(client, bit, value):
    return client.put("/api/plc/db19/dbb43", json={"bit": bit, "value": value})


def stored(client, sid) -> list[bool]:
    return [p["stored"] for p in ok(client.get(f"/api/measure/{sid}"))["points"]]


@pytest.fixture
def sid(client):
    """A 'Distance 2 edges' session (2 points) on the block, nothing stored yet."""
    session = ok(client.post("/api/measure", json={
        "task": "edge.distance", "params": {"axis": "X", "direction": "+", "direction_p2": "-",
                                            "setpoint": 0}}))
    return session["id"]


def measure(client, sid, n) -> dict:
    ball_to(client, P1_START if n == 1 else P2_START)
    answer = ok(client.post(f"/api/measure/{sid}/start", json={"point": n}))
    assert answer["point"]["stored"]
    return answer


def test_no_session_all_bits_zero(client):
    state = db19(client)
    assert state["dbb43"] == 0 and state["session"] is None
    assert state["bits"] == {str(b): False for b in range(8)}
    assert not any(p["exists"] or p["stored"] for p in state["points"].values())


def test_handshake_invalidates_the_point_like_the_softkey(client, sid):
    measure(client, sid, 1)
    assert db19(client)["dbb43"] == 0x10                     # HMI: P1 stored (bit 4)
    measure(client, sid, 2)
    state = db19(client)
    assert state["dbb43"] == 0x30 and state["bits"]["4"] and state["bits"]["5"]
    assert ok(client.get(f"/api/measure/{sid}"))["plc_dbb43"] == 0x30

    after = ok(put_bit(client, 0, True))                     # PLC: discard P1
    assert stored(client, sid) == [False, True]              # the workflow's own view
    assert not after["points"]["P1"]["stored"] and after["points"]["P2"]["stored"]
    assert not after["bits"]["4"] and after["bits"]["5"]
    assert not after["bits"]["0"]                            # auto-release: PLC dropped the request
    assert after["dbb43"] == 0x20
    texts = [e["text"] for e in reversed(after["events"])]
    assert texts == ["PLC set DBB43.0: discard P1", "HMI invalidated P1 and cleared DBB43.4",
                     "PLC released DBB43.0 (HMI acknowledged)"]
    session = ok(client.get(f"/api/measure/{sid}"))
    assert not session["can_calculate"] and session["next_point"] == 1

    measure(client, sid, 1)                                  # repeat P1: the request does not fire again
    assert db19(client)["dbb43"] == 0x30
    result = ok(client.post(f"/api/measure/{sid}/calculate"))
    assert result["result"]["distance"] == pytest.approx(BLOCK_LX, abs=1e-6)
    assert db19(client)["dbb43"] == 0                        # bits 4..7 cleared after Calculate


def test_bits_cleared_when_the_screen_is_left(client, sid):
    measure(client, sid, 1)
    measure(client, sid, 2)
    assert db19(client)["dbb43"] == 0x30
    ok(client.delete(f"/api/measure/{sid}"))
    state = db19(client)
    assert state["dbb43"] == 0 and state["session"] is None


def test_manual_release_holds_the_request_until_the_plc_clears_it(client, sid):
    assert ok(client.put("/api/plc/db19/mode", json={"auto_release": False}))["auto_release"] is False
    measure(client, sid, 1)
    held = ok(put_bit(client, 0, True))
    assert held["dbb43"] == 0x01 and stored(client, sid) == [False, False]   # bit 4 cleared, bit 0 held
    measure(client, sid, 1)                                  # still held: edge-triggered, P1 stays
    assert db19(client)["dbb43"] == 0x11 and stored(client, sid) == [True, False]
    assert ok(put_bit(client, 0, False))["dbb43"] == 0x10    # handshake step 4 by the PLC side
    assert stored(client, sid) == [True, False]


def test_request_for_a_point_not_stored_changes_nothing(client, sid):
    measure(client, sid, 1)
    state = ok(put_bit(client, 1, True))                     # P2 is not stored
    assert state["dbb43"] == 0x10 and stored(client, sid) == [True, False]
    state = ok(put_bit(client, 3, True))                     # P4 does not exist in a 2-point task
    assert state["dbb43"] == 0x10 and not state["points"]["P4"]["exists"]


def test_request_during_nc_start_is_served_after_it(client, app, sid):
    measure(client, sid, 1)
    session = app.state.services.workflow.session
    session.running = True                                   # as while NC Start measures the next point
    try:
        state = ok(put_bit(client, 0, True))
        assert state["points"]["P1"]["pending"] and state["dbb43"] == 0x11
        assert stored(client, sid) == [True, False]
    finally:
        session.running = False
    state = db19(client)
    assert state["dbb43"] == 0 and stored(client, sid) == [False, False]


BAD_WRITES = [
    ({"bit": 4, "value": True}, "bit", "hmi_owned"),
    ({"bit": 7, "value": False}, "bit", "hmi_owned"),
    ({"bit": 8, "value": True}, "bit", None),
    ({"bit": -1, "value": True}, "bit", None),
    ({"bit": "0", "value": True}, "bit", None),
    ({"bit": True, "value": True}, "bit", None),
    ({"bit": 1.5, "value": True}, "bit", None),
    ({"value": True}, "bit", None),
    ({"bit": 0}, "value", None),
    ({"bit": 0, "value": "yes"}, "value", None),
    ({"bit": 0, "value": 1}, "value", None),
    ({"bit": 0, "value": True, "extra": 1}, "extra", None),
]


@pytest.mark.parametrize(("body", "field", "code"), BAD_WRITES)
def test_bad_writes_are_4xx_naming_the_field_and_change_nothing(client, sid, body, field, code):
    measure(client, sid, 1)
    before = db19(client)
    response = client.put("/api/plc/db19/dbb43", json=body)
    assert 400 <= response.status_code < 500, response.text
    err = response.json()["error"]
    assert err["field"] == field and err["message"], err
    if code:
        assert err["code"] == code
    assert db19(client)["dbb43"] == before["dbb43"] == 0x10
    assert stored(client, sid) == [True, False]


def test_bad_mode_names_the_field(client):
    response = client.put("/api/plc/db19/mode", json={"auto_release": "maybe"})
    assert response.status_code == 422 and response.json()["error"]["field"] == "auto_release"
    assert db19(client)["auto_release"] is True


# --- readiness checklist (spec §1.6 [I]) ---------------------------------------------------

def checks(client, task: str | None = None) -> tuple[dict, dict]:
    report = ok(client.get("/api/readiness", params={"task": task} if task else None))
    return report, {c["id"]: c for c in report["checks"]}


def test_readiness_with_the_uncalibrated_probe_in_the_spindle(client):
    report, by_id = checks(client, "edge.distance")
    assert by_id["probe_active"]["ok"] and by_id["probe_offset"]["ok"]
    assert by_id["no_scale"]["ok"] and by_id["no_scale"]["alarm"] == 61310
    cal = by_id["probe_calibrated"]
    assert not cal["ok"] and cal["alarm"] == 61341 and cal["severity"] == "warning"
    assert report["ready_for_task"] and report["blocking"] == []
    assert [w["id"] for w in report["warnings"]] == ["probe_calibrated"]
    assert report["ready"]["workpiece"] and not report["ready"]["tool_measuring"]


def test_readiness_calibrated_probe_and_override(client):
    ok(client.put("/api/probes/1", json={"calibrated_radius": True, "calibrated_length": True,
                                         "calibrated_plane": "G17", "calibration_override": 100.0}))
    _, by_id = checks(client)
    assert by_id["probe_calibrated"]["ok"] and by_id["override"]["ok"]
    ok(client.put("/api/machine/override", json={"feed": 50}))
    _, by_id = checks(client)
    assert not by_id["override"]["ok"] and by_id["override"]["severity"] == "warning"
    ok(client.put("/api/probes/1", json={"calibrated_radius": True, "calibrated_length": True,
                                         "calibrated_plane": "G18"}))
    _, by_id = checks(client)
    assert not by_id["probe_calibrated"]["ok"] and "G18" in by_id["probe_calibrated"]["message"]


def test_readiness_cutter_in_the_spindle_blocks_workpiece_measuring(client):
    ok(client.post("/api/machine/tool", json={"tool": 1}))
    report, by_id = checks(client, "hole.1")
    assert not by_id["probe_active"]["ok"] and by_id["probe_active"]["alarm"] == 61309
    assert not report["ready_for_task"] and 61309 in [b["alarm"] for b in report["blocking"]]
    tool_report, by_id = checks(client, "tool.length")
    assert by_id["cutter_active"]["ok"] and by_id["tool_data"]["ok"]
    assert [b["alarm"] for b in tool_report["blocking"]] == [61341]          # tool probe not calibrated
    ok(client.put("/api/tool-probes/1", json={"calibrated_length": True, "disc_diameter": 20.0}))
    assert checks(client, "tool.length")[0]["ready_for_task"]
    assert not checks(client, "tool.diameter")[0]["ready_for_task"]         # diameter not calibrated


def test_readiness_empty_spindle_and_alarm(client):
    ok(client.post("/api/machine/tool", json={"tool": 0}))
    report, by_id = checks(client, "edge.set")
    assert {b["alarm"] for b in report["blocking"]} == {61309, 61311}
    assert by_id["cutter_active"]["alarm"] == 61311
    ok(client.post("/api/machine/tool", json={"tool": 9}))
    ball_to(client, (100.0, 100.0, BLOCK_TOP_Z - 10.0))
    sid = ok(client.post("/api/measure", json={"task": "edge.set", "params": {"axis": "Y", "direction": "-"}}))["id"]
    assert client.post(f"/api/measure/{sid}/start").status_code == 409     # probes into nothing: 61301
    report, by_id = checks(client)
    assert not by_id["no_alarm"]["ok"] and by_id["no_alarm"]["alarm"] == 61301
    assert not any(report["ready"].values())


def test_readiness_unknown_task_names_the_field(client):
    response = client.get("/api/readiness", params={"task": "hole.9"})
    assert response.status_code == 422 and response.json()["error"]["field"] == "task"


# --- the test page (server side) ------------------------------------------------------------

def test_page_shows_eight_leds_and_refuses_hmi_bits(client, sid):
    page = client.get("/plc")
    assert page.status_code == 200
    assert page.text.count('data-led="') == 8 and page.text.count('data-toggle="') == 4
    assert "BHG" in page.text and 'data-check="probe_active"' in page.text
    measure(client, sid, 1)
    block = client.post("/plc/db19/bit", data={"bit": "4", "value": "1"})
    assert 'role="alert"' in block.text and "DBB43.4" in block.text
    assert db19(client)["dbb43"] == 0x10
    block = client.post("/plc/db19/bit", data={"bit": "0", "value": "1"})
    assert 'data-dbb43="0"' in block.text and stored(client, sid) == [False, False]
    assert 'href="/plc"' in client.get("/settings").text

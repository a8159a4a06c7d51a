"""Probe state, the probe test and the NC Start refusals (issue 26 items 1, 2, 6; design.md §10.4).

Truth: the test scenario's geometry (the block's top face at BLOCK_TOP_Z, the probe's ball of
2 mm radius PROBE_LENGTH below the spindle nose, the tool probe's disc at its centre), and what
the operator's hand did through ``POST /api/sim/probe``.
"""

from __future__ import annotations

import json

import pytest
from hmi_testdata import BLOCK_TOP_Z, CUTTER_LENGTH, PROBE_LENGTH, TEST_SCENARIO, test_scenario
from waiting import wait_until

BALL_R = TEST_SCENARIO["probe"]["ball_diameter"] / 2.0
TOOL_PROBE = TEST_SCENARIO["tool_probe"]
CABLE = {"in_spindle": True, "armed": None, "deflected": False, "battery": None}


def machine(client) -> dict:
    answer = client.get("/api/machine")
    assert answer.status_code == 200
    return answer.json()


def hand(client, **body) -> dict:
    answer = client.post("/api/sim/probe", json=body)
    assert answer.status_code == 200, answer.text
    return answer.json()


def load(client, scenario: dict) -> None:
    answer = client.post("/api/sim/scenario", json={**scenario, "reset_data": True})
    assert answer.status_code == 200, answer.text


def radio_scenario(battery: float = 0.8, tool_battery: float | None = None) -> dict:
    scenario = test_scenario()
    scenario["probe"]["radio"] = {"battery": battery}
    if tool_battery is not None:
        scenario["tool_probe"]["radio"] = {"battery": tool_battery}
    return scenario


def error_code(answer, status: int = 409) -> str:
    assert answer.status_code == status, answer.text
    return answer.json()["error"]["code"]


# --- item 1: the state in GET /api/machine ----------------------------------------------------------

def test_a_cable_probe_in_the_spindle_is_ready_and_has_no_battery(client):
    state = machine(client)
    assert state["probe"] == CABLE
    assert state["tool_probe"] == {"armed": None, "deflected": False, "battery": None}


def test_a_hand_deflects_and_releases_the_probe(client):
    assert hand(client, deflect=True)["probe"]["deflected"] is True
    assert machine(client)["probe"]["deflected"] is True
    assert machine(client)["tool_probe"]["deflected"] is False        # the other probe is untouched
    assert hand(client, deflect=False)["probe"] == CABLE


def test_the_tool_probe_is_deflected_by_hand_on_its_own(client):
    assert hand(client, probe="tool", deflect=True)["tool_probe"]["deflected"] is True
    assert machine(client)["probe"]["deflected"] is False


def test_the_ball_pressed_into_the_block_deflects_the_probe_until_it_is_lifted(client):
    # the ball above the block: a measuring move down switches on the top face and brakes behind it
    client.post("/api/machine/goto", json={"X": 300.0, "Y": 200.0, "Z": BLOCK_TOP_Z + PROBE_LENGTH + BALL_R + 5.0,
                                           "coords": "MCS"})
    probed = client.post("/api/machine/probe", json={"direction": [0, 0, -1], "distance": 10.0, "feed": 300.0}).json()
    assert probed["triggered"]
    ball_bottom = probed["end_mcs"]["Z"] - PROBE_LENGTH - BALL_R
    assert ball_bottom < BLOCK_TOP_Z                               # truth: the stop lies behind the face
    assert machine(client)["probe"]["deflected"] is True
    client.post("/api/machine/jog", json={"axis": "Z", "distance": 1.0})
    assert machine(client)["probe"]["deflected"] is False


def test_a_cutter_on_the_tool_probe_deflects_the_tool_probe_not_the_probe(client):
    assert client.post("/api/machine/tool", json={"tool": 1}).status_code == 200
    assert machine(client)["probe"]["in_spindle"] is False
    top = TOOL_PROBE["center"][2]
    client.post("/api/machine/goto", json={"X": TOOL_PROBE["center"][0], "Y": TOOL_PROBE["center"][1],
                                           "Z": top + CUTTER_LENGTH + 5.0, "coords": "MCS"})
    probed = client.post("/api/machine/probe", json={"direction": [0, 0, -1], "distance": 10.0, "feed": 300.0}).json()
    assert probed["triggered"] and probed["end_mcs"]["Z"] - CUTTER_LENGTH < top     # the cutter's end below the disc
    state = machine(client)
    assert state["tool_probe"]["deflected"] is True and state["probe"]["deflected"] is False
    client.post("/api/machine/jog", json={"axis": "Z", "distance": 2.0})
    assert machine(client)["tool_probe"]["deflected"] is False


def test_a_radio_probe_is_armed_in_the_spindle_with_a_charged_battery(client):
    load(client, radio_scenario(0.8))
    assert machine(client)["probe"] == {"in_spindle": True, "armed": True, "deflected": False, "battery": 0.8}
    assert client.post("/api/machine/tool", json={"tool": 1}).status_code == 200
    assert machine(client)["probe"]["armed"] is False               # in the magazine it is off
    assert client.post("/api/machine/tool", json={"tool": 9}).status_code == 200
    assert hand(client, battery=0.0)["probe"]["armed"] is False      # flat
    assert hand(client, battery=0.5)["probe"] == {"in_spindle": True, "armed": True, "deflected": False,
                                                  "battery": 0.5}
    assert hand(client, armed=False)["probe"]["armed"] is False


@pytest.mark.parametrize("body, field", [
    ({"deflect": "yes"}, "deflect"), ({"deflect": 1}, "deflect"), ({"battery": 1.5}, "battery"),
    ({"battery": 0.5}, "battery"),                     # a cable probe has no battery
    ({"armed": False}, "armed"),                       # nor a switch
    ({"probe": "spindle", "deflect": True}, "probe"), ({"deflect": True, "force": 3}, "force")])
def test_bad_hand_input_is_422_naming_the_field_and_changes_nothing(client, body, field):
    before = machine(client)
    answer = client.post("/api/sim/probe", json=body)
    assert answer.status_code == 422, answer.text
    assert answer.json()["error"]["field"] == field
    assert machine(client)["probe"] == before["probe"] and machine(client)["tool_probe"] == before["tool_probe"]


def test_the_live_feed_carries_the_probe_state(client):
    hand(client, deflect=True)
    with client.stream("GET", "/api/events?limit=1") as stream:
        data = next(line for line in stream.iter_lines() if line.startswith("data:"))
    event = json.loads(data.removeprefix("data:"))
    assert event["probe"] == {**CABLE, "deflected": True}
    assert event["tool_probe"] == {"armed": None, "deflected": False, "battery": None}


# --- item 2: the probe test ----------------------------------------------------------------------------

def test_probe_test_waits_sees_the_switch_and_the_seat_again(client):
    started = client.post("/api/probe/test", json={})
    assert started.status_code == 200 and started.json()["state"] == "waiting"
    assert client.get("/api/probe/test").json()["state"] == "waiting"
    hand(client, deflect=True)
    test = client.get("/api/probe/test").json()
    assert test["state"] == "switched" and test["switched_at"] is not None and test["after_s"] >= 0.0
    hand(client, deflect=False)
    assert client.get("/api/probe/test").json()["state"] == "passed"


def test_tool_probe_test(client):
    assert client.post("/api/probe/test", json={"probe": "tool"}).json()["state"] == "waiting"
    hand(client, probe="workpiece", deflect=True)                   # the wrong probe: still waiting
    assert client.get("/api/probe/test").json()["state"] == "waiting"
    hand(client, probe="tool", deflect=True)
    test = client.get("/api/probe/test").json()
    assert test["probe"] == "tool" and test["state"] == "switched"


def test_probe_test_ends_not_switched_when_nothing_happens(client):
    client.post("/api/probe/test", json={"timeout_s": 0.05})
    wait_until(lambda: client.get("/api/probe/test").json()["state"] == "not_switched", "the test gave up")


def test_probe_test_cancel(client):
    client.post("/api/probe/test", json={})
    assert client.delete("/api/probe/test").json()["state"] == "cancelled"
    hand(client, deflect=True)
    assert client.get("/api/probe/test").json()["state"] == "cancelled"


def test_probe_test_refuses_a_probe_that_cannot_show_a_switch(client):
    hand(client, deflect=True)
    assert error_code(client.post("/api/probe/test", json={})) == "probe_deflected"
    hand(client, deflect=False)
    client.post("/api/machine/tool", json={"tool": 1})
    assert error_code(client.post("/api/probe/test", json={})) == "probe_not_in_spindle"
    client.post("/api/machine/tool", json={"tool": 9})
    load(client, radio_scenario(0.0))
    assert error_code(client.post("/api/probe/test", json={})) == "probe_not_armed"
    scenario = test_scenario()
    del scenario["tool_probe"]
    load(client, scenario)
    assert error_code(client.post("/api/probe/test", json={"probe": "tool"})) == "no_tool_probe"
    assert client.get("/api/probe/test").json()["state"] == "idle"


@pytest.mark.parametrize("body, field", [({"probe": "ball"}, "probe"), ({"timeout_s": 0}, "timeout_s"),
                                         ({"timeout_s": "10"}, "timeout_s"), ({"extra": 1}, "extra")])
def test_probe_test_bad_input(client, body, field):
    answer = client.post("/api/probe/test", json=body)
    assert answer.status_code == 422 and answer.json()["error"]["field"] == field
    assert client.get("/api/probe/test").json()["state"] == "idle"


# --- item 1: NC Start refuses a probe that cannot switch -------------------------------------------

def edge_session(client) -> str:
    answer = client.post("/api/measure", json={"task": "edge.set", "params": {"axis": "X", "direction": "+"}})
    assert answer.status_code in (200, 201), answer.text
    return answer.json()["id"]


def refused_with(client, sid: str, code: int) -> None:
    before = machine(client)["mcs"]
    answer = client.post(f"/api/measure/{sid}/start")
    assert answer.status_code == 409 and answer.json()["error"]["message"].startswith(str(code)), answer.text
    state = machine(client)
    assert state["mcs"] == before                                   # nothing moved
    assert any(a["code"] == code for a in state["alarms"])          # the alarm line shows why
    assert client.get(f"/api/measure/{sid}").json()["points"][0]["stored"] is False
    client.post("/api/machine/reset")


def test_nc_start_refuses_a_deflected_probe_with_65401(client):
    sid = edge_session(client)
    hand(client, deflect=True)
    refused_with(client, sid, 65401)


def test_nc_start_refuses_a_radio_probe_that_is_not_armed_with_65400(client):
    load(client, radio_scenario(0.8))
    sid = edge_session(client)
    hand(client, armed=False)
    refused_with(client, sid, 65400)


def test_nc_start_refuses_a_tool_measurement_on_a_deflected_tool_probe_with_65404(client):
    client.post("/api/machine/tool", json={"tool": 1})
    answer = client.post("/api/measure", json={"task": "tool.length", "params": {}})
    assert answer.status_code in (200, 201), answer.text
    hand(client, probe="tool", deflect=True)
    refused_with(client, answer.json()["id"], 65404)


def test_nc_start_refuses_a_radio_tool_probe_that_is_off_with_65403(client):
    load(client, radio_scenario(0.8, tool_battery=0.0))
    client.post("/api/machine/tool", json={"tool": 1})
    answer = client.post("/api/measure", json={"task": "tool.length", "params": {}})
    refused_with(client, answer.json()["id"], 65403)


def test_a_tool_change_cancels_a_running_probe_test(client):
    client.post("/api/probe/test", json={})
    client.post("/api/machine/tool", json={"tool": 1})
    assert client.get("/api/probe/test").json()["state"] == "cancelled"

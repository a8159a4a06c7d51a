"""Machine calls: state, jog, goto, activation, tool change, override, probe, reset, scenario."""

from __future__ import annotations

import math

import pytest
from hmi_testdata import BLOCK_TOP_Z, CUTTER_LENGTH, PROBE_LENGTH, test_scenario


def machine(client) -> dict:
    response = client.get("/api/machine")
    assert response.status_code == 200
    return response.json()


def assert_error(response, status: int, code: str | None = None, field: str | None = None) -> dict:
    assert response.status_code == status, response.text
    error = response.json()["error"]
    assert error["message"]
    if code:
        assert error["code"] == code
    if field:
        assert error["field"] == field
    return error


def test_health(client):
    assert client.get("/api/health").json() == {"status": "ok"}


def test_machine_state_has_the_contract_fields(client):
    state = machine(client)
    for key in ("mode", "mcs", "wcs", "active_offset", "plane", "tool", "feed_override", "alarms", "busy"):
        assert key in state
    assert state["mode"] == "JOG"
    assert state["mcs"] == {"X": 100.0, "Y": 100.0, "Z": 0.0}
    assert state["active_offset"] == "G500"
    assert state["tool"] == 9                      # the probe is put into the spindle
    # G500, no basic frames: WCS = tool tip = axes - L along Z
    assert state["wcs"] == pytest.approx({"X": 100.0, "Y": 100.0, "Z": -PROBE_LENGTH})


def test_jog_moves_one_axis_and_answers_the_new_state(client):
    state = client.post("/api/machine/jog", json={"axis": "X", "distance": -10.5}).json()
    assert state["mcs"]["X"] == pytest.approx(89.5)
    assert state["mcs"]["Y"] == pytest.approx(100.0)
    assert machine(client)["mcs"]["X"] == pytest.approx(89.5)


@pytest.mark.parametrize("body, field", [
    ({"axis": "Q", "distance": 1}, "axis"),
    ({"axis": "X", "distance": "abc"}, "distance"),
    ({"axis": "X"}, "distance"),
    ({"axis": "X", "distance": 1e9}, "distance"),
    ({"axis": "X", "distance": 1, "feed": -5}, "feed"),
    ({"axis": "X", "distance": 1, "extra": 1}, "extra"),
])
def test_jog_bad_input_is_422_and_nothing_moves(client, body, field):
    before = machine(client)["mcs"]
    assert_error(client.post("/api/machine/jog", json=body), 422, "validation", field)
    assert machine(client)["mcs"] == before


def test_non_finite_and_malformed_json_are_422(client):
    before = machine(client)["mcs"]
    headers = {"content-type": "application/json"}
    assert_error(client.post("/api/machine/jog", content='{"axis": "X", "distance": NaN}', headers=headers), 422)
    assert_error(client.post("/api/machine/jog", content='{"axis": "X", ', headers=headers), 422)
    assert_error(client.post("/api/machine/jog", content='[1, 2]', headers=headers), 422)
    assert machine(client)["mcs"] == before


def test_goto_mcs_keeps_missing_axes(client):
    state = client.post("/api/machine/goto", json={"X": 50, "coords": "MCS"}).json()
    assert state["mcs"] == pytest.approx({"X": 50.0, "Y": 100.0, "Z": 0.0})


def test_goto_wcs_is_the_default_and_lands_the_tool_tip(client):
    state = client.post("/api/machine/goto", json={"X": 20, "Y": 30, "Z": -150}).json()
    assert state["mcs"] == pytest.approx({"X": 20.0, "Y": 30.0, "Z": -150 + PROBE_LENGTH})
    assert state["wcs"] == pytest.approx({"X": 20.0, "Y": 30.0, "Z": -150.0})


def test_activation_changes_the_wcs(client):
    client.put("/api/offsets/G54", json={"trans": {"X": 100, "Y": -20, "Z": -50}})
    state = client.post("/api/machine/activate", json={"offset": "G54"}).json()
    assert state["active_offset"] == "G54"
    assert state["wcs"] == pytest.approx({"X": 0.0, "Y": 120.0, "Z": -PROBE_LENGTH + 50})
    state = client.post("/api/machine/activate", json={"offset": "G500"}).json()
    assert state["active_offset"] == "G500"
    assert state["wcs"] == pytest.approx({"X": 100.0, "Y": 100.0, "Z": -PROBE_LENGTH})


def test_basic_frames_are_part_of_the_chain(client):
    client.put("/api/offsets/BASIC_0", json={"trans": {"X": 10}})
    client.put("/api/offsets/G54", json={"trans": {"X": 5}})
    state = client.post("/api/machine/activate", json={"offset": "G54"}).json()
    assert state["wcs"]["X"] == pytest.approx(100 - 15)
    # G500 switches only the settable frame off
    state = client.post("/api/machine/activate", json={"offset": "G500"}).json()
    assert state["wcs"]["X"] == pytest.approx(100 - 10)


def test_goto_wcs_with_rotated_g54(client):
    client.put("/api/offsets/G54", json={"trans": {"X": 250, "Y": 150, "Z": -120}, "rot": {"Z": 30}})
    client.post("/api/machine/activate", json={"offset": "G54"})
    state = client.post("/api/machine/goto", json={"X": 10, "Y": 0, "Z": 5}).json()
    c, s = math.cos(math.radians(30)), math.sin(math.radians(30))
    # p_mcs = R(30° about Z) · (10, 0, 5) + T, axes = tip + L along Z (written out by hand)
    assert state["mcs"] == pytest.approx({"X": 250 + 10 * c, "Y": 150 + 10 * s, "Z": -120 + 5 + PROBE_LENGTH})
    assert state["wcs"] == pytest.approx({"X": 10.0, "Y": 0.0, "Z": 5.0}, abs=1e-9)
    # missing axes stay in the WCS: only WCS Y changes
    state = client.post("/api/machine/goto", json={"Y": 7}).json()
    assert state["wcs"] == pytest.approx({"X": 10.0, "Y": 7.0, "Z": 5.0}, abs=1e-9)


@pytest.mark.parametrize("name", ["G99", "BASIC_0", "BASIC_REF", "", "g54x"])
def test_activate_refuses_non_settable_names(client, name):
    assert_error(client.post("/api/machine/activate", json={"offset": name}), 422, field="offset")
    assert machine(client)["active_offset"] == "G500"


def test_activation_survives_a_restart(tmp_path, scenario_file):
    from fastapi.testclient import TestClient

    from app.config import Settings
    from app.main import create_app

    settings = Settings(db_path=tmp_path / "keep.db", scenario_path=scenario_file)
    with TestClient(create_app(settings)) as first:
        first.post("/api/machine/activate", json={"offset": "G55"})
        first.post("/api/machine/tool", json={"tool": 1})
    with TestClient(create_app(settings)) as second:
        state = machine(second)
        assert (state["active_offset"], state["tool"]) == ("G55", 1)


def test_tool_change_changes_wcs_z_by_the_length_difference(client):
    with_probe = machine(client)["wcs"]["Z"]
    state = client.post("/api/machine/tool", json={"tool": 1}).json()
    assert state["tool"] == 1
    assert state["tool_length"] == pytest.approx(CUTTER_LENGTH)
    assert state["wcs"]["Z"] - with_probe == pytest.approx(PROBE_LENGTH - CUTTER_LENGTH)


def test_tool_change_by_name_and_t_string_uses_length_plus_wear(client):
    client.put("/api/tools/1", json={"name": "end mill 10", "wear": {"length": 0.25}})
    assert client.post("/api/machine/tool", json={"tool": "end mill 10"}).json()["tool_length"] == \
        pytest.approx(CUTTER_LENGTH + 0.25)
    assert client.post("/api/machine/tool", json={"tool": "T9"}).json()["tool"] == 9
    # editing the tool in the spindle updates the NC's L1 at once
    client.put("/api/tools/9", json={"wear": {"length": -0.1}})
    assert machine(client)["tool_length"] == pytest.approx(PROBE_LENGTH - 0.1)


@pytest.mark.parametrize("tool, status", [(42, 404), ("no such tool", 404), (True, 422), (-1, 422), ([1], 422)])
def test_tool_change_bad_input(client, tool, status):
    assert_error(client.post("/api/machine/tool", json={"tool": tool}), status)
    assert machine(client)["tool"] == 9


def test_tool_change_to_a_tool_the_machine_does_not_have(client):
    client.put("/api/tools/5", json={"length": 50, "radius": 3})
    error = assert_error(client.post("/api/machine/tool", json={"tool": 5}), 409, "alarm")
    assert error["message"].startswith("61343")
    assert machine(client)["tool"] == 9


def test_override(client):
    assert client.put("/api/machine/override", json={"feed": 50}).json()["feed_override"] == 50
    for bad in (121, -1, "abc", None):
        assert_error(client.put("/api/machine/override", json={"feed": bad}), 422, field="feed")
    assert machine(client)["feed_override"] == 50


def test_collision_answers_409_alarm_until_reset(client):
    client.post("/api/machine/goto", json={"X": 300, "Y": 200, "coords": "MCS"})
    # tip at Z -100, block top at -120: jogging 50 down hits it
    error = assert_error(client.post("/api/machine/jog", json={"axis": "Z", "distance": -50}), 409, "alarm")
    assert error["message"].startswith("61302")
    state = machine(client)
    assert [a["code"] for a in state["alarms"]] == [61302]
    assert state["program_state"] == "interrupted"
    assert client.post("/api/machine/reset").json()["alarms"] == []


def test_limit_is_409_alarm(client):
    error = assert_error(client.post("/api/machine/jog", json={"axis": "X", "distance": 5000}), 409, "alarm")
    assert error["message"].startswith("21614")
    assert machine(client)["mcs"]["X"] == 100.0


def test_probe_move_latches_on_the_surface(client):
    client.post("/api/machine/goto", json={"X": 300, "Y": 200, "coords": "MCS"})
    result = client.post("/api/machine/probe", json={"direction": [0, 0, -1], "distance": 50, "feed": 300}).json()
    assert result["triggered"] is True
    # ball (radius 2) touches the top face when the axes are at top + radius + L
    assert result["mcs"]["Z"] == pytest.approx(BLOCK_TOP_Z + 2 + PROBE_LENGTH, abs=1e-6)
    assert result["wcs"]["Z"] == pytest.approx(BLOCK_TOP_Z + 2, abs=1e-6)


def test_probe_move_in_the_air_is_not_triggered(client):
    result = client.post("/api/machine/probe", json={"direction": [1, 0, 0], "distance": 5, "feed": 300}).json()
    assert result["triggered"] is False
    assert result["mcs"] is None
    assert machine(client)["alarms"] == []


@pytest.mark.parametrize("body", [
    {"direction": [0, 0, 0], "distance": 5, "feed": 300},
    {"direction": [0, 0], "distance": 5, "feed": 300},
    {"direction": [0, 0, -1], "distance": -5, "feed": 300},
    {"direction": [0, 0, -1], "distance": 5, "feed": 0},
    {"direction": [0, 0, -1], "distance": 5},
    {"direction": "down", "distance": 5, "feed": 300},
])
def test_probe_bad_input(client, body):
    before = machine(client)["mcs"]
    assert_error(client.post("/api/machine/probe", json=body), 422)
    assert machine(client)["mcs"] == before


def test_motion_while_busy_is_409(client):
    slow = test_scenario()
    slow["machine"]["time_scale"] = 1.0
    client.post("/api/sim/scenario", json=slow)
    assert client.post("/api/machine/jog/continuous", json={"axis": "X", "direction": 1}).status_code == 200
    try:
        assert machine(client)["busy"] is True
        assert_error(client.post("/api/machine/jog", json={"axis": "Y", "distance": 1}), 409, "busy")
        assert_error(client.post("/api/machine/goto", json={"Y": 1}), 409, "busy")
    finally:
        client.post("/api/machine/stop")
    assert machine(client)["busy"] is False


def test_scenario_load_resets_the_machine_but_keeps_data(client):
    client.put("/api/offsets/G54", json={"trans": {"X": 12}})
    client.put("/api/tools/1", json={"length": 86})
    client.post("/api/machine/jog", json={"axis": "X", "distance": 10})
    scenario = test_scenario()
    scenario["start"] = {"X": 10.0, "Y": 20.0, "Z": -5.0}
    state = client.post("/api/sim/scenario", json=scenario).json()
    assert state["mcs"] == {"X": 10.0, "Y": 20.0, "Z": -5.0}
    assert client.get("/api/offsets/G54").json()["trans"]["X"] == 12
    assert client.get("/api/tools/1").json()["length"] == 86


def test_scenario_reset_data_reseeds_the_tables(client):
    client.put("/api/offsets/G54", json={"trans": {"X": 12}})
    client.put("/api/tools/1", json={"length": 86})
    client.put("/api/settings", json={"plane": "G18"})
    client.post("/api/machine/activate", json={"offset": "G54"})
    state = client.post("/api/sim/scenario", json={**test_scenario(), "reset_data": True}).json()
    assert state["active_offset"] == "G500" and state["tool"] == 9 and state["plane"] == "G17"
    assert client.get("/api/offsets/G54").json()["trans"]["X"] == 0
    assert client.get("/api/tools/1").json()["length"] == CUTTER_LENGTH
    assert client.get("/api/tools/9").json()["type"] == 710


@pytest.mark.parametrize("body", [
    {"machine": {"rapid": -1}},
    {"probe": {"ball_diameter": "big"}},
    {"unknown": 1},
    {"reset_data": "yes"},
])
def test_bad_scenario_is_422_and_nothing_changes(client, body):
    client.post("/api/machine/jog", json={"axis": "X", "distance": 3})
    before = machine(client)
    assert_error(client.post("/api/sim/scenario", json=body), 422)
    assert machine(client) == before


def test_unknown_route_has_the_envelope(client):
    assert_error(client.get("/api/nope"), 404, "not_found")
    assert_error(client.delete("/api/machine"), 405)


def test_plane_g18_applies_the_tool_length_along_y(client):
    client.put("/api/settings", json={"plane": "G18"})
    state = machine(client)
    assert state["plane"] == "G18"
    assert state["wcs"] == pytest.approx({"X": 100.0, "Y": 100.0 - PROBE_LENGTH, "Z": 0.0})

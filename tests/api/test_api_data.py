"""Stored data: offsets (validated, audited), tools, probes, tool probes, settings, log."""

from __future__ import annotations

import pytest
from hmi_testdata import CUTTER_LENGTH, PROBE_LENGTH
from test_api_machine import assert_error

# --- zero offsets -------------------------------------------------------------------------


def test_offsets_list_in_chain_order(client):
    offsets = client.get("/api/offsets").json()
    assert list(offsets)[:3] == ["BASIC_REF", "BASIC_0", "BASIC_1"]
    assert {"G54", "G55", "G56", "G57", "G505", "G508"} <= set(offsets)
    assert offsets["G54"] == {"trans": {"X": 0.0, "Y": 0.0, "Z": 0.0}, "fine": {"X": 0.0, "Y": 0.0, "Z": 0.0},
                              "rot": {"X": 0.0, "Y": 0.0, "Z": 0.0}}


def test_put_offset_merges_and_is_audited(client):
    after = client.put("/api/offsets/G54", json={"trans": {"X": 1.5}, "rot": {"Z": -12.5}}).json()
    assert after["trans"] == {"X": 1.5, "Y": 0.0, "Z": 0.0}
    after = client.put("/api/offsets/G54", json={"trans": {"Y": 2}, "fine": {"Z": 0.01}}).json()
    assert after["trans"] == {"X": 1.5, "Y": 2.0, "Z": 0.0}
    assert after["rot"]["Z"] == -12.5 and after["fine"]["Z"] == 0.01
    assert client.get("/api/offsets/G54").json() == after
    audit = client.get("/api/audit", params={"name": "G54"}).json()
    assert [e["source"] for e in audit] == ["api", "api"]
    assert audit[0]["before"]["trans"]["Y"] == 0.0 and audit[0]["after"]["trans"]["Y"] == 2.0


@pytest.mark.parametrize("body, field", [
    ({"trans": {"X": "abc"}}, "trans.X"),
    ({"trans": {"Q": 1}}, "trans.Q"),
    ({"trans": {"C": 1}}, "trans.C"),          # the test machine has no rotary axis
    ({"fine": {"C": 1}}, "fine.C"),
    ({"rot": {"Z": 360}}, "rot.Z"),
    ({"rot": {"X": -400}}, "rot.X"),
    ({"trans": {"X": True}}, "trans.X"),
    ({"trans": {"X": 1e12}}, "trans.X"),
    ({"trans": [1, 2, 3]}, "trans"),
    ({"scale": {"X": 2}}, "scale"),
])
def test_put_offset_bad_input_changes_nothing(client, body, field):
    client.put("/api/offsets/G55", json={"trans": {"X": 7}})
    before = client.get("/api/offsets/G55").json()
    audit_count = len(client.get("/api/audit").json())
    assert_error(client.put("/api/offsets/G55", json=body), 422, "validation", field)
    assert client.get("/api/offsets/G55").json() == before
    assert len(client.get("/api/audit").json()) == audit_count


def test_unknown_offset_is_404(client):
    assert_error(client.get("/api/offsets/G99"), 404)
    assert_error(client.put("/api/offsets/G99", json={"trans": {"X": 1}}), 404)


def test_writing_the_active_offset_moves_the_wcs_at_once(client):
    client.post("/api/machine/activate", json={"offset": "G54"})
    client.put("/api/offsets/G54", json={"trans": {"X": 40}})
    assert client.get("/api/machine").json()["wcs"]["X"] == pytest.approx(60.0)


# --- tools -------------------------------------------------------------------------------

def test_tool_table_is_seeded_from_the_scenario(client):
    tools = {t["t"]: t for t in client.get("/api/tools").json()}
    assert tools[9]["type"] == 710 and tools[9]["length"] == PROBE_LENGTH and tools[9]["radius"] == 2.0
    assert tools[1] == {"t": 1, "name": None, "type": 120, "length": CUTTER_LENGTH, "radius": 5.0,
                        "wear": {"length": 0.0, "radius": 0.0}}


def test_put_tool_creates_and_updates(client):
    created = client.put("/api/tools/7", json={"t": 7, "type": 200, "length": 60, "radius": 4}).json()
    assert created["type"] == 200 and created["wear"] == {"length": 0.0, "radius": 0.0}
    updated = client.put("/api/tools/7", json={"wear": {"radius": -0.02}}).json()
    assert updated["length"] == 60 and updated["wear"] == {"length": 0.0, "radius": -0.02}
    assert client.get("/api/tools/7").json() == updated


@pytest.mark.parametrize("path, body, status, field", [
    ("/api/tools/1", {"radius": -1}, 422, "radius"),
    ("/api/tools/1", {"length": "long"}, 422, "length"),
    ("/api/tools/1", {"wear": {"length": "x"}}, 422, "wear.length"),
    ("/api/tools/1", {"wear": {"depth": 1}}, 422, "wear.depth"),
    ("/api/tools/1", {"t": 2}, 422, "t"),
    ("/api/tools/1", {"colour": "red"}, 422, "colour"),
    ("/api/tools/0", {"length": 1}, 422, "t"),
    ("/api/tools/abc", {"length": 1}, 422, "t"),
])
def test_put_tool_bad_input_changes_nothing(client, path, body, status, field):
    before = client.get("/api/tools").json()
    assert_error(client.put(path, json=body), status, field=field)
    assert client.get("/api/tools").json() == before


def test_get_unknown_tool_is_404(client):
    assert_error(client.get("/api/tools/77"), 404)


def test_tool_in_spindle_cannot_be_deleted(client):
    assert_error(client.delete("/api/tools/9"), 409)
    assert client.delete("/api/tools/1").status_code == 204
    assert_error(client.get("/api/tools/1"), 404)


# --- probes --------------------------------------------------------------------------------

def test_probe_records_have_defaults(client):
    record = client.get("/api/probes/1").json()
    assert record["number"] == 1 and record["effective_diameter"] == 0.0 and record["trigger"] == {}
    assert [p["number"] for p in client.get("/api/probes").json()] == [1, 2, 3]


def test_put_probe_replaces_the_record(client):
    data = {"ball_diameter": 4.0, "effective_diameter": 3.987, "trigger": {"X-": 1.99, "X+": -1.995},
            "skew": [0.01, -0.006], "calibrated_radius": True, "calibration_feed": 300,
            "calibration_override": 100, "calibrated_at": "2025-01-01T10:00:00+00:00"}
    stored = client.put("/api/probes/2", json=data).json()
    assert stored["number"] == 2 and stored["trigger"] == data["trigger"]
    assert client.get("/api/probes/2").json() == stored


@pytest.mark.parametrize("path, body, status", [
    ("/api/probes/1", {"trigger": {"Q+": 1}}, 422),
    ("/api/probes/1", {"ball_diameter": 0}, 422),
    ("/api/probes/1", {"skew": [1]}, 422),
    ("/api/probes/1", {"number": 2}, 422),
    ("/api/probes/1", {"whatever": 1}, 422),
    ("/api/probes/0", {}, 422),
    ("/api/probes/100", {}, 422),
])
def test_put_probe_bad_input(client, path, body, status):
    before = client.get("/api/probes").json()
    assert_error(client.put(path, json=body), status)
    assert client.get("/api/probes").json() == before


def test_unknown_probe_is_404(client):
    assert_error(client.get("/api/probes/50"), 404)


def test_tool_probe_records(client):
    stored = client.put("/api/tool-probes/1", json={"disc_diameter": 20, "trigger": {"Z-": -240.0}}).json()
    assert stored["axes"] == 133 and client.get("/api/tool-probes/1").json() == stored
    assert_error(client.put("/api/tool-probes/1", json={"type": 7}), 422, field="type")


# --- settings -------------------------------------------------------------------------------

def test_settings_defaults_follow_the_spec(client):
    s = client.get("/api/settings").json()
    # _JM_I[4]: the GUD6 definition line SET(0,1,1,17,100,...) gives 100 = keep the active WO; the
    # spec (§11 Q1) chose the element table's 0 (G500), the seed's code line wins (issue 17 note)
    assert s["plane"] == "G17" and s["measuring_wo"] == "active" and s["attempts"] == 1
    assert (s["measuring_feed"], s["fast_feed"], s["position_feed"], s["measuring_path"]) == (300, 900, 2000, 50)
    assert (s["mt_dz"], s["mt_dir"], s["mt_ax"], s["d_l"], s["d_r"]) == (2, -1, 133, 2, 1)


def test_put_settings_is_partial_and_persists(client):
    s = client.put("/api/settings", json={"plane": "G19", "measuring_wo": "G54", "two_stage": True}).json()
    assert (s["plane"], s["measuring_wo"], s["two_stage"], s["measuring_feed"]) == ("G19", "G54", True, 300)
    assert client.get("/api/settings").json() == s


@pytest.mark.parametrize("body, field", [
    ({"plane": "G20"}, "plane"),
    ({"measuring_wo": "G99"}, "measuring_wo"),
    ({"measuring_wo": "G509"}, "measuring_wo"),   # valid syntax, but only G505..G508 are configured
    ({"measuring_feed": 0}, "measuring_feed"),
    ({"measuring_feed": "fast"}, "measuring_feed"),
    ({"attempts": 3}, "attempts"),
    ({"mt_ax": 134}, "mt_ax"),
    ({"mt_ax": 33}, "mt_ax"),                    # tool axis must allow minus
    ({"probe_number": 100}, "probe_number"),
    ({"colour": "red"}, "colour"),
])
def test_put_settings_bad_input_changes_nothing(client, body, field):
    before = client.get("/api/settings").json()
    assert_error(client.put("/api/settings", json=body), 422, "validation", field)
    assert client.get("/api/settings").json() == before


# --- log ------------------------------------------------------------------------------------

def test_log_is_empty_and_unknown_entry_is_404(client):
    assert client.get("/api/log").json() == []
    assert_error(client.get("/api/log/1"), 404)
    assert_error(client.get("/api/log", params={"limit": 0}), 422, field="limit")


def test_log_lists_entries_written_by_the_workflow(client, app):
    with app.state.services.db.unit() as unit:
        log_id = unit.add_log({"task": "edge.set", "result": {"position": 1.0}})
    assert [e["id"] for e in client.get("/api/log").json()] == [log_id]
    assert client.get(f"/api/log/{log_id}").json()["task"] == "edge.set"


def test_log_id_out_of_range_is_a_422_not_a_500(client):
    """Found by schemathesis: an id beyond SQLite's 64-bit integers used to raise OverflowError."""
    for bad in ("703894987214326758188777472", "0", "-3"):
        response = client.get(f"/api/log/{bad}")
        assert response.status_code == 422, bad
        assert response.json()["error"]["field"] == "log_id"

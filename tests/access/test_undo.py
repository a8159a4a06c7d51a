"""Undo of audited changes (``POST /api/audit/{id}/undo``) and the History/Restore view of a zero
offset (design.md §9.2): the previous value exactly, as a new audited write, 409 when changed since."""

from __future__ import annotations

from access_helpers import ORIGIN, error_of, g54

HTMX = {"HX-Request": "true"}
FIRST = {"trans": {"X": 101.125, "Y": -42.0625, "Z": -120.5}, "fine": {"X": 0.003}, "rot": {"Z": 12.4375}}


def last_id(client, name="G54") -> int:
    return client.get("/api/audit", params={"name": name}).json()[0]["id"]


def test_undo_restores_the_previous_g54_exactly(client):
    client.put("/api/offsets/G54", json=FIRST)
    before = g54(client)
    client.put("/api/offsets/G54", json={"trans": {"X": 777.7}, "rot": {"Z": -3.0}})
    change = last_id(client)
    answer = client.post(f"/api/audit/{change}/undo")
    assert answer.status_code == 200, answer.text
    assert g54(client) == before                        # every component, bit for bit
    assert answer.json()["value"] == before and answer.json()["undone"] == change
    row = client.get("/api/audit", params={"name": "G54"}).json()[0]
    assert row["id"] == answer.json()["audit_id"] and row["source"] == "undo"
    assert row["detail"] == {"undo_of": change} and row["who"] == "trainer"
    assert client.get("/api/machine").json()["active_offset"] in ("G500", "G54")


def test_undo_of_an_older_change_is_409_unless_forced(client):
    client.put("/api/offsets/G54", json={"trans": {"X": 1.0}})
    old = last_id(client)
    client.put("/api/offsets/G54", json={"trans": {"X": 2.0}})
    refused = client.post(f"/api/audit/{old}/undo")
    assert refused.status_code == 409 and error_of(refused)["code"] == "changed_since"
    assert g54(client)["trans"]["X"] == 2.0
    forced = client.post(f"/api/audit/{old}/undo", json={"force": True})
    assert forced.status_code == 200 and g54(client)["trans"]["X"] == 0.0


def test_undo_needs_the_level_of_the_data(signin_client, tokens):
    signin_client.put("/api/offsets/G54", json={"trans": {"X": 4.0}}, headers=tokens[5])
    change = signin_client.get("/api/audit", headers=tokens[7]).json()[0]["id"]
    refused = signin_client.post(f"/api/audit/{change}/undo", headers=tokens[6])
    assert refused.status_code == 403 and error_of(refused)["function"] == "offsets"
    assert signin_client.post(f"/api/audit/{change}/undo", headers=tokens[5]).status_code == 200
    row = signin_client.get("/api/audit", headers=tokens[7]).json()[0]
    assert row["who"] == "token:mes5" and row["source"] == "undo"
    assert signin_client.post(f"/api/audit/{change}/undo").status_code == 401


def test_undo_of_tool_and_probe_changes(client):
    client.put("/api/tools/3", json={"length": 80.0, "radius": 4.0})
    client.put("/api/tools/3", json={"length": 81.5})
    tool_change = client.get("/api/audit", params={"name": "T3"}).json()[0]
    assert tool_change["kind"] == "tool" and tool_change["before"]["length"] == 80.0
    assert client.post(f"/api/audit/{tool_change['id']}/undo").status_code == 200
    assert client.get("/api/tools/3").json()["length"] == 80.0
    created = client.get("/api/audit", params={"name": "T3"}).json()[-1]
    assert created["before"] is None
    assert client.post(f"/api/audit/{created['id']}/undo", json={"force": True}).status_code == 200
    assert client.get("/api/tools/3").status_code == 404

    client.put("/api/probes/2", json={"ball_diameter": 3.0})
    probe_change = client.get("/api/audit", params={"name": "WP2"}).json()[0]
    assert client.post(f"/api/audit/{probe_change['id']}/undo").status_code == 200
    assert client.get("/api/probes/2").json()["ball_diameter"] != 3.0


def test_what_cannot_be_undone_says_so(client):
    client.put("/api/settings", json={"measuring_feed": 222.0})
    row = client.get("/api/audit", params={"kind": "settings"}).json()[0]
    assert row["before"] == {"measuring_feed": 300.0} and row["after"] == {"measuring_feed": 222.0}
    refused = client.post(f"/api/audit/{row['id']}/undo")
    assert refused.status_code == 409 and error_of(refused)["code"] == "not_undoable"
    assert client.post("/api/audit/999999/undo").status_code == 404


def test_history_view_lists_the_changes_and_restores(client):
    client.put("/api/offsets/G55", json={"trans": {"X": 10.0}})
    client.put("/api/offsets/G55", json={"trans": {"X": 20.0}})
    table = client.get("/offsets").text
    assert 'href="/offsets/G55/history"' in table
    history = client.get("/offsets/G55/history").text
    # in the operator's terms (issue 29 item 6): the value's name, the unit, the source
    assert history.count("data-restore=") == 2 and "<b>translation X</b>: 10.000 mm → 20.000 mm" in history
    assert "Trainer" in history and ">API<" in history
    token = client.cookies.get("csrftoken")
    headers = {"Origin": ORIGIN, "X-CSRFToken": token, **HTMX}
    newest = last_id(client, "G55")
    oldest = newest - 1
    # Restore asks first and shows what it writes; nothing is written by the question
    asked = client.post(f"/offsets/audit/{newest}/restore", headers=headers)
    assert asked.status_code == 200 and 'id="restore-question"' in asked.text
    assert "<b>translation X</b>: 20.000 mm → 10.000 mm" in asked.text.split('id="restore-question"')[1]
    assert client.get("/api/offsets/G55").json()["trans"]["X"] == 20.0
    # the older change: the offset changed since, the question says so and offers "Restore anyway"
    asked = client.post(f"/offsets/audit/{oldest}/restore", headers=headers)
    assert "changed again" in asked.text and "Restore anyway" in asked.text
    refused = client.post(f"/offsets/audit/{oldest}/restore", headers=headers, data={"confirm": "1"})
    assert refused.status_code == 200 and "Restore anyway" in refused.text
    assert g54(client) is not None and client.get("/api/offsets/G55").json()["trans"]["X"] == 20.0
    restored = client.post(f"/offsets/audit/{newest}/restore", headers=headers, data={"confirm": "1"})
    assert restored.status_code == 200 and "restored" in restored.text
    assert client.get("/api/offsets/G55").json()["trans"]["X"] == 10.0
    assert client.get("/api/audit", params={"name": "G55"}).json()[0]["source"] == "undo"


def test_history_restore_is_disabled_below_the_level(signin_client, tokens):
    signin_client.put("/api/offsets/G54", json={"trans": {"X": 4.0}}, headers=tokens[5])
    page = signin_client.get("/offsets/G54/history", headers=tokens[7]).text
    assert "data-restore=" in page and "disabled" in page and "needs level 5" in page
    table = signin_client.get("/offsets", headers=tokens[7]).text
    assert 'readonly disabled title="needs level 5' in table
    allowed = signin_client.get("/offsets", headers=tokens[5]).text
    assert "readonly disabled" not in allowed


def test_audit_screen_shows_who_for_every_kind(client):
    client.put("/api/offsets/G54", json={"trans": {"X": 1.0}})
    client.put("/api/tools/2", json={"length": 10.0})
    client.put("/api/settings", json={"measuring_feed": 250.0})
    page = client.get("/offsets/audit").text
    assert page.count('class="who-cell">Trainer (level 1)') >= 3 and "T2" in page
    assert "<b>Measuring feed</b>: 300 mm/min → 250 mm/min" in page      # the setting's name and unit

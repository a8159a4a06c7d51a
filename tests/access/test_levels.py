"""Access levels through the JSON API (design.md §9.2): trainer mode, 401 without credentials once a
user exists, every level boundary of the table allowed/refused, tokens, sessions, the keyswitch,
the level table in the settings, and the measuring commit's own check."""

from __future__ import annotations

import pytest
from access_helpers import PASSWORDS, error_of
from fastapi.testclient import TestClient
from hmi_testdata import test_scenario

from app.access.levels import FUNCTIONS

# one request per function of the level table: (method, path, json)
CALLS = {
    "view": ("GET", "/api/machine", None),
    "jog": ("POST", "/api/machine/jog", {"axis": "X", "distance": 1.0}),
    "measure": ("POST", "/api/measure", {"task": "edge.set", "target": "measure_only",
                                         "params": {"axis": "X", "direction": "+", "setpoint": 0.0}}),
    "offsets": ("PUT", "/api/offsets/G54", {"trans": {"X": 1.5}}),
    "tools": ("PUT", "/api/tools/5", {"length": 50.0}),
    "probe_data": ("PUT", "/api/probes/2", {"ball_diameter": 4.0}),
    "calibration": ("POST", "/api/measure", {"task": "probe.radius", "params": {"diameter": 25.0}}),
    "settings": ("PUT", "/api/settings", {"measuring_feed": 250.0}),
    "keyswitch": ("PUT", "/api/keyswitch", {"position": 1}),
    "scenario": ("POST", "/api/sim/scenario", "scenario"),
    "users": ("GET", "/api/users", None),
}


def call(client, function: str, headers: dict | None = None):
    method, path, body = CALLS[function]
    if body == "scenario":
        body = test_scenario()
    return client.request(method, path, json=body, headers=headers or {})


def test_the_table_covers_every_function():
    assert set(CALLS) == set(FUNCTIONS)
    defaults = {key: f.default for key, f in FUNCTIONS.items()}
    # Operate-like defaults: looking, jogging, measuring only: 7; offsets and tools: a keyswitch level;
    # probe data, calibration, settings, administration: a password level
    assert defaults["view"] == defaults["jog"] == defaults["measure"] == 7
    assert 4 <= defaults["offsets"] <= 6 and 4 <= defaults["tools"] <= 6
    assert all(defaults[f] <= 3 for f in ("probe_data", "calibration", "settings", "scenario", "users"))


# --- trainer mode ---------------------------------------------------------------------------------------

def test_trainer_mode_allows_everything_without_credentials_and_names_the_trainer(client):
    for function in CALLS:
        response = call(client, function)
        assert response.status_code < 400, (function, response.text)
    entry = client.get("/api/audit", params={"name": "G54"}).json()[0]
    assert entry["who"] == "trainer" and entry["level"] == 1 and entry["source"] == "api"
    session = client.get("/api/session").json()
    assert session["trainer"] and not session["signin_required"] and session["level"] == 1


def test_trainer_mode_serves_only_this_computer(app):
    with TestClient(app, client=("192.0.2.7", 40000), base_url="http://127.0.0.1:8000") as remote:
        response = remote.get("/api/machine")
        assert response.status_code == 403 and error_of(response)["code"] == "trainer_local_only"
    with TestClient(app, client=("127.0.0.1", 40000), base_url="http://127.0.0.1:8000") as local:
        assert local.get("/api/machine").status_code == 200


def test_a_token_keeps_its_level_in_trainer_mode(client, access):
    secret, _ = access.add_token("viewer", 7)
    response = client.put("/api/offsets/G54", json={"trans": {"X": 1.0}}, headers={"Authorization": f"Bearer {secret}"})
    assert response.status_code == 403 and error_of(response)["required_level"] == 5


def test_the_banner_says_trainer_mode(client):
    page = client.get("/jog").text
    assert 'id="trainer-banner"' in page and "user add" in page


# --- sign-in on ------------------------------------------------------------------------------------------

def test_after_user_add_unauthenticated_calls_are_401_and_change_nothing(signin_client):
    before = signin_client.app.state.services.offsets.get("G54")
    for function in CALLS:
        response = call(signin_client, function)
        assert response.status_code == 401, (function, response.text)
        assert error_of(response)["code"] == "unauthenticated"
        assert response.headers["www-authenticate"] == "Bearer"
    assert signin_client.app.state.services.offsets.get("G54") == before
    assert signin_client.get("/api/health").json() == {"status": "ok"}
    assert signin_client.get("/api/session").json()["signin_required"] is True


def test_a_screen_without_sign_in_goes_to_the_sign_in_screen(signin_client):
    response = signin_client.get("/offsets", follow_redirects=False)
    assert response.status_code == 303 and response.headers["location"].startswith("/signin?next=/offsets")
    htmx = signin_client.get("/offsets", headers={"HX-Request": "true"})
    assert htmx.status_code == 401 and htmx.headers["hx-redirect"].startswith("/signin")
    assert signin_client.get("/signin").status_code == 200


def test_a_wrong_token_is_401(signin_client):
    response = signin_client.get("/api/machine", headers={"Authorization": "Bearer hmi_nope"})
    assert response.status_code == 401 and error_of(response)["code"] == "invalid_token"
    basic = signin_client.get("/api/machine", headers={"Authorization": "Basic YTpi"})
    assert basic.status_code == 401


@pytest.mark.parametrize("function", sorted(CALLS))
def test_each_level_boundary(signin_client, tokens, function):
    """A token at the function's level may, one level lower (numerically higher) may not: 403
    ``access_level`` naming the level needed, nothing changed."""
    needed = FUNCTIONS[function].default
    if needed < 7:
        before = signin_client.app.state.services.offsets.list()
        refused = call(signin_client, function, tokens[needed + 1])
        assert refused.status_code == 403, refused.text
        error = error_of(refused)
        assert error["code"] == "access_level" and error["required_level"] == needed
        assert error["function"] == function and f"level {needed}" in error["message"]
        assert signin_client.app.state.services.offsets.list() == before
    allowed = call(signin_client, function, tokens[needed])
    assert allowed.status_code < 400, allowed.text


def test_a_sufficient_token_writes_and_is_named_in_the_audit(signin_client, tokens):
    response = signin_client.put("/api/offsets/G54", json={"trans": {"X": 12.25}}, headers=tokens[5])
    assert response.status_code == 200
    entry = signin_client.get("/api/audit", params={"name": "G54"}, headers=tokens[7]).json()[0]
    assert (entry["who"], entry["level"], entry["source"]) == ("token:mes5", 5, "api")
    assert entry["after"]["trans"]["X"] == 12.25


def test_reset_and_stop_are_never_locked(signin_client, tokens):
    assert signin_client.post("/api/machine/reset", headers=tokens[7]).status_code == 200
    assert signin_client.post("/api/machine/stop", headers=tokens[7]).status_code == 200


def test_measuring_into_a_zero_offset_needs_the_offsets_level(signin_client, tokens):
    body = {"task": "edge.set", "params": {"axis": "X", "direction": "+", "setpoint": 0.0}, "target": "G54"}
    refused = signin_client.post("/api/measure", json=body, headers=tokens[7])
    assert refused.status_code == 403 and error_of(refused)["function"] == "offsets"
    session = signin_client.post("/api/measure", json=body, headers=tokens[5])
    assert session.status_code == 200
    # NC Start of that session by a level-7 token: refused before anything moves
    start = signin_client.post(f"/api/measure/{session.json()['id']}/start", json={}, headers=tokens[7])
    assert start.status_code == 403 and error_of(start)["required_level"] == 5
    tool = signin_client.post("/api/measure", json={"task": "tool.length", "params": {}}, headers=tokens[6])
    assert tool.status_code == 403 and error_of(tool)["function"] == "tools"


def test_the_measuring_commit_checks_the_acting_level(app, tokens):
    """The last line: a write of a measurement is refused for a too low level, nothing written."""
    from app.access.errors import AccessDenied
    from db import Actor, acting_as

    env = app.state.services.workflow._env
    before = app.state.services.offsets.get("G54")
    with acting_as(Actor("token:mes7", 7)), pytest.raises(AccessDenied):
        env.commit_measurement(offset=object(), log_entry={"task": "edge.set"})
    with acting_as(Actor("token:mes7", 7)), pytest.raises(AccessDenied):
        env.commit_measurement(tool_update=(1, {"length": 1.0}), log_entry={"task": "tool.length"})
    assert app.state.services.offsets.get("G54") == before
    assert app.state.services.log.list(10, 0) == []


def test_calibration_writes_to_tool_data_are_audited(app, client):
    from db import Actor, acting_as

    env = app.state.services.workflow._env
    client.put("/api/tools/9", json={"type": 710, "length": 100.2, "radius": 2.0})
    with acting_as(Actor("user:anna", 3)):
        env.commit_measurement(probe_update=(1, {"ball_diameter": 4.0}), tool_update=(9, {"length": 99.987}),
                               log_entry={"task": "probe.length"})
    rows = client.get("/api/audit", params={"limit": 5}).json()
    tool_row = next(r for r in rows if r["kind"] == "tool" and r["source"] == "calibration")
    assert tool_row["offset"] == "T9" and tool_row["before"]["length"] == 100.2
    assert tool_row["after"]["length"] == 99.987 and tool_row["who"] == "user:anna"
    assert any(r["kind"] == "probe" and r["offset"] == "WP1" and r["source"] == "calibration" for r in rows)


# --- sessions ------------------------------------------------------------------------------------------

def test_sign_in_sets_a_strict_http_only_cookie_and_sign_out_ends_it(signin_client):
    wrong = signin_client.post("/api/session", json={"user": "anna", "password": "nope"})
    assert wrong.status_code == 401 and error_of(wrong)["code"] == "sign_in_failed"
    unknown = signin_client.post("/api/session", json={"user": "nobody", "password": "nope"})
    assert unknown.status_code == 401 and error_of(unknown)["message"] == error_of(wrong)["message"]

    ok = signin_client.post("/api/session", json={"user": "anna", "password": PASSWORDS["anna"][0]})
    assert ok.status_code == 200, ok.text
    assert ok.json()["name"] == "anna" and ok.json()["level"] == 3 and ok.json()["csrf_token"]
    cookie = ok.headers["set-cookie"]
    assert "hmi_session=" in cookie and "HttpOnly" in cookie and "SameSite=strict" in cookie.replace("Strict", "strict")
    assert "Max-Age=28800" in cookie
    # a JSON client with the cookie (no Origin): allowed as far as its level goes
    assert signin_client.put("/api/settings", json={"measuring_feed": 280.0}).status_code == 200
    refused = signin_client.post("/api/sim/scenario", json=test_scenario())
    assert refused.status_code == 403 and error_of(refused)["required_level"] == 2
    assert signin_client.get("/api/audit", params={"kind": "settings"}).json()[0]["who"] == "user:anna"
    assert "anna" in signin_client.get("/jog").text

    assert signin_client.delete("/api/session").json() == {"signed_in": False}
    assert signin_client.get("/api/machine").status_code == 401


def test_repeated_wrong_passwords_make_that_computer_wait(signin_client, access, monkeypatch):
    # per source, not per name: tests/hardening/test_signin_bounds.py (issue 25)
    monkeypatch.setattr(access._hasher, "verify_and_update", lambda password, hashed: (False, None))
    codes = [signin_client.post("/api/session", json={"user": "anna", "password": "x"}).status_code
             for _ in range(6)]
    assert codes == [401] * 5 + [429]


def test_the_panel_signs_in_at_the_keyswitch_level(signin_client, tokens, app):
    ok = signin_client.post("/api/session", json={"panel": True})
    assert ok.status_code == 200 and ok.json()["kind"] == "panel" and ok.json()["level"] == 7
    assert signin_client.put("/api/offsets/G54", json={"trans": {"X": 3.0}}).status_code == 403
    # the setter (password level 3) turns the key to position 2: level 5 for the panel
    assert signin_client.put("/api/keyswitch", json={"position": 2}, headers=tokens[3]).json() == \
        {"position": 2, "level": 5}
    assert signin_client.get("/api/session").json()["level"] == 5
    assert signin_client.put("/api/offsets/G54", json={"trans": {"X": 3.0}}).status_code == 200
    assert signin_client.get("/api/audit", params={"name": "G54"}).json()[0]["who"] == "panel"
    with TestClient(app, client=("192.0.2.9", 5000), base_url="http://127.0.0.1:8000") as remote:
        refused = remote.post("/api/session", json={"panel": True})
        assert refused.status_code == 403 and error_of(refused)["code"] == "panel_local_only"


def test_the_level_table_is_in_the_settings_and_guarded(signin_client, tokens):
    settings = signin_client.get("/api/settings", headers=tokens[7]).json()
    assert {f"level_{f}" for f in FUNCTIONS} <= set(settings) and settings["level_offsets"] == 5
    refused = signin_client.put("/api/settings", json={"level_offsets": 7}, headers=tokens[3])
    assert refused.status_code == 403 and error_of(refused)["function"] == "users"
    assert signin_client.put("/api/settings", json={"level_offsets": 7}, headers=tokens[1]).status_code == 200
    assert signin_client.put("/api/offsets/G54", json={"trans": {"X": 2.0}}, headers=tokens[7]).status_code == 200
    assert signin_client.put("/api/settings", json={"level_offsets": 0}, headers=tokens[1]).status_code == 422
    # saving the other settings with the table unchanged needs only the settings level
    same = signin_client.put("/api/settings", json={**settings, "level_offsets": 7, "measuring_feed": 310.0},
                             headers=tokens[3])
    assert same.status_code == 200, same.text


def test_administration_over_the_api(signin_client, tokens):
    assert [u["name"] for u in signin_client.get("/api/users", headers=tokens[1]).json()] == ["anna"]
    made = signin_client.post("/api/tokens", json={"name": "plc", "level": 5}, headers=tokens[1])
    assert made.status_code == 201 and made.json()["token"].startswith("hmi_")
    assert signin_client.get("/api/machine", headers={"Authorization": f"Bearer {made.json()['token']}"}).status_code == 200
    assert "token" not in signin_client.get("/api/tokens", headers=tokens[1]).json()[0]
    assert signin_client.delete("/api/tokens/plc", headers=tokens[1]).status_code == 200
    revoked = signin_client.get("/api/machine", headers={"Authorization": f"Bearer {made.json()['token']}"})
    assert revoked.status_code == 401
    assert signin_client.post("/api/users", json={"name": "anna", "password": "abcdefgh", "level": 3},
                              headers=tokens[1]).status_code == 409
    kinds = [r["kind"] for r in signin_client.get("/api/audit", headers=tokens[1]).json()]
    assert "token" in kinds

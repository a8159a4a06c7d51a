"""Answers schemathesis's contract checks want (issue 25 item 7): a 405 names the allowed methods
(Allow), and an empty ``Authorization: Bearer`` of a trainer-mode client counts as no credentials."""

from __future__ import annotations


def test_a_405_names_the_allowed_methods(client):
    answer = client.delete("/api/machine")
    assert answer.status_code == 405 and answer.json()["error"]["code"] == "method_not_allowed"
    assert set(answer.headers["Allow"].replace(" ", "").split(",")) == {"GET"}


def test_an_empty_bearer_is_no_credentials_in_trainer_mode(client):
    assert client.get("/api/machine", headers={"Authorization": "Bearer "}).status_code == 200
    assert client.put("/api/machine/override", json={"feed": 80.0},
                      headers={"Authorization": "Bearer "}).status_code == 200


def test_an_empty_bearer_is_still_refused_with_sign_in_on(app, client):
    app.state.access.add_user("anna", 3, "anna-pw-333")
    answer = client.get("/api/machine", headers={"Authorization": "Bearer "})
    assert answer.status_code == 401

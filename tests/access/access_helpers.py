"""Helpers of the access tests."""

from __future__ import annotations

PASSWORDS = {"manu": ("manufacturer-pw", 1), "serv": ("service-pw", 2), "anna": ("user-pw-3", 3)}
ORIGIN = "http://testserver"          # the TestClient's own origin


def error_of(response) -> dict:
    body = response.json()
    assert set(body) == {"error"}, body
    return body["error"]


def g54(client, headers=None) -> dict:
    response = client.get("/api/offsets/G54", headers=headers or {})
    assert response.status_code == 200, response.text
    return response.json()

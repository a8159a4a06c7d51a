"""CSRF, Origin, Host, JSON-only and the security headers (design.md §9.2), with the in-process
client: forged requests are refused and change nothing; the HMI's own kind of request passes."""

from __future__ import annotations

import re

import pytest
from access_helpers import ORIGIN, error_of, g54
from fastapi.testclient import TestClient

HTMX = {"HX-Request": "true"}


def page_token(client) -> str:
    """The token a page of the HMI carries (hx-headers on <body>); its cookie is now set."""
    html = client.get("/offsets").text
    return re.search(r'hx-headers=\'\{"X-CSRFToken": "([^"]+)"\}\'', html).group(1)


# --- Origin / Referer ------------------------------------------------------------------------------------

@pytest.mark.parametrize("origin", ["http://127.0.0.1:9999", "http://evil.example", "null", "http://testserver:81"])
def test_a_foreign_origin_is_refused_and_changes_nothing(client, origin):
    token = page_token(client)
    before = g54(client)
    position = client.get("/api/machine").json()["mcs"]
    for response in (
        client.post("/offsets/G54/trans.X", data={"value": "777.7", "csrftoken": token},
                    headers={"Origin": origin}),
        client.put("/api/offsets/G54", json={"trans": {"X": 777.7}}, headers={"Origin": origin, "X-CSRFToken": token}),
        client.post("/api/machine/jog", json={"axis": "X", "distance": 5.0}, headers={"Origin": origin}),
        client.post("/api/sim/scenario", json={"reset_data": True}, headers={"Origin": origin}),
    ):
        assert response.status_code == 403, response.text
        assert error_of(response)["code"] == "cross_origin"
    assert g54(client) == before
    assert client.get("/api/machine").json()["mcs"] == position       # the jog moved nothing


def test_a_foreign_referer_without_origin_is_refused(client):
    before = g54(client)
    response = client.post("/offsets/G54/trans.X", data={"value": "5"}, headers={"Referer": "http://evil.example/x"})
    assert response.status_code == 403 and error_of(response)["code"] == "cross_origin"
    assert g54(client) == before


def test_a_same_origin_browser_request_needs_the_token(client):
    before = g54(client)
    missing = client.post("/offsets/G54/trans.X", data={"value": "5"}, headers={"Origin": ORIGIN, **HTMX})
    assert missing.status_code == 403 and error_of(missing)["code"] == "csrf"
    token = page_token(client)
    wrong = client.post("/offsets/G54/trans.X", data={"value": "5"},
                        headers={"Origin": ORIGIN, "X-CSRFToken": token[:-2] + "xx", **HTMX})
    assert wrong.status_code == 403 and error_of(wrong)["code"] == "csrf"
    assert g54(client) == before
    header = client.post("/offsets/G54/trans.X", data={"value": "5"},
                         headers={"Origin": ORIGIN, "X-CSRFToken": token, **HTMX})
    assert header.status_code == 200 and g54(client)["trans"]["X"] == 5.0
    field = client.post("/offsets/G54/trans.Y", data={"value": "6", "csrftoken": token},
                        headers={"Referer": f"{ORIGIN}/offsets"})
    assert field.status_code == 200 and g54(client)["trans"]["Y"] == 6.0
    api = client.put("/api/offsets/G54", json={"trans": {"Z": 7.0}}, headers={"Origin": ORIGIN, "X-CSRFToken": token})
    assert api.status_code == 200


def test_a_browser_without_the_cookie_is_refused(app):
    with TestClient(app) as fresh:
        response = fresh.put("/api/offsets/G54", json={"trans": {"X": 1.0}},
                             headers={"Origin": ORIGIN, "X-CSRFToken": "whatever"})
        assert response.status_code == 403 and error_of(response)["code"] == "csrf"


def test_non_browser_clients_need_no_token(client, access):
    """No Origin and no Referer: no browser's request (JSON API clients, form-posting scripts)."""
    assert client.put("/api/offsets/G54", json={"trans": {"X": 1.0}}).status_code == 200
    assert client.post("/api/machine/reset").status_code == 200
    assert client.post("/offsets/G54/trans.Y", data={"value": "2"}).status_code == 200
    secret, _ = access.add_token("mes", 5)
    bearer = client.put("/api/offsets/G54", json={"trans": {"X": 3.0}},
                        headers={"Authorization": f"Bearer {secret}", "Origin": ORIGIN})
    assert bearer.status_code == 200


def test_the_cookie_is_strict_and_the_token_is_in_the_page(client):
    response = client.get("/jog")
    cookie = response.headers.get("set-cookie", "")
    assert "csrftoken=" in cookie and "SameSite=Strict" in cookie
    assert 'hx-headers=\'{"X-CSRFToken": "' in response.text


def test_native_forms_carry_the_csrf_field(client):
    html = client.get("/measure/workpiece/tilted-setup").text
    forms = re.findall(r"<form[^>]*method=\"post\"[^>]*>(.*?)</form>", html, flags=re.S)
    assert forms and all('name="csrftoken"' in body for body in forms)
    signin = client.get("/signin").text
    assert signin.count('name="csrftoken"') >= 1


# --- JSON only ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("content_type, body", [
    ("text/plain", '{"trans": {"X": 777.7}}'),
    ("application/x-www-form-urlencoded", "trans=777.7"),
    ("multipart/form-data; boundary=xx", '--xx\r\nContent-Disposition: form-data; name="a"\r\n\r\n1\r\n--xx--\r\n'),
    (None, '{"trans": {"X": 777.7}}'),
])
def test_the_json_api_refuses_other_bodies(client, content_type, body):
    before = g54(client)
    headers = {"content-type": content_type} if content_type else {}
    response = client.put("/api/offsets/G54", content=body, headers=headers)
    assert response.status_code == 415, response.text
    assert error_of(response)["code"] == "unsupported_media_type"
    scenario = client.post("/api/sim/scenario", content='{"reset_data": true}', headers={"content-type": "text/plain"})
    assert scenario.status_code == 415
    assert g54(client) == before


# --- Host -------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("host", ["evil.example", "evil.example:8000", "127.0.0.1.evil.example", "10.1.2.3"])
def test_an_unknown_host_is_400_and_changes_nothing(app, host):
    with TestClient(app, base_url=f"http://{host}", client=("127.0.0.1", 5000)) as rebound:
        for response in (rebound.get("/api/machine"), rebound.get("/jog"),
                         rebound.put("/api/offsets/G54", json={"trans": {"X": 777.7}})):
            assert response.status_code == 400
            assert error_of(response)["code"] == "invalid_host"
    with TestClient(app) as client:
        assert g54(client)["trans"]["X"] == 0.0


@pytest.mark.parametrize("host", ["127.0.0.1:8000", "localhost:8000", "[::1]:8000", "LOCALHOST"])
def test_the_loopback_names_are_trusted(app, host):
    with TestClient(app, base_url=f"http://{host}", client=("127.0.0.1", 5000)) as local:
        assert local.get("/api/health").status_code == 200


def test_configured_names_are_trusted(tmp_path, scenario_file):
    from app.config import Settings
    from app.main import create_app

    app = create_app(Settings(db_path=tmp_path / "h.db", scenario_path=scenario_file, trusted_hosts=["hmi.plant.local"]))
    with TestClient(app, base_url="http://hmi.plant.local", client=("127.0.0.1", 5000)) as client:
        assert client.get("/api/health").status_code == 200


# --- headers ------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("path", ["/jog", "/offsets", "/api/machine", "/signin", "/api/nothing-here"])
def test_every_answer_forbids_framing_and_sniffing(client, path):
    response = client.get(path)
    assert response.headers["x-frame-options"] == "DENY"
    assert response.headers["x-content-type-options"] == "nosniff"
    csp = response.headers["content-security-policy"]
    assert "frame-ancestors 'none'" in csp and "script-src 'self'" in csp
    assert "unsafe-eval" not in csp and "'unsafe-inline'" not in csp.split("script-src")[1].split(";")[0]


def test_pages_load_only_the_products_own_scripts(client):
    for path in ("/jog", "/offsets", "/measure/workpiece/edge/set", "/settings", "/signin"):
        html = client.get(path).text
        assert not re.search(r"<script(?![^>]*\bsrc=)[^>]*>", html), path            # no inline script
        assert all(src.startswith("/static/") for src in re.findall(r'<script[^>]*src="([^"]+)"', html))
        assert "hx-on" not in html and "javascript:" not in html

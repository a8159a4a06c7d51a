"""The polls answered from their cached bytes (app/web/fast_reads.py, issue 30 item 2): the same
status, headers and body as the routes themselves give, the state after a change, the request
checks outside it still applied, and only a repeat answered without the route."""

from __future__ import annotations

import pytest
from fastapi.testclient import TestClient

from app.config import Settings
from app.main import create_app
from app.web.fast_reads import CachedReads

POLLS = [("/api/machine", {}), ("/ui/position", {}),
         ("/ui/position", {"X-Panel-Coords": "MCS"}), ("/ui/position?lang=de", {})]


def _app(tmp_path, scenario_file, name: str, fast: bool):
    app = create_app(Settings(db_path=tmp_path / f"{name}.db", scenario_path=scenario_file))
    if not fast:       # the middleware stack is built at the first request: the routes answer alone
        app.user_middleware = [m for m in app.user_middleware if m.cls is not CachedReads]
    return app


def _answer(client, path: str, headers: dict) -> tuple:
    client.cookies.clear()          # each as a new tab (a language chosen is set again)
    response = client.get(path, headers=headers)
    return response.status_code, sorted(response.headers.items()), response.content


def test_polls_answer_as_the_routes_do(tmp_path, scenario_file):
    with (TestClient(_app(tmp_path, scenario_file, "fast", True)) as fast,
          TestClient(_app(tmp_path, scenario_file, "route", False)) as route):
        for step in range(3):
            if step == 1:
                for client in (fast, route):
                    assert client.post("/api/machine/jog", json={"axis": "X", "distance": 2.5}).status_code == 200
            if step == 2:
                for client in (fast, route):
                    assert client.post("/api/machine/activate", json={"offset": "G54"}).status_code == 200
            for path, headers in POLLS:
                first = _answer(fast, path, headers)
                assert first[0] == 200
                assert first == _answer(route, path, headers), path
                assert _answer(fast, path, headers) == first, path      # a repeat: the cached bytes
        assert fast.get("/api/machine").json()["mcs"]["X"] == pytest.approx(102.5)
        assert fast.get("/api/machine").json()["active_offset"] == "G54"


def test_a_repeated_poll_does_not_reach_the_routes(tmp_path, scenario_file):
    app = _app(tmp_path, scenario_file, "count", True)
    reached = []
    with TestClient(app) as client:
        for path, headers in POLLS:
            _answer(client, path, headers)                  # the position blocks are made by the route
        inner = app.middleware_stack
        while not isinstance(inner, CachedReads):
            inner = inner.app
        router = inner.app

        async def counting(scope, receive, send):
            reached.append(scope["path"])
            await router(scope, receive, send)

        inner.app = counting
        for path, headers in POLLS:
            assert _answer(client, path, headers)[0] == 200
        assert reached == []
        assert client.head("/api/machine").status_code == 405     # another method: the usual way
        assert client.get("/api/machines").status_code == 404     # another path
        assert reached == ["/api/machine", "/api/machines"]


def test_the_request_checks_outside_still_apply(tmp_path, scenario_file):
    with TestClient(_app(tmp_path, scenario_file, "checks", True)) as client:
        client.get("/api/machine")
        answer = client.get("/api/machine")
        assert answer.headers["x-frame-options"] == "DENY"           # SecurityHeaders
        assert "content-security-policy" in answer.headers
        wrong_host = client.get("/api/machine", headers={"Host": "evil.example"})
        assert wrong_host.status_code == 400
        assert wrong_host.json()["error"]["code"] == "invalid_host"
        client.get("/ui/position")
        chosen = client.get("/ui/position?lang=zh")                   # the language's cookie
        assert "hmi_lang=zh" in chosen.headers.get("set-cookie", "") or chosen.cookies
        # sign-in on: no credentials is 401, however often the answer was given before
        app = client.app
        app.state.access.add_user("anna", 3, "correct horse battery")
        refused = client.get("/api/machine")
        assert refused.status_code == 401
        assert refused.json()["error"]["code"] == "unauthenticated"
        assert client.get("/ui/position", follow_redirects=False).status_code in (401, 303)

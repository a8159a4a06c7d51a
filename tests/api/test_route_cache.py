"""app/route_cache.py: the kept route matches and routes versions never hide a route added later,
and a path parameter is each request's own."""

from __future__ import annotations

from fastapi import APIRouter, FastAPI
from fastapi.testclient import TestClient

from app import route_cache


def _app() -> tuple[FastAPI, APIRouter]:
    assert route_cache.install()
    inner = APIRouter(prefix="/inner")
    outer = APIRouter(prefix="/outer")

    @inner.get("/item/{key}")
    def item(key: str) -> dict:
        return {"key": key}

    outer.include_router(inner)
    app = FastAPI()
    app.include_router(outer)
    return app, inner


def test_a_route_added_after_requests_is_found():
    app, inner = _app()
    with TestClient(app) as client:
        for _ in range(3):
            assert client.get("/outer/inner/late").status_code == 404
            assert client.get("/outer/inner/item/a").json() == {"key": "a"}

        @inner.get("/late")
        def late() -> dict:
            return {"late": True}

        assert client.get("/outer/inner/late").json() == {"late": True}
        assert client.get("/outer/inner/item/b").json() == {"key": "b"}


def test_path_parameters_are_each_requests_own():
    app, _inner = _app()
    with TestClient(app) as client:
        for key in ("a", "b", "a", "c", "b"):
            assert client.get(f"/outer/inner/item/{key}").json() == {"key": key}

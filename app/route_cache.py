"""Route matching remembered per path (issue 30: polls and NC Start).

FastAPI (>= 0.16x) keeps an included router apart (``_IncludedRouter``) and matches a request
against its routes at every level of inclusion, and again when it hands the request down: a screen
request such as ``GET /ui/position`` tries every one of the API's routes twice before the screens'
router. The routes do not change after start-up, so the answer of ``_IncludedRouter._match`` for
one (method, path, root path) is kept, for as long as the router's routes version stays the same
(FastAPI raises it when a route is added). The answers are FastAPI's own: a cached one is handed out
as a copy (its scope and path parameters), so a request can never change another's.

Only HTTP requests are cached (a WebSocket or lifespan scope goes the usual way). Without the
internals this relies on (another FastAPI), ``install`` changes nothing.
"""

from __future__ import annotations

from typing import Any

CACHED_PATHS = 2048          # answers kept per router (session ids make paths without end)
_MARK = "_hmi_route_cache"


def install() -> bool:
    """Wrap ``fastapi.routing._IncludedRouter._match`` once per process; False when FastAPI has no
    such method (nothing changed)."""
    try:
        from fastapi.routing import _IncludedRouter
    except ImportError:
        return False
    original = getattr(_IncludedRouter, "_match", None)
    if original is None or not callable(original):
        return False
    if getattr(original, _MARK, False):
        return True

    def _match(self, scope) -> Any:
        if scope.get("type") != "http":
            return original(self, scope)
        version = self.original_router._get_routes_version()
        state = self.__dict__.get(_MARK)
        if state is None or state[0] != version:
            state = (version, {})
            self.__dict__[_MARK] = state
        answers = state[1]
        key = (scope.get("method"), scope.get("path"), scope.get("root_path", ""))
        answer = answers.get(key)
        if answer is None:
            answer = original(self, scope)
            if len(answers) >= CACHED_PATHS:
                answers.clear()
            answers[key] = answer
        match, child_scope, route, context = answer
        return match, _copy_scope(child_scope), route, context

    setattr(_match, _MARK, True)
    _match.__wrapped__ = original          # type: ignore[attr-defined]
    _IncludedRouter._match = _match         # type: ignore[method-assign]
    _remember_routes_versions()
    return True


_epoch = [0]            # raised whenever any router's routes change


def _remember_routes_versions() -> None:
    """``APIRouter._get_routes_version()`` walks every route of every included router (about 60
    calls and some thousand ``isinstance`` per request that the path cache does not answer, e.g.
    one with a session id): its answer is kept per router until any router marks its routes
    changed (``_mark_routes_changed``, FastAPI's only way to raise a version)."""
    from fastapi.routing import APIRouter

    get, mark = getattr(APIRouter, "_get_routes_version", None), getattr(APIRouter, "_mark_routes_changed", None)
    if get is None or mark is None or getattr(get, _MARK, False):
        return

    def _mark_routes_changed(self) -> None:
        _epoch[0] += 1
        mark(self)

    def _get_routes_version(self, seen=None) -> int:
        if seen is not None:
            return get(self, seen)
        epoch = _epoch[0]           # read first: a change while walking leaves the kept answer stale
        kept = self.__dict__.get(_MARK)
        if kept is not None and kept[0] == epoch:
            return kept[1]
        version = get(self)
        self.__dict__[_MARK] = (epoch, version)
        return version

    setattr(_get_routes_version, _MARK, True)
    APIRouter._mark_routes_changed = _mark_routes_changed     # type: ignore[method-assign]
    APIRouter._get_routes_version = _get_routes_version       # type: ignore[method-assign]


def _copy_scope(child_scope: dict) -> dict:
    """A copy a request may update: the scope and its path parameters (values are immutable)."""
    copied = dict(child_scope)
    params = copied.get("path_params")
    if isinstance(params, dict):
        copied["path_params"] = dict(params)
    return copied

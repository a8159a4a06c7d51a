"""``GET /api/events``: the live feed as server-sent events (design.md §9.9, app/services/live.py)."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Query, Request
from sse_starlette import EventSourceResponse

from app.access.deps import needs
from app.deps import MachineDep, WorkflowDep
from app.services.live import LiveFeed

router = APIRouter(tags=["live"])


@router.get("/events", name="api_events", dependencies=[needs("view")], response_class=EventSourceResponse,
            responses={200: {"content": {"text/event-stream": {}},
                             "description": "`machine` and `session` events, JSON data with a `seq` number"}})
async def events(request: Request, machine: MachineDep, workflow: WorkflowDep,
                 limit: Annotated[int | None, Query(ge=1, le=100_000, description="close after this many events")]
                 = None):
    """Server-sent events: ``machine`` (the ``GET /api/machine`` body) 20 times a second while the
    machine moves, on every change and at least 4 times a second at rest; ``session`` (the
    ``GET /api/measure/{id}`` body, ``{"id": null}`` without a session) on every change, e.g. the
    progress of a running NC Start (point, pass, step)."""
    def session() -> dict | None:
        current = workflow.session
        return None if current is None else current.to_api()

    feed = LiveFeed(machine.status, session, machine.changes)
    return EventSourceResponse(feed.events(limit, request.is_disconnected), ping=15,
                               headers={"Cache-Control": "no-store", "X-Accel-Buffering": "no"})

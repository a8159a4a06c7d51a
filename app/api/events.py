"""``GET /api/events``: the live feed as server-sent events (design.md §9.9, app/services/live.py)."""

from __future__ import annotations

from collections.abc import AsyncIterator
from typing import Annotated

from fastapi import APIRouter, Query, Request
from sse_starlette import EventSourceResponse

from app.access.deps import needs
from app.deps import MachineDep, WorkflowDep
from app.services.live import LiveHub

router = APIRouter(tags=["live"])


class LiveEventResponse(EventSourceResponse):
    """sse-starlette's response without a cancel scope around every send when no send timeout is
    set (as here): 200 subscribers at 20 events a second are 4 000 sends a second, and the scope
    cost a quarter of the feed's CPU (issue 30 item 1). A send that fails is marked as the library
    does, so its clean-up and shutdown work as before."""

    async def _send_with_timeout(self, send, message) -> None:
        if self.send_timeout is not None:
            return await super()._send_with_timeout(send, message)
        try:
            await send(message)
        except BaseException:
            self._send_interrupted = True
            raise


@router.get("/events", name="api_events", dependencies=[needs("view")], response_class=LiveEventResponse,
            responses={200: {"content": {"text/event-stream": {}},
                             "description": "`machine` and `session` events, JSON data with a `seq` number"}})
async def events(request: Request, machine: MachineDep, workflow: WorkflowDep,
                 limit: Annotated[int | None, Query(ge=1, le=100_000, description="close after this many events")]
                 = None,
                 tab: Annotated[str | None, Query(min_length=1, max_length=64, pattern=r"^[A-Za-z0-9_-]+$",
                                                  description="the browser tab: its held jog stops when "
                                                              "this feed drops (issue 24 §6)")] = None):
    """Server-sent events: ``machine`` (the ``GET /api/machine`` body) 20 times a second while the
    machine moves, on every change and at least 4 times a second at rest (the same state again:
    the heartbeat); ``session`` (the
    ``GET /api/measure/{id}`` body, ``{"id": null}`` without a session) on every change, e.g. the
    progress of a running NC Start (point, pass, step)."""
    stream = _hub(request, machine, workflow).events(limit)
    if tab is not None:
        machine.tab_back(tab)
        stream = _held_jog_stops_with(stream, machine, tab)
    return LiveEventResponse(stream, ping=15,
                               headers={"Cache-Control": "no-store", "X-Accel-Buffering": "no"})


def _hub(request: Request, machine, workflow) -> LiveHub:
    """The HMI's one live feed (made on first use; a scenario load keeps both services)."""
    hub = getattr(request.app.state, "live_hub", None)
    if hub is None or hub.sources != (machine, workflow):
        def session() -> dict | None:
            current = workflow.session
            return None if current is None else current.to_api()

        hub = LiveHub(machine.snapshot, session, machine.changes)
        hub.sources = (machine, workflow)
        request.app.state.live_hub = hub
    return hub


async def _held_jog_stops_with(stream: AsyncIterator[bytes], machine, tab: str) -> AsyncIterator[bytes]:
    """The feed of ``tab``; when it ends (the browser died, the tab closed, the network went) the
    jog that tab holds stops at once, not only when its renewals run out."""
    try:
        async for item in stream:
            yield item
    finally:
        machine.tab_gone(tab)       # synchronous: a cancelled stream cannot await any more

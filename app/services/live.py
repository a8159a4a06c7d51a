"""The live feed behind ``GET /api/events`` (design.md §9.9): machine state and measuring-session
changes as server-sent events.

The feed samples the services (no hooks into the machine or the workflow), so a screen needs no
polling: ``machine`` carries the ``GET /api/machine`` body, ``session`` the ``GET /api/measure/{id}``
body (``{"id": null}`` when no session is open), each with a sequence number ``seq``.

Rates: while the machine moves every ``MOVING_S`` (20 per second; design.md §9.9 promises >= 5);
at rest on every change and the same state again every ``HEARTBEAT_S`` (>= 4 a second: the
heartbeat the screens use to tell a lost connection from a quiet machine). A change the HMI makes
itself without motion (a probe deflected by hand, design.md §10.4) wakes the feed at once through a
``ChangeSignal`` instead of waiting for the next sample, so that the screens show it within a few
milliseconds.

One ``LiveHub`` per HMI serves every subscriber (issue 30 item 1): the state is read and encoded
once per tick, not once per subscriber; a subscriber only adds its ``seq`` to the shared bytes.
"""

from __future__ import annotations

import asyncio
import json
import threading
import time
from collections.abc import AsyncIterator, Callable
from typing import Any

import anyio

MOVING_S = 0.045      # 22 a second: >= 20 even when a tick comes late
HEARTBEAT_S = 0.2     # at rest the state again this often: >= 4 a second whatever the scheduling
TICK_IDLE_S = 0.05
RETRY_MS = 500          # a browser reconnects this soon after a lost connection


class ChangeSignal:
    """"Something changed": calls the subscribed listeners (the live feed's sampler, the probe
    test), from any thread."""

    def __init__(self) -> None:
        self._listeners: list[Callable[[], None]] = []
        self.count = 0                  # changes so far

    def subscribe(self, listener: Callable[[], None]) -> None:
        """``listener()`` after each change, in the thread that reported it."""
        self._listeners.append(listener)

    def notify(self) -> None:
        self.count += 1
        for listener in list(self._listeners):
            listener()


class LiveHub:
    """The live feed of one HMI for all its subscribers (issue 30 item 1): one sampler thread reads
    the state, encodes each change once and wakes the subscribers, which send those bytes with
    their own sequence number. While the machine moves it publishes every ``MOVING_S``; at rest
    it checks every ``TICK_IDLE_S`` (a ``ChangeSignal`` wakes it at once) and publishes a change
    when there is one and the same bytes again as the heartbeat every ``HEARTBEAT_S``. The thread
    runs while somebody listens."""

    def __init__(self, snapshot: Callable[[], Any], session: Callable[[], dict | None],
                 changes: ChangeSignal | None = None):
        self._snapshot = snapshot               # () -> MachineService.snapshot(): .body, .json, .version
        self._session = session
        self._lock = threading.Lock()           # subscribers, thread, loop waiters
        self._sample_lock = threading.Lock()    # one sample at a time
        self._wake = threading.Event()
        self._subscribers = 0
        self._thread: threading.Thread | None = None
        self._waiters: dict[asyncio.AbstractEventLoop, asyncio.Event] = {}
        self._last_version: int | None = None
        self._session_text: str | None = None
        self._next_heartbeat = 0.0
        self.busy = False
        # what a subscriber sends: (count, JSON body without its closing brace); count rises per publish
        self.machine: tuple[int, bytes] = (0, b"")
        self.session: tuple[int, bytes] = (0, b"")
        self.published = 0
        self.sources: tuple = ()                # what it was made for (app/api/events.py)
        if changes is not None:
            changes.subscribe(self._wake.set)

    # --- subscribers (on any event loop) ---------------------------------------------------
    async def join(self) -> None:
        with self._lock:
            self._subscribers += 1
            if self._thread is None:
                self._thread = threading.Thread(target=self._run, name="live-feed", daemon=True)
                self._thread.start()
        await anyio.to_thread.run_sync(self.sample)      # the newest state for the newcomer

    def leave(self) -> None:
        with self._lock:
            self._subscribers -= 1

    async def wait(self, seen: int) -> None:
        """Until something was published after the first ``seen`` publications."""
        loop = asyncio.get_running_loop()
        while self.published == seen:
            with self._lock:
                event = self._waiters.get(loop)
                if event is None:
                    event = self._waiters[loop] = asyncio.Event()
            await event.wait()

    def _wake_loop(self, loop: asyncio.AbstractEventLoop) -> None:
        with self._lock:
            event = self._waiters.pop(loop, None)
        if event is not None:
            event.set()

    # --- the sampler ----------------------------------------------------------------------
    def _run(self) -> None:
        next_tick = time.monotonic()
        while True:
            with self._lock:
                if self._subscribers <= 0:
                    self._thread = None
                    return
            self._wake.clear()
            self.sample()
            next_tick += MOVING_S if self.busy else TICK_IDLE_S
            now = time.monotonic()
            if next_tick < now:
                next_tick = now
            self._wake.wait(next_tick - now)

    def sample(self) -> None:
        """Read the state; publish what changed (and the heartbeat when due)."""
        with self._sample_lock:
            snapshot = self._snapshot()
            session = self._session() or {"id": None}
            now = time.monotonic()
            published = False
            self.busy = bool(snapshot.body.get("busy"))
            if self.busy or snapshot.version != self._last_version or now >= self._next_heartbeat:
                # on a fixed schedule from the last change: no drift below the promised rate
                heartbeat = snapshot.version == self._last_version and not self.busy
                self._next_heartbeat = max(self._next_heartbeat + HEARTBEAT_S, now) if heartbeat \
                    else now + HEARTBEAT_S
                self._last_version = snapshot.version
                self.machine = (self.machine[0] + 1, snapshot.json[:-1])
                published = True
            session_text = json.dumps(session, default=str)
            if session_text != self._session_text:
                self._session_text = session_text
                self.session = (self.session[0] + 1, session_text[:-1].encode("utf-8"))
                published = True
            if published:
                self._publish()

    def _publish(self) -> None:
        with self._lock:
            self.published += 1
            loops = list(self._waiters)
        for loop in loops:
            try:
                loop.call_soon_threadsafe(self._wake_loop, loop)
            except RuntimeError:        # that loop has closed (its feeds are gone)
                with self._lock:
                    self._waiters.pop(loop, None)

    # --- a subscriber's stream --------------------------------------------------------------
    async def events(self, limit: int | None = None) -> AsyncIterator[bytes]:
        """The SSE bytes of one subscriber until ``limit`` events were sent (or it leaves)."""
        await self.join()
        try:
            seq = 0
            sent_machine = sent_session = 0
            while limit is None or seq < limit:
                seen = self.published
                machine, session = self.machine, self.session
                if machine[0] != sent_machine:
                    sent_machine = machine[0]
                    seq += 1
                    yield _event(b"machine", seq, machine[1])
                if session[0] != sent_session and (limit is None or seq < limit):
                    sent_session = session[0]
                    seq += 1
                    yield _event(b"session", seq, session[1])
                if limit is not None and seq >= limit:
                    return
                await self.wait(seen)
        finally:
            self.leave()


def _event(name: bytes, seq: int, body: bytes) -> bytes:
    """One server-sent event: the shared JSON body (without its closing brace) + this stream's ``seq``."""
    retry = b"retry: %d\r\n" % RETRY_MS if seq == 1 else b""
    return b"id: %d\r\nevent: %s\r\ndata: %s,\"seq\":%d}\r\n%s\r\n" % (seq, name, body, seq, retry)

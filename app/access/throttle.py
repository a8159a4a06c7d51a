"""Bounded password work and per-source throttling of sign-ins (design.md §9.2, §10.8).

A password check costs an argon2 run (CPU and tens of MiB). Without a bound, a flood of wrong
sign-ins starves the server (issue 25: 40 parallel failures took ``/api/health`` to 21 s and the
process to 2 GB). So:

- the checks run on ``workers`` threads of their own; at most ``queue`` more wait for them, and a
  sign-in beyond that is refused at once (429 ``sign_in_busy``), without any argon2 work;
- each source (channel + client address) may fail ``free_failures`` times; after that it must wait
  ``base_delay_s`` doubling with each further failure (at most ``max_delay_s``) before the next
  try, and a try inside the wait is refused at once (429 ``too_many_attempts``). A refused try does
  not extend the wait, and a user name is never locked: the right password from another source
  (another computer, or OPC UA against HTTP) still signs in;
- the table of sources is bounded (``max_sources``, oldest forgotten first), so many addresses
  cost bounded memory.
"""

from __future__ import annotations

import math
import threading
import time
from collections import OrderedDict
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import TypeVar

T = TypeVar("T")

HTTP, OPCUA = "http", "opcua"          # channels counted apart


class Throttled(Exception):
    """A sign-in refused before any password work; ``retry_after_s`` for the Retry-After header."""

    def __init__(self, code: str, message: str, retry_after_s: int):
        super().__init__(message)
        self.code, self.message, self.retry_after_s = code, message, retry_after_s


@dataclass
class _Failures:
    count: int
    last: float


class SignInGate:
    def __init__(self, workers: int = 1, queue: int = 8, free_failures: int = 5, base_delay_s: float = 1.0,
                 max_delay_s: float = 60.0, forget_s: float = 900.0, max_sources: int = 4096,
                 clock: Callable[[], float] = time.monotonic):
        self.workers, self.queue = workers, queue
        self.free_failures, self.base_delay_s, self.max_delay_s = free_failures, base_delay_s, max_delay_s
        self.forget_s, self.max_sources = forget_s, max_sources
        self._clock = clock
        self._lock = threading.Lock()
        # the checks run on these threads only: argon2's memory is malloc'd in their arenas, so what
        # glibc keeps after a check stays bounded by the workers, not by every request thread
        self._pool = ThreadPoolExecutor(workers, thread_name_prefix="password-check")
        self._admitted = 0                     # running + waiting
        self._sources: OrderedDict[tuple[str, str], _Failures] = OrderedDict()

    # --- per source ----------------------------------------------------------------------------
    def wait_left(self, source: tuple[str, str]) -> float:
        """Seconds this source must still wait before its next try (0: it may try now)."""
        with self._lock:
            record = self._sources.get(source)
            if record is None or record.count < self.free_failures:
                return 0.0
            return max(0.0, record.last + self._delay(record.count) - self._clock())

    def _delay(self, count: int) -> float:
        return min(self.max_delay_s, self.base_delay_s * 2 ** (count - self.free_failures))

    def failed(self, source: tuple[str, str]) -> None:
        now = self._clock()
        with self._lock:
            record = self._sources.pop(source, None)
            if record is None or now - record.last > self.forget_s:
                record = _Failures(0, now)
            record.count, record.last = record.count + 1, now
            self._sources[source] = record            # newest last
            while len(self._sources) > self.max_sources:
                self._sources.popitem(last=False)

    def succeeded(self, source: tuple[str, str]) -> None:
        with self._lock:
            self._sources.pop(source, None)

    def check_source(self, source: tuple[str, str]) -> None:
        left = self.wait_left(source)
        if left > 0:
            seconds = math.ceil(left)
            raise Throttled("too_many_attempts",
                            f"too many failed sign-ins from this computer: try again in {seconds} s", seconds)

    # --- the bounded pool --------------------------------------------------------------------
    def check_room(self) -> None:
        """Throttled when a check would find the queue full now (a look ahead, without a slot)."""
        if self._admitted >= self.workers + self.queue:
            raise Throttled("sign_in_busy", "too many sign-ins at once: try again in a moment", 1)

    def run(self, check: Callable[[], T]) -> T:
        """``check()`` on one of the ``workers`` password threads, after waiting in a queue of at
        most ``queue``; Throttled at once when the queue is full."""
        with self._lock:
            if self._admitted >= self.workers + self.queue:
                raise Throttled("sign_in_busy", "too many sign-ins at once: try again in a moment", 1)
            self._admitted += 1
        try:
            return self._pool.submit(check).result()
        finally:
            with self._lock:
                self._admitted -= 1

    @property
    def admitted(self) -> int:
        """Checks running or waiting now."""
        return self._admitted

    @property
    def sources(self) -> int:
        return len(self._sources)

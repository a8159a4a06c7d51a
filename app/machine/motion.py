"""Motion of the simulated axes: one straight travel at a time, in (scaled) real time.

The travel is played out so that ``status()`` from another thread sees the axes move: the
position is updated every ``TICK_S`` under the machine's lock, and the lock is never held
while sleeping. ``time_scale`` 0 (tests) moves at once, without waiting.

Decisions (where the spec leaves room):
- One motion at a time: a second one is refused with MachineBusy while the first runs.
- Reset aborts a motion at its current position (outcome "reset"), ``stop()`` ends it without
  an alarm (outcome "stop", the jog key released); both wait up to ``WAIT_IDLE_S`` for it.
- The feed in effect (override included) is read continuously for the timing:
  duration = length / feed · 60 · time_scale (design.md §5).
- A continuous jog runs its motion in a background thread until stop()/Reset/limit/collision.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

import numpy as np

from .protocol import MachineBusy

TICK_S = 0.01                 # motion update period at time_scale > 0
WAIT_IDLE_S = 2.0             # how long abort()/stop() wait for a motion to end


class Motion:
    """The axes' position and the one motion that may be moving them."""

    def __init__(self, lock: threading.RLock, position: np.ndarray) -> None:
        self._lock = lock                        # the machine's state lock, shared
        self._idle = threading.Condition(lock)
        self._abort = threading.Event()
        self._stop = threading.Event()
        self._busy = False
        self._thread: threading.Thread | None = None
        self.position = position                 # axes now (MCS); read and written under the lock

    @property
    def busy(self) -> bool:
        return self._busy

    def begin(self, may_move: Callable[[], None] = lambda: None) -> None:
        """Claim the axes for one motion; ``may_move`` may refuse it (raise) first."""
        with self._lock:
            if self._busy:
                raise MachineBusy("a motion is already running")
            may_move()
            self._busy = True
            self._abort.clear()
            self._stop.clear()

    def finish(self) -> None:
        with self._idle:
            self._busy = False
            self._idle.notify_all()

    def in_background(self, run: Callable[[], None]) -> None:
        """Run a claimed motion in a thread (continuous jog); ``run`` calls ``finish()``."""
        self._thread = threading.Thread(target=run, name="sim-jog", daemon=True)
        self._thread.start()

    def abort(self) -> None:
        """Reset: abort the motion at its current position and wait for it to end."""
        self._abort.set()
        self._wait_idle()

    def stop(self) -> None:
        """End the motion without an alarm and wait for it to end."""
        self._stop.set()
        self._wait_idle()

    def _wait_idle(self) -> None:
        deadline = time.monotonic() + WAIT_IDLE_S
        with self._idle:
            while self._busy and time.monotonic() < deadline:
                self._idle.wait(timeout=TICK_S)
        thread = self._thread
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout=WAIT_IDLE_S)

    def travel(self, start: np.ndarray, end: np.ndarray, feed_in_effect: Callable[[], float],
               time_scale: float) -> tuple[np.ndarray, str]:
        """Play the straight move out in scaled real time: -> (position, 'done'|'reset'|'stop').

        ``feed_in_effect()`` (mm/min) is asked at every tick, so an override change acts at once.
        """
        delta = end - start
        length = float(np.linalg.norm(delta[:3])) or float(np.linalg.norm(delta))
        if length == 0.0 or time_scale == 0.0:
            with self._lock:
                self.position = end.copy()
            return end.copy(), "done"
        travelled = 0.0
        last = time.monotonic()
        while True:
            time.sleep(TICK_S)
            now = time.monotonic()
            with self._lock:
                if self._abort.is_set():
                    return self.position.copy(), "reset"
                if self._stop.is_set():
                    return self.position.copy(), "stop"
                travelled += feed_in_effect() / 60.0 * (now - last) / time_scale
                last = now
                fraction = min(travelled / length, 1.0)
                self.position = start + fraction * delta
                if fraction >= 1.0:
                    self.position = end.copy()
                    return end.copy(), "done"

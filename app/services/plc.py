"""Simulated PLC: the interface byte DB19.DBB43 for P1..P4 (spec/jog-measuring.md §3.2).

Bits 0..3 (PLC -> HMI) are written by the PLC side (``PUT /api/plc/db19/dbb43``, the ``/plc``
test page; in a real plant the user program wired to the keys of a handheld unit, BHG): "point n
invalid, discard its measurement". Bits 4..7 (HMI -> PLC) are owned by the HMI and mirror the
open measuring session's stored points (``MeasureSession.plc_byte()``), so they are 0 with no
session, after Calculate and after the screen was left, by construction.

Handshake ([I] jog-measuring §3.2):

1. HMI sets bit 4+n-1 when Pn is stored (the session does that).
2. PLC sets bit n-1 (``write(n-1, True)``).
3. HMI invalidates Pn through ``WorkflowService.invalidate`` (exactly the softkey's effect) and
   so clears bit 4+n-1. The HMI reacts to the rising edge of bit n-1: a bit the PLC keeps set
   does not discard Pn again when it is measured anew.
4. PLC clears bit n-1. Decision: with ``auto_release`` (the default) the simulated PLC user
   program drops the request itself as soon as it sees bit 4+n-1 = 0, as the manual describes
   ("PLC holds the bit until HMI resets DBB43.4 to 0"). With ``auto_release`` off the PLC side
   holds the bit until it is written 0 (the test page's toggle button), to watch each step.

The HMI side scans the byte on every read and write (the page polls it). A request arriving while
NC Start is measuring stays pending and is served at the first scan after the measurement; a
request for a point that is not stored has nothing to discard and is acknowledged at once.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from collections.abc import Callable

from app.errors import InvalidInput, WorkflowError
from app.workflow.service import WorkflowService

PLC_BITS = range(0, 4)         # PLC -> HMI: discard request for P1..P4
HMI_BITS = range(4, 8)         # HMI -> PLC: P1..P4 measured and stored

MEANINGS = {
    **{b: f"PLC → HMI: request P{b + 1} invalid, discard its measurement" for b in PLC_BITS},
    **{b: f"HMI → PLC: P{b - 3} measured and stored" for b in HMI_BITS},
}


def check_bit(bit) -> int:
    """A PLC-writable bit number (0..3); anything else is refused naming the field ``bit``."""
    if isinstance(bit, bool) or not isinstance(bit, int):
        raise InvalidInput("bit: must be an integer 0..3", field="bit")
    if bit in HMI_BITS:
        raise InvalidInput(f"bit: DBB43.{bit} is written by the HMI (point stored); the PLC writes "
                           "bits 0..3 only", field="bit", code="hmi_owned")
    if bit not in PLC_BITS:
        raise InvalidInput(f"bit: DBB43 has bits 0..7; the PLC writes bits 0..3, not {bit}", field="bit")
    return bit


class PlcSimulator:
    """DB19.DBB43 with the HMI side of the handshake. Thread-safe."""

    def __init__(self, workflow: Callable[[], WorkflowService | None], auto_release: bool = True):
        self._workflow = workflow
        self._lock = threading.RLock()
        self._requests = 0                     # bits 0..3 as written by the PLC
        self._pending: set[int] = set()        # points whose request the HMI has not served yet
        self.auto_release = auto_release
        self._events: deque[dict] = deque(maxlen=12)

    # --- PLC side -----------------------------------------------------------------------------
    def write(self, bit, value: bool) -> dict:
        """The PLC writes bit 0..3; answers the byte after the HMI's scan."""
        bit = check_bit(bit)
        if not isinstance(value, bool):
            raise InvalidInput("value: must be true or false", field="value")
        n = bit + 1
        with self._lock:
            was = bool(self._requests >> bit & 1)
            if value and not was:
                self._requests |= 1 << bit
                self._pending.add(n)
                self._event(f"PLC set DBB43.{bit}: discard P{n}")
            elif not value and was:
                self._requests &= ~(1 << bit)
                self._pending.discard(n)
                self._event(f"PLC cleared DBB43.{bit}")
            return self.snapshot()

    def set_auto_release(self, value: bool) -> dict:
        if not isinstance(value, bool):
            raise InvalidInput("auto_release: must be true or false", field="auto_release")
        with self._lock:
            self.auto_release = value
            return self.snapshot()

    def reset(self) -> None:
        with self._lock:
            self._requests = 0
            self._pending.clear()
            self._events.clear()

    # --- HMI side -----------------------------------------------------------------------------
    def _session(self):
        workflow = self._workflow()
        return workflow, (workflow.session if workflow is not None else None)

    def _hmi_bits(self) -> int:
        _, session = self._session()
        return session.plc_byte() & 0xF0 if session is not None else 0

    def _scan(self) -> None:
        """Serve pending discard requests, then let the PLC release acknowledged ones."""
        for n in sorted(self._pending):
            workflow, session = self._session()
            stored = session is not None and n <= session.n_points and session.slot(n).stored
            if not stored:
                self._pending.discard(n)
                self._event(f"HMI: P{n} not stored, nothing to discard (DBB43.{n + 3} = 0)")
                continue
            if session.running:
                continue                       # served after the running NC Start
            try:
                workflow.invalidate(session.id, n)
            except WorkflowError:
                continue                       # busy or gone: try again at the next scan
            self._pending.discard(n)
            self._event(f"HMI invalidated P{n} and cleared DBB43.{n + 3}")
        if self.auto_release:
            hmi = self._hmi_bits()
            for bit in PLC_BITS:
                n = bit + 1
                if self._requests >> bit & 1 and n not in self._pending and not hmi >> (bit + 4) & 1:
                    self._requests &= ~(1 << bit)
                    self._event(f"PLC released DBB43.{bit} (HMI acknowledged)")

    def _event(self, text: str) -> None:
        self._events.appendleft({"time": time.strftime("%H:%M:%S"), "text": text})

    def snapshot(self) -> dict:
        """``GET /api/plc/db19``: the byte, its bits and the P1..P4 view (after a scan)."""
        with self._lock:
            self._scan()
            _, session = self._session()
            hmi = session.plc_byte() & 0xF0 if session is not None else 0
            byte = hmi | self._requests
            n_points = session.n_points if session is not None else 0
            return {
                "dbb43": byte,
                "bits": {str(b): bool(byte >> b & 1) for b in range(8)},
                "points": {f"P{n}": {"exists": n <= n_points,
                                     "stored": bool(hmi >> (n + 3) & 1),
                                     "discard_request": bool(self._requests >> (n - 1) & 1),
                                     "pending": n in self._pending} for n in range(1, 5)},
                "session": None if session is None else {"id": session.id, "task": session.task},
                "auto_release": self.auto_release,
                "events": list(self._events),
            }

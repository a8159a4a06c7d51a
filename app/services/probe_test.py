"""The probe test (design.md §10.4): does the probe switch, and does it seat again?

The operator starts the test (softkey or ``POST /api/probe/test``) and deflects the probe by hand
(the simulator: ``POST /api/sim/probe``); the test sees the probe signal come on ("switched") and
go off again ("passed"). A test that sees nothing within its time ends "not_switched". It is the
check before a calibration (QtPlasmaC's probe-test key, Renishaw: test the probe after a battery
or stylus change) and works alike for the workpiece probe and the tool probe.

Decisions (where the spec leaves room):
- The test refuses to start (409) when the probe cannot show a switch: the workpiece probe not in
  the spindle, a radio probe not armed, a probe already deflected, no tool probe on the machine.
- The signal is watched two ways: every change the HMI makes itself (a hand deflection in the
  simulator) is seen at once through the machine service's ``changes``; a change the controller
  makes on its own (a real probe, a deflection by a motion) by sampling every ``SAMPLE_S``.
- One test at a time; a new start replaces the running one; a tool change or a scenario load
  cancels it.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass, replace
from datetime import UTC, datetime

from app.errors import ConflictError, InvalidInput
from app.i18n import N_

from .machine_service import MachineService

WORKPIECE, TOOL = "workpiece", "tool"
DEFAULT_TIMEOUT_S = 30.0
MAX_TIMEOUT_S = 300.0
SAMPLE_S = 0.01
# why a test cannot start (the screens translate these texts by the catalogue)
REFUSALS = {
    "no_tool_probe": N_("This machine has no tool probe."),
    "probe_not_in_spindle": N_("The probe is not the tool in the spindle: load the probe first."),
    "probe_not_armed": N_("The probe is not switched on (armed): switch it on or change its battery."),
    "tool_probe_not_armed": N_("The tool probe is not switched on (armed): switch it on or change its battery."),
    "probe_deflected": N_("The probe is deflected already: clear the stylus, then start the test."),
    "tool_probe_deflected": N_("The tool probe is deflected already: clear it, then start the test."),
}


def _now() -> str:
    return datetime.now(UTC).isoformat(timespec="milliseconds")


@dataclass(frozen=True)
class ProbeTest:
    probe: str                       # "workpiece" | "tool"
    state: str                       # "waiting" | "switched" | "passed" | "not_switched" | "cancelled"
    started: str
    deadline: float                  # time.monotonic() at which a waiting test gives up
    switched_at: str | None = None
    released_at: str | None = None
    after_s: float | None = None     # from the start to the switch
    t0: float = 0.0                  # time.monotonic() at the start

    def to_api(self) -> dict:
        return {"probe": self.probe, "state": self.state, "started": self.started,
                "switched_at": self.switched_at, "released_at": self.released_at, "after_s": self.after_s}


class ProbeTestService:
    def __init__(self, machine: MachineService) -> None:
        self._machine = machine
        self._lock = threading.Lock()
        self._test: ProbeTest | None = None
        self._wake = threading.Event()
        machine.changes.subscribe(self._on_change)
        machine.on_discard(self._discarded)      # a tool change, a scenario load: the test ends

    # --- the API ---------------------------------------------------------------------------
    def start(self, probe: str = WORKPIECE, timeout_s: float = DEFAULT_TIMEOUT_S) -> dict:
        if probe not in (WORKPIECE, TOOL):
            raise InvalidInput("probe: \"workpiece\" or \"tool\"", field="probe")
        if isinstance(timeout_s, bool) or not isinstance(timeout_s, int | float) or not 0 < timeout_s <= MAX_TIMEOUT_S:
            raise InvalidInput(f"timeout_s: seconds, more than 0 and at most {MAX_TIMEOUT_S:g}", field="timeout_s")
        self._refuse_unready(probe, self._signal(probe))
        now = time.monotonic()
        test = ProbeTest(probe, "waiting", _now(), now + float(timeout_s), t0=now)
        with self._lock:
            self._test = test
            self._wake.set()                 # a watcher of a replaced test ends
            self._wake = threading.Event()
            wake = self._wake
        threading.Thread(target=self._watch, args=(test, wake), name="probe-test", daemon=True).start()
        return test.to_api()

    def state(self) -> dict:
        """The current (or last) test, ``{"state": "idle"}`` before the first."""
        self._observe()
        with self._lock:
            return {"state": "idle", "probe": None} if self._test is None else self._test.to_api()

    def cancel(self) -> dict:
        with self._lock:
            if self._test is not None and self._test.state in ("waiting", "switched"):
                self._test = replace(self._test, state="cancelled")
            self._wake.set()
        return self.state()

    def _discarded(self, _reason: str) -> None:
        self.cancel()

    # --- watching the signal -------------------------------------------------------------------
    def _signal(self, probe: str) -> dict | None:
        return self._machine.probe_status()["probe" if probe == WORKPIECE else "tool_probe"]

    @staticmethod
    def _refuse_unready(probe: str, signal: dict | None) -> None:
        """409 with a code and the operator's reason when the probe cannot show a switch."""
        prefix = "" if probe == WORKPIECE else "tool_"
        reason = None
        if signal is None:
            reason = "no_tool_probe"
        elif probe == WORKPIECE and not signal["in_spindle"]:
            reason = "probe_not_in_spindle"
        elif signal["armed"] is False:
            reason = prefix + "probe_not_armed"
        elif signal["deflected"]:
            reason = prefix + "probe_deflected"
        if reason is not None:
            raise ConflictError(REFUSALS[reason], code=reason.removeprefix("tool_"))

    def _on_change(self) -> None:
        self._observe()

    def _observe(self) -> None:
        """Advance the test by the probe's signal now."""
        with self._lock:
            test = self._test
        if test is None or test.state not in ("waiting", "switched"):
            return
        signal = self._signal(test.probe)
        deflected = bool(signal and signal["deflected"])
        now = time.monotonic()
        with self._lock:
            if self._test is not test:
                return
            if test.state == "waiting" and deflected:
                self._test = replace(test, state="switched", switched_at=_now(), after_s=round(now - test.t0, 3))
            elif test.state == "switched" and not deflected:
                self._test = replace(test, state="passed", released_at=_now())
            elif test.state == "waiting" and now >= test.deadline:
                self._test = replace(test, state="not_switched")

    def _watch(self, test: ProbeTest, wake: threading.Event) -> None:
        """Sample the signal while the test runs (a change the controller makes on its own)."""
        while not wake.wait(SAMPLE_S) and time.monotonic() <= test.deadline + SAMPLE_S:
            self._observe()
            with self._lock:
                current = self._test
            if current is None or current.t0 != test.t0 or current.state not in ("waiting", "switched"):
                return

"""The alarms a control shows until Reset: one book for every Machine implementation.

The simulated milling machine, the simulated lathe and the LinuxCNC adapter keep their shown
alarms here (issue 27 item 1), so "shown once", "Reset clears the resettable ones" and "the
probe is broken exactly while PROBE_BROKEN is shown" are decided in one place.

Decisions:
- An alarm with the code and text of one already shown is not shown twice (``raise_`` returns
  the alarm all the same, so the caller can raise ``MachineAlarm`` with it).
- The book shares its owner's lock (an ``RLock``): the owner may hold it while calling.
"""

from __future__ import annotations

import threading

from engine import alarms

from .protocol import Alarm, MachineAlarm

PROBE_BROKEN_TEXT = "Probe broken: overtravel beyond the permissible deflection"


class AlarmBook:
    """The shown alarms of one control, guarded by the control's lock."""

    def __init__(self, lock: threading.RLock) -> None:
        self._lock = lock
        self._shown: list[Alarm] = []

    def shown(self) -> tuple[Alarm, ...]:
        with self._lock:
            return tuple(self._shown)

    def raise_(self, alarm: Alarm) -> Alarm:
        """Show ``alarm`` unless the same one is shown already; returns it."""
        with self._lock:
            if all(a.code != alarm.code or a.text != alarm.text for a in self._shown):
                self._shown.append(alarm)
        return alarm

    def refusal(self, definition: alarms.AlarmDef, text: str) -> MachineAlarm:
        """Show the catalogue alarm ``definition`` with ``text``; the exception to raise with it."""
        return MachineAlarm(self.raise_(Alarm.of(definition, text)))

    def reset(self) -> None:
        """NC Reset: the resettable alarms go, the others stay."""
        with self._lock:
            self._shown = [a for a in self._shown if not a.resettable]

    def clear(self) -> None:
        with self._lock:
            self._shown = []

    # --- the broken stylus (measuring-math §1.3: not resettable) ------------------------------
    def broken(self) -> Alarm | None:
        """The broken-stylus alarm: the probe is broken exactly while it is shown."""
        with self._lock:
            return next((a for a in self._shown if a.is_(alarms.PROBE_BROKEN)), None)

    def break_probe(self) -> Alarm:
        return self.raise_(Alarm.of(alarms.PROBE_BROKEN, PROBE_BROKEN_TEXT))

    def repair_probe(self) -> None:
        """A tool change (a new stylus) ends the broken-stylus alarm."""
        with self._lock:
            broken = self.broken()
            self._shown = [a for a in self._shown if a is not broken]

    def refuse_if_broken(self) -> None:
        """A broken probe refuses every motion while it is in the spindle."""
        broken = self.broken()
        if broken is not None:
            raise MachineAlarm(broken)

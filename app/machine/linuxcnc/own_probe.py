"""Probing with the machine's own probe on LinuxCNC (``--linuxcnc-ini``, issue 34 §2-3).

LinuxCNC records ``stat.probed_position`` in the servo period in which motion sees its
``motion.probe-input`` switch: one to two servo periods after the switching instant, i.e.
v·(1..2)·T late (measured 10 / 22 / 64 µm at 300 / 1000 / 3000 mm/min with T = 1 ms). A
machine without a hardware latch is measured as the manual's measuring cycles do it, in two
stages (measuring-math §1.5: the switching position lags by e_lat = v·t for a signal delay t):

1. ``G38.3`` at the requested feed v1 finds the surface (no contact: not triggered, no alarm);
2. back off to where the probe is released (``G38.5``) and a clearance further (``G38.3``
   away, see bounce below), then ``G38.3`` again at the slow feed v2 at which one servo period
   moves the axes 0.5 µm (v2·T = 0.5 µm, at most v1/4);
3. the delay t follows from the two stages' probed positions s_i = S + v_i·t along the travel
   (least squares of two points: t = (s1 − s2)/(v1 − v2), within 0..50 ms), valid when the first
   stage ran at its feed (its travel exceeded the acceleration distance v1²/2a); else t = T.
   The switching position is S = s2 − v2·t: what is left is v2·T·(u2 − u1) with u uniform in
   a servo period, at most ±0.5 µm.

A hardware latch (``[HMI] PROBE_LATCH_X/_Y/_Z``, own.py: e.g. a Mesa encoder's
``position-latched``) holds the axis positions at the switching instant itself: one stage,
its values are the result.

Bounce (LinuxCNC issue #2926, fixed in 2.9.5 by PRs #3534/#3537; Debian 12 ships 2.9.0~pre1):
a probe input that chatters while the axes brake after the switch makes LinuxCNC before 2.9.5
report "Probe tripped during non-probe move" although its probed position was taken at the
first edge. After a tripped probing move that message is this bounce: the probed position
stands, no collision is raised. Every move of the probing with the probe near the surface is
itself a probing move (G38.5 away to the release, G38.3 away for the clearance, stopped early by
a chatter edge and repeated), so a chattering input never trips a non-probe move; the probing
ends with the probe released.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from engine import alarms

from ..protocol import Alarm, MachineAlarm, ProbeResult
from ..scenario import GEOMETRY_AXES

if TYPE_CHECKING:
    from .adapter import LinuxCncMachine

SLOW_STEP_MM = 0.0005        # travel per servo period at the slow stage's feed
CLEARANCE_MM = 0.2           # from the release point back for the slow stage's run-up
RELEASE_TRIES = 100          # a chatter stops each away move early; each one still gains ground
BOUNCE = "probe tripped during non-probe move"
ALREADY = "already tripped"
MAX_DELAY_S = 0.05            # a plausible signal delay (a debounce stage of many periods included)


@dataclass(frozen=True)
class Stage:
    tripped: bool
    probed: np.ndarray        # LinuxCNC's probed position (MCS), meaningful when tripped
    reached: np.ndarray       # where the axes stopped
    errors: list[str]
    outcome: str


class OwnProbing:
    """The probing moves of ``LinuxCncMachine`` on the machine's own configuration."""

    def __init__(self, machine: LinuxCncMachine) -> None:
        self.m = machine

    # --- one G38 move ----------------------------------------------------------------------
    def _g38(self, code: str, target: np.ndarray, feed: float, may_stand: bool = False) -> Stage:
        """One probing move; ``may_stand``: ending where it began is an answer (a chattering input
        may release or switch at once), not a block LinuxCNC did not run."""
        m = self.m
        start = m._position()
        travel = float(np.linalg.norm(target - start))
        program = m._program_point(target)
        words = " ".join(f"{a}{_num(v)}" for a, v in zip(GEOMETRY_AXES, program, strict=True))
        errors, outcome = m._mdi(f"G90 {code} {words} F{_num(feed)}",
                                 m._timeout(travel, feed * max(m._override, 1.0) / 100.0), start, None,
                                 0.0 if may_stand else travel)
        s = m._stat()
        tripped = bool(s.probe_tripped) and code in ("G38.2", "G38.3")
        probed = np.array(s.probed_position[:3], dtype=float)
        return Stage(tripped, probed, m._position(), errors, outcome)

    def _input(self) -> bool:
        return bool(self.m._hal.get_value("motion.probe-input"))

    def _check(self, stage: Stage, after_trip: bool) -> None:
        if stage.outcome != "done":
            raise MachineAlarm(Alarm.of(alarms.RESET_ABORT, "Motion aborted by Reset" if stage.outcome == "reset"
                                        else "Motion stopped"))
        errors = [e for e in stage.errors if not (after_trip and BOUNCE in e.lower())]
        if errors:
            raise MachineAlarm(self.m._raise(self.m._controller_alarm(errors)))

    def _release(self, d: np.ndarray, surface: np.ndarray, feed: float) -> np.ndarray:
        """Away from the surface until the probe is released and a clearance further; only probing
        moves (a chatter edge stops G38.3 early: once more from there)."""
        clear = surface - CLEARANCE_MM * d
        for _ in range(RELEASE_TRIES):
            if self._input():
                self._check(self._g38("G38.5", clear, feed, may_stand=True), after_trip=True)
            away = self._g38("G38.3", clear, feed, may_stand=True)
            if any(ALREADY in e.lower() for e in away.errors):
                continue                           # the contact closed again before the move began
            self._check(away, after_trip=True)
            if not away.tripped:
                return away.reached
        raise MachineAlarm(self.m._raise(Alarm.of(alarms.CONTROLLER_ERROR, "LinuxCNC: the probe does not release "
                                                  f"(its input chatters {RELEASE_TRIES} times)")))

    # --- the measuring move -----------------------------------------------------------------
    def slow_feed(self, feed: float) -> float:
        """mm/min of the second stage: one servo period moves SLOW_STEP_MM (with the override)."""
        m = self.m
        period = m._own.servo_period_s if m._own is not None else 0.001
        limit = SLOW_STEP_MM / period * 60.0 * 100.0 / max(m._override, 1.0)
        return min(limit, feed / 4.0)

    def probe(self, d: np.ndarray, distance: float, feed: float) -> ProbeResult:
        m = self.m
        start = m._position()
        end = start + distance * d
        m._check_limits(end)
        override = m._override
        first = self._g38("G38.3", end, feed)
        self._check(first, after_trip=first.tripped)
        if not first.tripped:
            m.last_probe = {"tripped": False, "start": start.tolist(), "end": first.reached.tolist()}
            return ProbeResult(False, None, m._kin.as_dict(first.reached), feed, override)
        latch = self._hardware_latch()
        info: dict = {"start": start.tolist(), "direction": d.tolist(), "feed": feed, "override": override,
                      "linuxcnc_probed": first.probed.tolist(), "stages": [first.probed.tolist()]}
        if latch is not None:
            switch, reached = latch, first.reached
            info["method"] = "hardware latch"
        else:
            switch, reached = self._two_stages(d, start, first, feed, override, info)
        reached = self._release(d, switch, feed) if self._input() else reached
        info.update(latch=switch.tolist(), end=reached.tolist())
        m.last_probe = info
        return ProbeResult(True, m._kin.as_dict(switch), m._kin.as_dict(reached), feed, override)

    def _two_stages(self, d, start, first: Stage, feed: float, override: float, info: dict):
        m = self.m
        period = m._own.servo_period_s if m._own is not None else 0.001
        accel = m._own.max_acceleration() if m._own is not None else 1000.0
        v1 = feed * override / 100.0 / 60.0
        slow = self.slow_feed(feed)
        v2 = slow * override / 100.0 / 60.0
        s1 = float((first.probed - start) @ d)
        if feed <= 1.5 * slow or v1 <= 0.0:
            info["method"] = "one stage, nominal delay of one servo period"
            return first.probed - v1 * period * d, first.reached
        begin = self._release(d, first.probed, feed)
        second = self._g38("G38.3", begin + (2.0 * CLEARANCE_MM) * d, slow)
        self._check(second, after_trip=second.tripped)
        if not second.tripped:
            raise MachineAlarm(m._raise(Alarm.of(alarms.CONTROLLER_ERROR, "LinuxCNC: the slow probing stage found "
                                                 "no contact where the first one switched (the part moved?)")))
        s2 = float((second.probed - start) @ d)
        steady = s1 > v1 * v1 / (2.0 * accel) * 1.1
        delay = min(max((s1 - s2) / (v1 - v2), 0.0), MAX_DELAY_S) if steady else period
        info.update(method="two stages", slow_feed=slow, delay_s=delay, steady=steady,
                    stages=[first.probed.tolist(), second.probed.tolist()])
        return second.probed - v2 * delay * d, second.reached

    def _hardware_latch(self) -> np.ndarray | None:
        m = self.m
        if m._own is None:
            return None
        pins, valid = m._own.latch_pins()
        if not pins:
            return None
        if valid and not m._hal.get_value(valid):
            raise MachineAlarm(m._raise(Alarm.of(alarms.CONTROLLER_ERROR, f"LinuxCNC: the probe latch {valid} holds "
                                                 "no value for this switch")))
        return np.array([float(m._hal.get_value(pins[a])) for a in GEOMETRY_AXES], dtype=float)


def _num(value: float) -> str:
    text = f"{value:.10f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text

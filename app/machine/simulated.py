"""The simulated machine's facade, written once for the milling machine and the lathe.

What a simulated control does alike on both (design.md §5, issue 27 item 1): the alarms (one
``AlarmBook``), busy/abort/stop (``motion.Motion``), the positioning with collision
monitoring, the continuous jog, the measuring move (MEAS), Reset, override, the active frame,
the NC's data and the probes' signals. A subclass brings its own objects and what only it
knows (``sim.SimulatedMachine``, ``lathe.LatheMachine``):

- ``_build(scenario)`` -> (kinematics, contact, NC data) for a scenario; it raises before
  anything changes when the scenario cannot be played (design.md §9.1);
- ``_install_extra(scenario)``: its own state after a load (caller holds the lock);
- ``status()``, ``spindle_position()``, ``scene_geometry()`` and ``_cut_next_part()``.

Decisions (where the spec leaves room), shared by both machines:
- A broken probe (PROBE_BROKEN per measuring-math §1.3, not resettable) refuses every motion
  while it is in the spindle/turret; Reset does not repair it, a tool change or a load does.
- A switch during goto/jog is a collision (PROBE_COLLISION); braking beyond the permissible
  deflection then also breaks the probe (not resettable).
- A move whose end lies outside the limits is refused before moving (the limit alarm is shown
  and raised as ``MachineAlarm``); a continuous jog stops at the limit with the same alarm.
- Reset during a motion: goto/jog return ``MoveResult(completed=False, alarm=RESET_ABORT)``; a
  probe() raises ``MachineAlarm(RESET_ABORT)``; that alarm is informational and not shown.
- Feed override is read continuously for the motion timing; the probe physics (latency,
  braking) use the override in effect when the move starts.
"""

from __future__ import annotations

import threading
from typing import Any

import numpy as np

from engine import alarms

from .alarm_book import AlarmBook
from .checks import finite, positive
from .kinematics import XYZ
from .machine_data import machine_data
from .motion import Motion
from .probe_signal import ProbeSignals
from .protocol import ActiveFrame, Alarm, MachineAlarm, MachineBusy, MoveResult, ProbeResult
from .scenario import Scenario


class SimulatedControl:
    """What both simulated machines do alike; the scenario is their truth."""

    TOOL_STORE = "magazine"            # where a tool the scenario lacks is missing from (alarm text)

    def __init__(self, scenario: Any) -> None:
        self._lock = threading.RLock()
        self._alarms = AlarmBook(self._lock)
        self._motion = Motion(self._lock, np.zeros(3))
        self._install(scenario)

    # --- scenario (SimulatorControl) ---------------------------------------------------------
    def _build(self, scenario: Any) -> tuple[Any, Any, Any]:
        raise NotImplementedError

    def _install_extra(self, scenario: Any) -> None:
        """The subclass's own state after a load (the caller holds the lock)."""

    def _install(self, scenario: Any) -> None:
        # build everything first: a scenario the physics refuses changes nothing (design.md §9.1)
        kinematics, contact, nc = self._build(scenario)
        start = kinematics.start_position()
        with self._lock:
            self._scenario = scenario
            self._kinematics = kinematics
            self._motion.position = start
            self._contact = contact
            self._nc = nc
            self._tool: int | None = scenario.probe.t
            self._offset_length = 0.0          # the milling machine's: the probe's nominal length
            self._frame = ActiveFrame()
            self._bcs2wcs = np.eye(4)
            self._override = 100.0
            self._spindle_angle = 0.0
            self._spindle_speed = 0.0
            self._alarms.clear()
            self._probes = ProbeSignals(scenario.probe.radio, scenario.tool_probe.radio if scenario.tool_probe
                                        else None, scenario.tool_probe is not None)
            self._install_extra(scenario)

    def load(self, scenario: Any) -> None:
        """Replace the truth and reset the machine (axes to the start position, probe in spindle)."""
        self.reset()
        self._install(scenario)

    @property
    def scenario(self) -> Any:
        return self._scenario

    # --- machine data (MachineData, manual ch. 9) ---------------------------------------------
    def machine_data(self) -> dict[str, Any]:
        """MD number -> value: as commissioned for the measuring cycles, with the scenario's own."""
        scenario = self._scenario
        return machine_data(scenario.machine.machine_data if isinstance(scenario, Scenario) else None)

    @property
    def axes(self) -> tuple[str, ...]:
        return self._kinematics.axes

    @property
    def controller(self) -> str:
        return "sim"

    def shown_alarms(self) -> tuple[Alarm, ...]:
        """``status().alarms`` without the rest of the status (the step executor counts them)."""
        return self._alarms.shown()

    def machine_part(self, scatter_sigma: float = 0.0) -> int:
        """The next part of the series replaces the workpiece (app.machine.series, turning.md §11);
        the machine keeps its position, tool, frame and alarms. Returns the part's number (1, 2, ...)."""
        sigma = finite(scatter_sigma, "scatter_sigma")
        if not 0.0 <= sigma <= 1.0:
            raise ValueError("scatter_sigma must be 0..1 mm")
        with self._lock:
            if self._motion.busy:
                raise MachineBusy("the next part is clamped while the axes stand still")
            return self._cut_next_part(sigma)

    def _cut_next_part(self, sigma: float) -> int:
        raise NotImplementedError

    # --- the NC's data -----------------------------------------------------------------------
    def write_offset(self, name: str, frame: dict) -> None:
        """The simulated NC holds every named frame the HMI offers; motion uses the active chain."""
        with self._lock:
            self._nc.write_offset(name, frame)

    def write_tool(self, t: int, data: dict) -> None:
        with self._lock:
            self._nc.write_tool(t, data)

    @property
    def nc_offsets(self) -> dict[str, dict]:
        """The named frames as the NC holds them (copies; simulator only)."""
        with self._lock:
            return self._nc.offsets

    @property
    def nc_tools(self) -> dict[int, dict]:
        """The tool data as the NC holds it (copies; simulator only)."""
        with self._lock:
            return self._nc.tools

    def close(self) -> None:
        self.stop()

    def set_probe(self, which: str, deflect: bool | None = None, battery: float | None = None,
                  armed: bool | None = None) -> None:
        """The operator's hand on a probe (design.md §10.4, probe_signal.py)."""
        with self._lock:
            self._probes.set(which, deflect, battery, armed)

    # --- settings without motion -------------------------------------------------------------
    def change_tool(self, tool: int | None, offset_length: float = 0.0) -> None:
        """Tool change; a new probe (or any other tool) replaces a broken stylus."""
        offset_length = finite(offset_length, "offset_length")
        if tool is not None and tool != self._scenario.probe.t and self._scenario.tool(tool) is None:
            # the simulator has no truth for it (spec/jog-measuring.md §10)
            raise self._alarms.refusal(alarms.NO_TOOL_FOR_IDENTIFIER, f"No tool for the given tool identifier: "
                                       f"T{tool} is not in the {self.TOOL_STORE}")
        with self._lock:
            if self._motion.busy:
                raise MachineBusy("tool change while the axes move")
            self._tool = tool
            self._offset_length = offset_length
            self._alarms.repair_probe()

    def set_tool_offset(self, offset_length: float) -> None:
        with self._lock:
            self._offset_length = finite(offset_length, "offset_length")

    def activate_frame(self, frame: ActiveFrame) -> None:
        matrix = np.asarray(frame.wcs2bcs, dtype=float)
        if matrix.shape != (4, 4) or not np.all(np.isfinite(matrix)):
            raise ValueError("frame.wcs2bcs must be a finite 4x4 matrix")
        bcs2wcs = np.linalg.inv(matrix)         # the display's inverse, once per activation
        with self._lock:
            self._frame, self._bcs2wcs = frame, bcs2wcs

    def spindle_rotate(self, speed_rpm: float) -> None:
        with self._lock:
            self._spindle_speed = finite(speed_rpm, "speed_rpm")

    def set_override(self, percent: float) -> None:
        percent = finite(percent, "percent")
        if not 0.0 <= percent <= 120.0:
            raise ValueError(f"feed override must be within 0..120 %, got {percent}")
        with self._lock:
            self._override = percent

    # --- Reset / stop / alarms ---------------------------------------------------------------
    def reset(self) -> None:
        """Abort any motion at its current position, stop the spindle, clear resettable alarms."""
        self._motion.abort()
        with self._lock:
            self._spindle_speed = 0.0          # NC Reset ends M3/M4 like a real control
            self._alarms.reset()

    def probe_braking(self) -> dict:
        """The braking behind a switch and the probes' permissible deflection (protocol.ProbeReach):
        the machine data of the scenario's ``machine`` section, measuring-math §1.3. A tool probe
        without ``max_deflection`` (the milling machine's) is not broken by overtravel."""
        m, sc = self._scenario.machine, self._scenario
        tool_probe = getattr(sc, "tool_probe", None)
        tool_limit = getattr(tool_probe, "max_deflection", None) if tool_probe is not None else None
        probe = getattr(sc, "probe", None)
        return {"latency_s": float(m.latency_s), "decel": float(m.decel), "kv": float(m.kv),
                "max_deflection": {"workpiece": None if probe is None else float(probe.max_deflection),
                                   "tool": None if tool_limit is None else float(tool_limit)}}

    def stop(self) -> None:
        """Stop motion without an alarm (jog key released)."""
        self._motion.stop()

    def post_alarm(self, alarm: Alarm) -> None:
        """An alarm raised by a measuring cycle (e.g. probe not switched): shown until Reset."""
        self._alarms.raise_(alarm)

    def _overtravel(self) -> Alarm:
        """Braking beyond the permissible deflection: the stylus breaks; on the tool probe
        (a turning tool against it) it is a collision."""
        if self._contact.is_probe(self._tool):
            return self._alarms.break_probe()
        return self._alarms.raise_(Alarm.of(alarms.PROBE_COLLISION, "Probe collision: the tool probe was pushed "
                                            "beyond its permissible deflection"))

    def _check_limits(self, target: np.ndarray) -> None:
        alarm = self._kinematics.limit_alarm(target)
        if alarm is not None:
            raise MachineAlarm(self._alarms.raise_(alarm))

    # --- motions -----------------------------------------------------------------------------
    def goto(self, target_mcs: dict[str, float], feed: float | None = None) -> MoveResult:
        """Straight positioning (rapid when feed is None), collision-monitored."""
        target = self._target(target_mcs)
        if feed is not None:
            feed = positive(feed, "feed")
        self._begin()
        try:
            return self._positioning(target, feed)
        finally:
            self._motion.finish()

    def jog(self, axis: str, distance: float, feed: float | None = None) -> MoveResult:
        """Incremental jog of one axis (jog feed when feed is None), collision-monitored."""
        index = self._kinematics.index(axis)
        distance = finite(distance, "distance")
        feed = self._scenario.machine.jog_feed if feed is None else positive(feed, "feed")
        self._begin()
        try:
            target = self._motion.position.copy()   # read after _begin: never a point of a running motion
            target[index] += distance
            return self._positioning(target, feed)
        finally:
            self._motion.finish()

    def jog_continuous(self, axis: str, direction: int, feed: float | None = None) -> None:
        """Jog towards the limit in a background thread until stop()/Reset/limit/collision."""
        index = self._kinematics.index(axis)
        if direction not in (1, -1):
            raise ValueError("direction must be +1 or -1")
        feed = self._scenario.machine.jog_feed if feed is None else positive(feed, "feed")
        self._begin()
        target = self._motion.position.copy()
        lo, hi = self._kinematics.limits[axis]
        target[index] = hi if direction > 0 else lo

        def run() -> None:
            try:
                result = self._positioning(target, feed)
                if result.completed:   # ran onto the software limit
                    self._alarms.raise_(Alarm.of(alarms.SOFTWARE_LIMIT, f"Axis {axis} at software limit switch"))
            finally:
                self._motion.finish()

        self._motion.in_background(run)

    def probe(self, direction, distance: float, feed: float) -> ProbeResult:
        """Measuring move (MEAS): contact, pre-travel, latency, noise, braking (measuring-math §1)."""
        d = np.asarray(direction, dtype=float).reshape(-1)
        if d.shape != (3,) or not np.all(np.isfinite(d)) or not np.linalg.norm(d) > 0.0:
            raise ValueError("direction must be a finite, non-zero [dx, dy, dz]")
        d = d / np.linalg.norm(d)
        distance = positive(distance, "distance")
        feed = positive(feed, "feed")
        self._begin()
        try:
            return self._measuring_move(d, distance, feed)
        finally:
            self._motion.finish()

    def _measuring_move(self, d: np.ndarray, distance: float, feed: float) -> ProbeResult:
        kin = self._kinematics
        start = self._motion.position.copy()
        end = kin.along(start, d, distance)
        self._check_limits(end)
        override = self._override
        event = self._first_event(start, d, distance)
        if event is None or (event.kind == "switch" and event.s_switch > distance):
            reached = self._travel_to_end(start, end, feed)
            return ProbeResult(False, None, kin.as_dict(reached), feed, override)
        if event.kind == "crash":
            self._travel_to_end(start, kin.along(start, d, event.s_contact), feed)
            raise self._alarms.refusal(alarms.PROBE_COLLISION, event.text)
        stop = self._contact.measuring_stop(event, feed * override / 100.0, distance, self._tool)
        reached = self._travel_to_end(start, kin.along(start, d, stop.s_stop), feed)
        if stop.breaks:
            raise MachineAlarm(self._overtravel())
        assert stop.s_latch is not None                 # a measuring stop has its latch
        latched = kin.along(start, d, stop.s_latch)
        return ProbeResult(True, kin.as_dict(latched), kin.as_dict(reached), feed, override)

    # --- motion internals --------------------------------------------------------------------
    def _begin(self) -> None:
        """Claim the axes; a broken probe refuses every motion."""
        self._motion.begin(self._alarms.refuse_if_broken)

    def _first_event(self, start: np.ndarray, d: np.ndarray, length: float):
        with self._lock:
            tool, angle = self._tool, self._spindle_angle
        return self._contact.first_event(start, d, length, tool, angle)

    def _effective_feed(self, feed: float | None) -> float:
        """mm/min in effect: ``feed`` × override, or rapid × override (at most 100 %) when None."""
        if feed is None:
            return self._scenario.machine.rapid * min(self._override, 100.0) / 100.0
        return feed * self._override / 100.0

    def _travel(self, start: np.ndarray, end: np.ndarray, feed: float | None) -> tuple[np.ndarray, str]:
        return self._motion.travel(start, end, lambda: self._effective_feed(feed), self._scenario.machine.time_scale)

    def _travel_to_end(self, start: np.ndarray, end: np.ndarray, feed: float) -> np.ndarray:
        """A measuring move's travel: Reset or stop on the way raise RESET_ABORT (not shown)."""
        reached, outcome = self._travel(start, end, feed)
        if outcome != "done":
            raise MachineAlarm(Alarm.of(alarms.RESET_ABORT, "Motion aborted by Reset" if outcome == "reset"
                                        else "Motion stopped"))
        return reached

    def _positioning(self, target: np.ndarray, feed: float | None) -> MoveResult:
        """A goto/jog once the axes are claimed (the milling machine adds its rotary table)."""
        return self._move(target, feed)

    def _move(self, target: np.ndarray, feed: float | None) -> MoveResult:
        """Positioning with collision monitoring (rapid when feed is None); caller holds the busy flag."""
        start = self._motion.position.copy()
        self._check_limits(target)
        delta = target[XYZ] - start[XYZ]
        length = float(np.linalg.norm(delta))
        event = self._first_event(start, delta / length, length) if length > 0.0 else None
        if event is None or (event.kind == "switch" and event.s_switch > length):
            reached, outcome = self._travel(start, target, feed)
            return self._move_result(reached, outcome)
        stop = self._contact.positioning_stop(event, self._effective_feed(feed), length, self._tool)
        stop_at = start + (target - start) * (stop.s_stop / length)
        reached, outcome = self._travel(start, stop_at, feed)
        if outcome != "done":
            return self._move_result(reached, outcome)
        alarm = self._alarms.raise_(Alarm.of(alarms.PROBE_COLLISION, event.text))
        if stop.breaks and self._contact.is_probe(self._tool):
            self._alarms.break_probe()
        return MoveResult(self._kinematics.as_dict(reached), False, alarm)

    def _move_result(self, reached: np.ndarray, outcome: str) -> MoveResult:
        alarm = Alarm.of(alarms.RESET_ABORT, "Motion aborted by Reset") if outcome == "reset" else None
        return MoveResult(self._kinematics.as_dict(reached), outcome == "done", alarm)

    def _target(self, target_mcs: dict[str, float]) -> np.ndarray:
        if not isinstance(target_mcs, dict):
            raise ValueError("target must be a dict of axis -> position")
        with self._lock:
            target = self._motion.position.copy()
        for axis, value in target_mcs.items():
            target[self._kinematics.index(axis)] = finite(value, f"target.{axis}")
        return target

"""The simulated milling machine behind the Machine Protocol (design.md §5).

Physics of one move is decided when the move starts (contact, switch, latch, braking: all
analytic, see scene.py/physics.py); the motion itself is then played out in (scaled) real
time so that ``status()`` from another thread sees the axes move. The lock is never held
while sleeping.

Decisions (where the spec leaves room):
- A broken probe (61302 per measuring-math §1.3, not resettable) refuses every motion (probe, goto, jog) while it is
  in the spindle; Reset does not repair it, a tool change (any tool, also the same T = new
  stylus) or ``load()`` does.
- A switch during goto/jog is a collision (61302); if the overtravel behind the first contact
  then exceeds ``max_deflection`` the probe also breaks (61302, not resettable): a rapid move into the part
  breaks the stylus, as on a real machine.
- Active alarms do not lock the axes (the operator may jog away before pressing Reset).
- Limits: a move whose end lies outside the limits is refused before moving: the limit
  alarm is put into the status and raised as ``MachineAlarm``. A continuous jog stops at
  the limit with the same alarm.
- Reset during a motion: goto/jog return ``MoveResult(completed=False, alarm=16900)``; a
  probe() raises ``MachineAlarm(16900)``. The 16900 alarm is informational and not put into
  the status (Reset has just cleared the status alarms).
- Feed override is read continuously for the motion timing; the probe physics (latency,
  braking) use the override in effect when the move starts.
- Rotary axes are positions with limits; the axis named in ``machine.rotary_table`` turns the
  workpiece (not the gauges) about the vertical table axis (scene.workpiece_pose); the part is
  re-placed when a positioning of that axis ends (see ``_move_and_turn``).
- Swivel head (scenario ``machine.kinematics``, model in scenario.SwivelHead): the head axes
  are rotary axes of the machine; the ball centre is A + R_head·(e(φ) − L·ẑ) and the tool axis
  R_head·ẑ. A motion that turns the head is checked at ``SWIVEL_SAMPLES`` poses along the path
  (end pose included; X/Y/Z interpolated with the angles): any contact is a collision (61302)
  and the motion is refused before it starts (the probe does not measure while swivelling).
  ``swivel_to_wcs`` is CYCLE800-like: it solves the head angles for tool axis ∥ the WCS infeed
  axis (the solution in the limits with the smallest axis motion; the twist about the tool axis
  is not aligned). ``retract_tool_axis`` moves up along the tool axis (to the limits by default).
  The tool probe's Minkowski sum assumes a vertical cutter (tool measuring with the head at 0).
- Cutters: a flat-end cylinder, stationary or rotating alike (the full cylinder of radius R;
  the eccentricity of the ball probe is not smeared by rotation either). The tool probe
  contact is exact (Minkowski sum of two vertical cylinders); a cutter touching the
  workpiece or the ring gauge is a crash, detected for a ball of radius R at the tool end
  (approximate: the flat end reaches R·(1 − 1/√2) lower at an oblique approach, the shank is
  not checked). There is no braking/broken check for the tool probe.
"""

from __future__ import annotations

import math
import threading
import time
from dataclasses import dataclass

import numpy as np

from .physics import (
    Z_UNIT,
    ball_centre,
    braking_distance,
    head_angles_for,
    head_rotation,
    latency_path,
    pretravel_along,
)
from .protocol import (
    ALARM_LIMIT,
    ALARM_PROBE_BROKEN,
    ALARM_PROBE_COLLISION,
    ALARM_RESET,
    ActiveFrame,
    Alarm,
    MachineAlarm,
    MachineBusy,
    MachineStatus,
    MoveResult,
    ProbeResult,
)
from .scenario import GEOMETRY_AXES, Scenario
from .scene import Body, Scene, build_scene, outline, tool_probe_cylinder

ALARM_NO_TOOL = 61343         # "no tool for the given tool identifier" (spec/jog-measuring.md §10)
TICK_S = 0.01                 # motion update period at time_scale > 0
WAIT_IDLE_S = 2.0             # how long reset()/stop() wait for a motion to end
SWIVEL_SAMPLES = 16           # poses checked along a motion that turns the swivel head
_XYZ = slice(0, 3)


@dataclass(frozen=True)
class _Event:
    """What happens first on a path: a switch (probe or tool probe) or a crash (cutter vs part)."""

    kind: str                # "switch" or "crash"
    s_contact: float         # path length to first contact
    s_switch: float          # path length to the switching point (contact + pre-travel)
    text: str


class SimulatedMachine:
    """A 3-axis (+ rotary) milling machine with a 3D touch probe; the scenario is its truth."""

    def __init__(self, scenario: Scenario) -> None:
        self._lock = threading.RLock()
        self._idle = threading.Condition(self._lock)
        self._abort = threading.Event()
        self._stop = threading.Event()
        self._busy = False
        self._jog_thread: threading.Thread | None = None
        self._install(scenario)

    # --- scenario ------------------------------------------------------------------------
    def _install(self, scenario: Scenario) -> None:
        with self._lock:
            self._scenario = scenario
            self._scene = build_scene(scenario)
            self._table_angle = 0.0
            self._axes = scenario.axes
            self._limits = scenario.limits()
            start = scenario.start_position()
            self._pos = np.array([start[a] for a in self._axes], dtype=float)
            self._tool: int | None = scenario.probe.t
            self._offset_length = scenario.probe.nominal_length
            self._frame = ActiveFrame()
            self._override = 100.0
            self._spindle_angle = 0.0
            self._spindle_speed = 0.0
            self._alarms: list[Alarm] = []
            self._rng = np.random.default_rng(scenario.seed)
            self._sync_table()

    def load(self, scenario: Scenario) -> None:
        """Replace the truth and reset the machine (axes to the start position, probe in spindle)."""
        self.reset()
        self._install(scenario)

    @property
    def scenario(self) -> Scenario:
        return self._scenario

    @property
    def scene(self) -> Scene:
        return self._scene

    @property
    def axes(self) -> tuple[str, ...]:
        return self._axes

    # --- status --------------------------------------------------------------------------
    def status(self) -> MachineStatus:
        with self._lock:
            mcs = {a: float(v) for a, v in zip(self._axes, self._pos, strict=True)}
            tool_length = self._offset_length if self._tool is not None else 0.0
            axis = self._tool_axis_at(self._pos)
            tip_in_mcs = self._pos[_XYZ] - tool_length * axis
            bcs2wcs = np.linalg.inv(np.asarray(self._frame.wcs2bcs, dtype=float))
            p_in_wcs = bcs2wcs @ np.append(tip_in_mcs, 1.0)
            wcs = {a: float(p_in_wcs[i]) for i, a in enumerate(GEOMETRY_AXES)}
            for a in self._axes[3:]:
                wcs[a] = mcs[a] - float(self._frame.rotary_offsets.get(a, 0.0))
            return MachineStatus(
                mcs=mcs, wcs=wcs, active_offset=self._frame.name, tool=self._tool,
                tool_length=float(tool_length), feed_override=self._override,
                spindle_angle=self._spindle_angle, spindle_speed=self._spindle_speed,
                busy=self._busy, alarms=tuple(self._alarms),
                tool_axis=(float(axis[0]), float(axis[1]), float(axis[2])))

    # --- settings without motion ---------------------------------------------------------
    def change_tool(self, tool: int | None, offset_length: float) -> None:
        """Tool change; a new probe (or any other tool) replaces a broken stylus."""
        offset_length = _finite(offset_length, "offset_length")
        if tool is not None and tool != self._scenario.probe.t and self._scenario.tool(tool) is None:
            # the simulator has no truth for it: alarm 61343 (spec/jog-measuring.md §10)
            raise MachineAlarm(self._raise_alarm(Alarm(ALARM_NO_TOOL, f"No tool for the given tool "
                                                                      f"identifier: T{tool} is not in the magazine")))
        with self._lock:
            if self._busy:
                raise MachineBusy("tool change while the axes move")
            self._tool = tool
            self._offset_length = offset_length
            broken = self._broken_alarm()
            self._alarms = [a for a in self._alarms if a is not broken]

    def set_tool_offset(self, offset_length: float) -> None:
        with self._lock:
            self._offset_length = _finite(offset_length, "offset_length")

    def activate_frame(self, frame: ActiveFrame) -> None:
        matrix = np.asarray(frame.wcs2bcs, dtype=float)
        if matrix.shape != (4, 4) or not np.all(np.isfinite(matrix)):
            raise ValueError("frame.wcs2bcs must be a finite 4x4 matrix")
        with self._lock:
            self._frame = frame

    def spindle_position(self, angle: float) -> None:
        """SPOS: the probe's eccentricity turns with the spindle (measuring-math §1.7)."""
        with self._lock:
            self._spindle_angle = _finite(angle, "angle") % 360.0
            self._spindle_speed = 0.0

    def spindle_rotate(self, speed_rpm: float) -> None:
        with self._lock:
            self._spindle_speed = _finite(speed_rpm, "speed_rpm")

    def set_override(self, percent: float) -> None:
        percent = _finite(percent, "percent")
        if not 0.0 <= percent <= 120.0:
            raise ValueError(f"feed override must be within 0..120 %, got {percent}")
        with self._lock:
            self._override = percent

    # --- Reset / stop --------------------------------------------------------------------
    def reset(self) -> None:
        """Abort any motion at its current position, stop the spindle, clear resettable alarms."""
        self._abort.set()
        self._wait_idle()
        with self._lock:
            self._spindle_speed = 0.0          # NC Reset ends M3/M4 like a real control
            self._alarms = [a for a in self._alarms if not a.resettable]

    def stop(self) -> None:
        """Stop motion without an alarm (jog key released)."""
        self._stop.set()
        self._wait_idle()

    def _wait_idle(self) -> None:
        deadline = time.monotonic() + WAIT_IDLE_S
        with self._idle:
            while self._busy and time.monotonic() < deadline:
                self._idle.wait(timeout=TICK_S)
        thread = self._jog_thread
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout=WAIT_IDLE_S)

    # --- motions -------------------------------------------------------------------------
    def goto(self, target_mcs: dict[str, float], feed: float | None = None) -> MoveResult:
        """Straight positioning (rapid when feed is None), collision-monitored."""
        target = self._target(target_mcs)
        if feed is not None:
            feed = _positive(feed, "feed")
        self._begin()
        try:
            return self._move_and_turn(target, feed)
        finally:
            self._finish()

    def jog(self, axis: str, distance: float, feed: float | None = None) -> MoveResult:
        """Incremental jog of one axis (jog feed when feed is None), collision-monitored."""
        index = self._axis_index(axis)
        distance = _finite(distance, "distance")
        feed = self._scenario.machine.jog_feed if feed is None else _positive(feed, "feed")
        self._begin()
        try:
            target = self._pos.copy()       # read after _begin: never a point of a running motion
            target[index] += distance
            return self._move_and_turn(target, feed)
        finally:
            self._finish()

    def jog_continuous(self, axis: str, direction: int, feed: float | None = None) -> None:
        """Jog towards the limit in a background thread until stop()/Reset/limit/collision."""
        index = self._axis_index(axis)
        if direction not in (1, -1):
            raise ValueError("direction must be +1 or -1")
        feed = self._scenario.machine.jog_feed if feed is None else _positive(feed, "feed")
        self._begin()
        target = self._pos.copy()
        lo, hi = self._limits[axis]
        target[index] = hi if direction > 0 else lo

        def run() -> None:
            try:
                result = self._move_and_turn(target, feed)
                if result.completed:   # ran onto the software limit
                    self._raise_alarm(Alarm(ALARM_LIMIT, f"Axis {axis} at software limit switch"))
            finally:
                self._finish()

        self._jog_thread = threading.Thread(target=run, name="sim-jog", daemon=True)
        self._jog_thread.start()

    def probe(self, direction, distance: float, feed: float) -> ProbeResult:
        """Measuring move (MEAS): contact, pre-travel, latency, noise, braking (measuring-math §1)."""
        d = np.asarray(direction, dtype=float).reshape(-1)
        if d.shape != (3,) or not np.all(np.isfinite(d)) or not np.linalg.norm(d) > 0.0:
            raise ValueError("direction must be a finite, non-zero [dx, dy, dz]")
        d = d / np.linalg.norm(d)
        distance = _positive(distance, "distance")
        feed = _positive(feed, "feed")
        self._begin()
        try:
            start = self._pos.copy()
            end = start.copy()
            end[_XYZ] += distance * d
            self._check_limits(end)
            override = self._override
            v = feed * override / 100.0                      # mm/min in effect
            event = self._first_event(start, d, distance)
            if event is None or (event.kind == "switch" and event.s_switch > distance):
                reached, outcome = self._travel(start, end, feed)
                self._raise_if_aborted(outcome)
                return ProbeResult(False, None, self._as_dict(reached), feed, override)
            if event.kind == "crash":
                reached, outcome = self._travel(start, self._along(start, d, event.s_contact), feed)
                self._raise_if_aborted(outcome)
                raise MachineAlarm(self._raise_alarm(Alarm(ALARM_PROBE_COLLISION, event.text)))
            s_stop = min(event.s_switch + self._braking(v), distance)
            s_latch = min(event.s_switch + latency_path(v, self._scenario.machine.latency_s), s_stop)
            sigma = self._scenario.probe.noise_sigma
            if sigma > 0.0 and self._probe_in_spindle():
                s_latch += float(self._rng.normal(0.0, sigma))
            broken = self._breaks_probe(s_stop - event.s_contact)
            reached, outcome = self._travel(start, self._along(start, d, s_stop), feed)
            self._raise_if_aborted(outcome)
            if broken:
                raise MachineAlarm(self._break_probe())
            latched = self._along(start, d, s_latch)
            return ProbeResult(True, self._as_dict(latched), self._as_dict(reached), feed, override)
        finally:
            self._finish()

    # --- motion internals ----------------------------------------------------------------
    def _move_and_turn(self, target: np.ndarray, feed: float | None) -> MoveResult:
        """``_move``, then the part follows the rotary table axis (scenario machine.rotary_table).

        Simplification: the path is checked with the part where it stood at the start of the
        move; a table turn that ends with the probe inside the part is a collision (61302).
        """
        if self._head_turns(target):
            alarm = self._swivel_collision(self._pos.copy(), target)
            if alarm is not None:
                return MoveResult(self._as_dict(self._pos), False, alarm)
        result = self._move(target, feed)
        if not self._sync_table():
            return result
        if self._probe_in_spindle():
            with self._lock:
                hit = self._ball_in_solid(self._pos, self._spindle_angle)
            if hit:
                alarm = self._raise_alarm(Alarm(ALARM_PROBE_COLLISION, "Probe collision: the rotary table "
                                                "turned the workpiece into the probe"))
                return MoveResult(result.mcs, False, alarm)
        return result

    def _sync_table(self) -> bool:
        """Rebuild the scene when the rotary table axis moved; True when it did."""
        table = self._scenario.machine.rotary_table
        if table is None or table.axis not in self._axes:
            return False
        with self._lock:
            angle = float(self._pos[self._axes.index(table.axis)])
            if angle == self._table_angle:
                return False
            self._table_angle = angle
            self._scene = build_scene(self._scenario, table_angle=angle)
        return True

    def _move(self, target: np.ndarray, feed: float | None) -> MoveResult:
        """Positioning with collision monitoring (rapid when feed is None); caller holds the busy flag."""
        start = self._pos.copy()
        self._check_limits(target)
        delta = target[_XYZ] - start[_XYZ]
        length = float(np.linalg.norm(delta))
        event = self._first_event(start, delta / length, length) if length > 0.0 else None
        if event is None or (event.kind == "switch" and event.s_switch > length):
            reached, outcome = self._travel(start, target, feed)
            return self._move_result(reached, outcome)
        if event.kind == "switch":
            s_stop = min(event.s_switch + self._braking(self._effective_feed(feed)), length)
        else:
            s_stop = event.s_contact
        stop_at = start + (target - start) * (s_stop / length)
        reached, outcome = self._travel(start, stop_at, feed)
        if outcome != "done":
            return self._move_result(reached, outcome)
        alarm = self._raise_alarm(Alarm(ALARM_PROBE_COLLISION, event.text))
        if event.kind == "switch" and self._breaks_probe(s_stop - event.s_contact):
            self._break_probe()
        return MoveResult(self._as_dict(reached), False, alarm)

    def _travel(self, start: np.ndarray, end: np.ndarray, feed: float | None) -> tuple[np.ndarray, str]:
        """Play the straight move out in scaled real time: -> (position, 'done'|'reset'|'stop')."""
        delta = end - start
        length = float(np.linalg.norm(delta[_XYZ])) or float(np.linalg.norm(delta))
        time_scale = self._scenario.machine.time_scale
        if length == 0.0 or time_scale == 0.0:
            with self._lock:
                self._pos = end.copy()
            return end.copy(), "done"
        travelled = 0.0
        last = time.monotonic()
        while True:
            time.sleep(TICK_S)
            now = time.monotonic()
            with self._lock:
                if self._abort.is_set():
                    return self._pos.copy(), "reset"
                if self._stop.is_set():
                    return self._pos.copy(), "stop"
                # duration = length / feed · 60 · time_scale (design.md §5), override read live
                travelled += self._effective_feed(feed) / 60.0 * (now - last) / time_scale
                last = now
                fraction = min(travelled / length, 1.0)
                self._pos = start + fraction * delta
                if fraction >= 1.0:
                    self._pos = end.copy()
                    return end.copy(), "done"

    def _first_event(self, start: np.ndarray, d: np.ndarray, length: float) -> _Event | None:
        """First switch or crash along the geometric path from ``start`` (axes) along unit ``d``."""
        with self._lock:
            tool = self._tool
            angle = self._spindle_angle
        scenario = self._scenario
        if tool is None:
            return None
        if tool == scenario.probe.t:
            probe = scenario.probe
            centre = self._ball_centre(start, angle)
            radius = probe.ball_diameter / 2.0
            s_contact = self._scene.first_contact(centre, d, length, radius)
            if s_contact is None:
                return None
            # already deflected and pressing deeper: the probe signal is on at once
            deflected = s_contact == 0.0 and self._scene.sdf(centre) <= radius
            head = self._head(start)
            d_probe = d if head is None else head.T @ d          # pre-travel in the probe's own axes
            s_switch = s_contact if deflected else s_contact + pretravel_along(d_probe, probe.pretravel)
            return _Event("switch", s_contact, s_switch, "Probe collision")
        cutter = scenario.tool(tool)
        tool_axis = self._tool_axis_at(start)
        tip = start[_XYZ] - cutter.length * tool_axis
        events = []
        tp = scenario.tool_probe
        if tp is not None:
            grown = Scene([Body("tool_probe", tool_probe_cylinder(tp, cutter.radius, cutter.length))])
            s_contact = grown.first_contact(tip, d, length, 0.0)
            if s_contact is not None:
                deflected = s_contact == 0.0 and grown.sdf(tip) <= 0.0
                s_switch = s_contact if deflected else s_contact + tp.pretravel
                events.append(_Event("switch", s_contact, s_switch, "Probe collision (tool probe)"))
        obstacles = self._scene.subset({"part", "ring_gauge"})
        s_crash = obstacles.first_contact(tip + cutter.radius * tool_axis, d, length, cutter.radius)
        if s_crash is not None:
            events.append(_Event("crash", s_crash, s_crash, f"Probe collision: T{tool} hit the workpiece"))
        if not events:
            return None
        return min(events, key=lambda e: e.s_switch)

    def _ball_centre(self, position: np.ndarray, spindle_angle: float) -> np.ndarray:
        """The true ball centre with the axes at ``position`` (physics.ball_centre, this probe and head)."""
        probe = self._scenario.probe
        return ball_centre(position[_XYZ], probe.length, probe.eccentricity, spindle_angle, self._head(position))

    def _ball_in_solid(self, position: np.ndarray, spindle_angle: float) -> bool:
        return self._scene.sdf(self._ball_centre(position, spindle_angle)) < self._scenario.probe.ball_diameter / 2.0

    def _probe_in_spindle(self) -> bool:
        return self._tool is not None and self._tool == self._scenario.probe.t

    def _breaks_probe(self, deflection: float) -> bool:
        """Pre-travel + braking beyond the permissible deflection (measuring-math §1.3)."""
        return self._probe_in_spindle() and deflection > self._scenario.probe.max_deflection

    def _break_probe(self) -> Alarm:
        return self._raise_alarm(Alarm(ALARM_PROBE_BROKEN, "Probe broken: overtravel beyond the "
                                       "permissible deflection", resettable=False))

    def _broken_alarm(self) -> Alarm | None:
        """The broken-stylus alarm: the probe is broken exactly while it is in the list."""
        return next((a for a in self._alarms if a.code == ALARM_PROBE_BROKEN and not a.resettable), None)

    def _braking(self, feed_in_effect: float) -> float:
        """Overtravel behind the switch at this feed (mm/min), measuring-math §1.3."""
        cfg = self._scenario.machine
        return braking_distance(feed_in_effect, cfg.latency_s, cfg.decel, cfg.kv)

    def _effective_feed(self, feed: float | None) -> float:
        """mm/min in effect: ``feed`` × override, or rapid × override (at most 100 %) when None."""
        if feed is None:
            return self._scenario.machine.rapid * min(self._override, 100.0) / 100.0
        return feed * self._override / 100.0

    def _begin(self) -> None:
        with self._lock:
            if self._busy:
                raise MachineBusy("a motion is already running")
            broken = self._broken_alarm()
            if broken is not None:
                raise MachineAlarm(broken)
            self._busy = True
            self._abort.clear()
            self._stop.clear()

    def _finish(self) -> None:
        with self._idle:
            self._busy = False
            self._idle.notify_all()

    def post_alarm(self, alarm: Alarm) -> None:
        """An alarm raised by a measuring cycle (e.g. 61301): shown until Reset."""
        self._raise_alarm(alarm)

    def _raise_alarm(self, alarm: Alarm) -> Alarm:
        with self._lock:
            if all(a.code != alarm.code or a.text != alarm.text for a in self._alarms):
                self._alarms.append(alarm)
        return alarm

    def _raise_if_aborted(self, outcome: str) -> None:
        if outcome != "done":
            raise MachineAlarm(Alarm(ALARM_RESET, "Motion aborted by Reset" if outcome == "reset"
                                     else "Motion stopped"))

    def _move_result(self, reached: np.ndarray, outcome: str) -> MoveResult:
        alarm = Alarm(ALARM_RESET, "Motion aborted by Reset") if outcome == "reset" else None
        return MoveResult(self._as_dict(reached), outcome == "done", alarm)

    def _check_limits(self, target: np.ndarray) -> None:
        for axis, value in zip(self._axes, target, strict=True):
            lo, hi = self._limits[axis]
            if not lo - 1e-9 <= value <= hi + 1e-9:
                alarm = Alarm(ALARM_LIMIT, f"Software limit switch {axis}: {value:.3f} outside "
                                           f"[{lo:g}, {hi:g}]")
                raise MachineAlarm(self._raise_alarm(alarm))

    def _target(self, target_mcs: dict[str, float]) -> np.ndarray:
        if not isinstance(target_mcs, dict):
            raise ValueError("target must be a dict of axis -> position")
        with self._lock:
            target = self._pos.copy()
        for axis, value in target_mcs.items():
            target[self._axis_index(axis)] = _finite(value, f"target.{axis}")
        return target

    def _axis_index(self, axis: str) -> int:
        if axis not in self._axes:
            raise ValueError(f"unknown axis {axis!r}; the machine has {list(self._axes)}")
        return self._axes.index(axis)

    def _along(self, start: np.ndarray, d: np.ndarray, s: float) -> np.ndarray:
        out = start.copy()
        out[_XYZ] += s * d
        return out

    def _as_dict(self, position: np.ndarray) -> dict[str, float]:
        return {a: float(v) for a, v in zip(self._axes, position, strict=True)}

    # --- swivel head (scenario.SwivelHead) -----------------------------------------------
    def has_swivel(self) -> bool:
        head = self._scenario.machine.kinematics
        return head is not None and all(a in self._axes for a in head.axes)

    def _head(self, position: np.ndarray) -> np.ndarray | None:
        """R_head at the axis ``position`` (None without a swivel head)."""
        if not self.has_swivel():
            return None
        head_axes = self._scenario.machine.kinematics.axes
        return head_rotation(head_axes, [position[self._axes.index(a)] for a in head_axes])

    def _tool_axis_at(self, position: np.ndarray) -> np.ndarray:
        head = self._head(position)
        return Z_UNIT.copy() if head is None else head @ Z_UNIT

    def _head_turns(self, target: np.ndarray) -> bool:
        if not self.has_swivel():
            return False
        index = [self._axes.index(a) for a in self._scenario.machine.kinematics.axes]
        return any(target[i] != self._pos[i] for i in index)

    def _swivel_collision(self, start: np.ndarray, target: np.ndarray) -> Alarm | None:
        """Sample the swivel path (end pose included): the ball/cutter end must stay clear."""
        self._check_limits(target)
        with self._lock:
            tool, angle = self._tool, self._spindle_angle
        if tool is None:
            return None
        sc = self._scenario
        for k in range(1, SWIVEL_SAMPLES + 1):
            pose = start + (target - start) * (k / SWIVEL_SAMPLES)
            if tool == sc.probe.t:
                hit = self._ball_in_solid(pose, angle)
            else:
                cutter = sc.tool(tool)
                end = pose[_XYZ] - (cutter.length - cutter.radius) * self._tool_axis_at(pose)
                hit = self._scene.subset({"part", "ring_gauge"}).sdf(end) < cutter.radius
            if hit:
                return self._raise_alarm(Alarm(ALARM_PROBE_COLLISION, "Probe collision: the swivel "
                                               "would turn the tool into the workpiece"))
        return None

    def swivel_to(self, angles: dict[str, float]) -> MoveResult:
        """Turn the head axes to ``angles`` (deg), collision-checked at samples, rapid."""
        if not self.has_swivel():
            raise ValueError("this machine has no swivel head")
        head_axes = self._scenario.machine.kinematics.axes
        unknown = set(angles) - set(head_axes)
        if unknown:
            raise ValueError(f"not a head axis: {sorted(unknown)}; the head has {list(head_axes)}")
        return self.goto(dict(angles), None)

    def head_angles_for(self, tool_axis) -> dict[str, float]:
        """CYCLE800-like: the head angles within the limits that put the tool axis ∥ ``tool_axis``."""
        if not self.has_swivel():
            raise ValueError("this machine has no swivel head")
        head_axes = self._scenario.machine.kinematics.axes
        with self._lock:
            current = [float(self._pos[self._axes.index(a)]) for a in head_axes]
        best = None
        for cand in head_angles_for(head_axes, tool_axis, current):
            shifted = []
            for axis, value, now in zip(head_axes, cand, current, strict=True):
                lo, hi = self._limits[axis]
                value = value + 360.0 * round((now - value) / 360.0)   # nearest turn to the current angle
                while value > hi + 1e-9:
                    value -= 360.0
                while value < lo - 1e-9:
                    value += 360.0
                shifted.append(value if lo - 1e-9 <= value <= hi + 1e-9 else None)
            if None in shifted:
                continue
            cost = max(abs(v - now) for v, now in zip(shifted, current, strict=True))
            if best is None or cost < best[0] - 1e-9:
                best = (cost, shifted)
        if best is None:
            alarm = self._raise_alarm(Alarm(ALARM_LIMIT, "Swivel: the tool axis cannot be reached within the "
                                            "limits of the head axes"))
            raise MachineAlarm(alarm)
        return {a: float(v) for a, v in zip(head_axes, best[1], strict=True)}

    def swivel_to_wcs(self, wcs2bcs_rotation, infeed=(0.0, 0.0, 1.0)) -> MoveResult:
        """CYCLE800-like re-alignment: tool axis ∥ the WCS infeed axis R·infeed (MCS)."""
        rotation = np.asarray(wcs2bcs_rotation, dtype=float)
        if rotation.shape == (4, 4):
            rotation = rotation[:3, :3]
        n = rotation @ np.asarray(infeed, dtype=float)
        return self.swivel_to(self.head_angles_for(n / np.linalg.norm(n)))

    def retract_tool_axis(self, distance: float | None = None) -> MoveResult:
        """Up along the tool axis by ``distance`` (default: as far as the X/Y/Z limits allow)."""
        with self._lock:
            axis = self._tool_axis_at(self._pos)
            xyz = self._pos[_XYZ].copy()
        s_max = math.inf
        for i, name in enumerate(GEOMETRY_AXES):
            lo, hi = self._limits[name]
            if axis[i] > 1e-12:
                s_max = min(s_max, (hi - xyz[i]) / axis[i])
            elif axis[i] < -1e-12:
                s_max = min(s_max, (lo - xyz[i]) / axis[i])
        s = max(0.0, s_max) if distance is None else _finite(distance, "distance")
        target = xyz + s * axis
        return self.goto({a: float(v) for a, v in zip(GEOMETRY_AXES, target, strict=True)}, None)

    # --- machine view --------------------------------------------------------------------
    def scene_geometry(self) -> dict:
        """The true scene for the machine view (JSON-ready, MCS)."""
        sc = self._scenario
        out = outline(sc, self._table_angle)
        with self._lock:
            position = self._pos.copy()
            tool, angle = self._tool, self._spindle_angle
        axes_xyz, tool_axis = position[_XYZ], self._tool_axis_at(position)
        if tool is not None and tool == sc.probe.t:
            tip = self._ball_centre(position, angle)
            probe = {"tip": tip, "diameter": sc.probe.ball_diameter, "is_probe": True, "tool_radius": 0.0}
        elif tool is not None:
            cutter = sc.tool(tool)
            probe = {"tip": axes_xyz - cutter.length * tool_axis, "diameter": 2 * cutter.radius,
                     "is_probe": False, "tool_radius": cutter.radius}
        else:
            probe = {"tip": axes_xyz, "diameter": 0.0, "is_probe": False, "tool_radius": 0.0}
        probe["tip"] = [float(v) for v in probe["tip"]]
        probe["axis"] = [float(v) for v in tool_axis]
        out["probe"] = probe
        return out


def _finite(value, name: str) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(number):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return number


def _positive(value, name: str) -> float:
    number = _finite(value, name)
    if number <= 0.0:
        raise ValueError(f"{name} must be > 0, got {value!r}")
    return number

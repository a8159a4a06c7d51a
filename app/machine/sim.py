"""The simulated milling machine behind the Machine Protocol (design.md §5): the facade.

It implements ``Machine``, ``SwivelHead`` and ``SimulatorControl`` (protocol.py) over separate
objects, each with its own decisions in its module docstring:

- ``kinematics.Kinematics``: axes, limits, swivel head, where the tool is for given axes;
- ``contact.Contact``: the true scene, the first switch or crash along a path, latch, braking;
- ``motion.Motion``: the position, the one timed travel, busy/abort/stop, the continuous jog;
- ``nc_data.NcData``: the NC's copy of the named offsets and tool data the HMI writes.

The facade holds what the NC holds besides (tool in the spindle and its offset length, the
active frame, override, spindle, alarms) and decides what a motion means for the alarms.
One lock (shared with the motion) guards that state; it is never held while sleeping.

Decisions (where the spec leaves room):
- A broken probe (PROBE_BROKEN per measuring-math §1.3, not resettable) refuses every motion
  (probe, goto, jog) while it is in the spindle; Reset does not repair it, a tool change (any
  tool, also the same T = new stylus) or ``load()`` does.
- A switch during goto/jog is a collision (PROBE_COLLISION); if the overtravel behind the first
  contact then exceeds ``max_deflection`` the probe also breaks (PROBE_BROKEN, not resettable).
- Active alarms do not lock the axes (the operator may jog away before pressing Reset).
- Limits: a move whose end lies outside the limits is refused before moving: the limit
  alarm is put into the status and raised as ``MachineAlarm``. A continuous jog stops at
  the limit with the same alarm.
- Reset during a motion: goto/jog return ``MoveResult(completed=False, alarm=RESET_ABORT)``; a
  probe() raises ``MachineAlarm(RESET_ABORT)``. That alarm is informational and not put into
  the status (Reset has just cleared the status alarms).
- Feed override is read continuously for the motion timing; the probe physics (latency,
  braking) use the override in effect when the move starts.
- Rotary table: the part is re-placed when a positioning of the table axis ends (see
  ``_move_and_turn``); a table turn that ends with the probe inside the part is a collision.
- Swivel head: a motion that turns the head is refused before it starts when any sampled pose
  touches a solid (PROBE_COLLISION; the probe does not measure while swivelling).
  ``swivel_to_wcs`` aligns the tool axis with the WCS infeed axis (kinematics.head_angles_for).
"""

from __future__ import annotations

import threading
from typing import Any

import numpy as np

from engine import alarms

from .checks import finite, positive
from .contact import Contact, Event
from .kinematics import XYZ, Kinematics
from .motion import Motion
from .nc_data import NcData
from .probe_signal import TOOL, WORKPIECE, ProbeSignals
from .protocol import (
    ActiveFrame,
    Alarm,
    MachineAlarm,
    MachineBusy,
    MachineStatus,
    MoveResult,
    ProbeResult,
    add_alarm_once,
)
from .scenario import GEOMETRY_AXES, Scenario
from .scene import Scene, outline, protection_data
from .series import cut_part, new_tools, worn
from .sim_trainer import setup_error as trainer_setup_error


class SimulatedMachine:
    """A 3-axis (+ rotary) milling machine with a 3D touch probe; the scenario is its truth."""

    def __init__(self, scenario: Scenario) -> None:
        self._lock = threading.RLock()
        self._motion = Motion(self._lock, np.zeros(len(scenario.axes)))
        self._install(scenario)
        self._series = (scenario, new_tools(scenario), 0)

    # --- scenario (SimulatorControl) -----------------------------------------------------
    def _install(self, scenario: Scenario) -> None:
        # build everything first: a scenario the physics refuses changes nothing (design.md §9.1)
        kinematics = Kinematics(scenario)
        start = kinematics.start_position()
        contact = Contact(scenario, kinematics, kinematics.table_angle(start) or 0.0)
        nc = NcData(scenario.axes)
        with self._lock:
            self._scenario = scenario
            self._kinematics = kinematics
            self._motion.position = start
            self._contact = contact
            self._nc = nc
            self._tool: int | None = scenario.probe.t
            self._offset_length = scenario.probe.nominal_length
            self._frame = ActiveFrame()
            self._bcs2wcs = np.eye(4)
            self._override = 100.0
            self._spindle_angle = 0.0
            self._spindle_speed = 0.0
            self._alarms: list[Alarm] = []
            self._probes = ProbeSignals(scenario.probe.radio, scenario.tool_probe.radio if scenario.tool_probe
                                        else None, scenario.tool_probe is not None)

    def load(self, scenario: Scenario) -> None:
        """Replace the truth and reset the machine (axes to the start position, probe in spindle)."""
        self.reset()
        self._install(scenario)
        with self._lock:
            self._series = (scenario, new_tools(scenario), 0)      # (programmed part, cutters, parts made)

    def machine_part(self, scatter_sigma: float = 0.0) -> int:
        """The next part of the series replaces the workpiece (app.machine.series); the machine
        keeps its position, tool, frame and alarms. Returns the part's number (1, 2, ...)."""
        sigma = finite(scatter_sigma, "scatter_sigma")
        if not 0.0 <= sigma <= 1.0:
            raise ValueError("scatter_sigma must be 0..1 mm")
        with self._lock:
            if self._motion.busy:
                raise MachineBusy("the next part is clamped while the axes stand still")
            base, sizes, made = self._series
            rng = np.random.default_rng([base.seed, made + 1])
            part = cut_part(base, sizes, self._nc.tools, made + 1, rng, sigma)
            contact = Contact(part, self._kinematics, self._contact.table_angle)
            self._scenario, self._contact = part, contact
            self._series = (base, worn(base, sizes), made + 1)
            return made + 1

    @property
    def scenario(self) -> Scenario:
        return self._scenario

    @property
    def scene(self) -> Scene:
        return self._contact.scene

    @property
    def axes(self) -> tuple[str, ...]:
        return self._kinematics.axes

    @property
    def controller(self) -> str:
        return "sim"

    # --- the NC's data -------------------------------------------------------------------
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

    # --- status --------------------------------------------------------------------------
    def status(self) -> MachineStatus:
        with self._lock:
            position = self._motion.position
            mcs = self._kinematics.as_dict(position)
            tool_length = self._offset_length if self._tool is not None else 0.0
            # what the NC computes from its kinematic data (design.md §10.6), not the truth
            axis = self._kinematics.nc_tool_axis(position)
            shift = self._kinematics.nc_head_shift(position)
            tip_in_mcs = position[XYZ] + shift - tool_length * axis
            p_in_wcs = self._bcs2wcs @ np.append(tip_in_mcs, 1.0)
            wcs = {a: float(p_in_wcs[i]) for i, a in enumerate(GEOMETRY_AXES)}
            for a in self.axes[3:]:
                wcs[a] = mcs[a] - float(self._frame.rotary_offsets.get(a, 0.0))
            on_probe, on_tool_probe = self._contact.touching(position, self._tool, self._spindle_angle)
            return MachineStatus(
                mcs=mcs, wcs=wcs, active_offset=self._frame.name, tool=self._tool,
                tool_length=float(tool_length), feed_override=self._override,
                spindle_angle=self._spindle_angle, spindle_speed=self._spindle_speed,
                busy=self._motion.busy, alarms=tuple(self._alarms),
                tool_axis=(float(axis[0]), float(axis[1]), float(axis[2])),
                head_shift=(float(shift[0]), float(shift[1]), float(shift[2])),
                probe=self._probes.state(WORKPIECE, self._contact.is_probe(self._tool), on_probe),
                tool_probe=self._probes.state(TOOL, True, on_tool_probe) if self._probes.has(TOOL) else None)

    def set_probe(self, which: str, deflect: bool | None = None, battery: float | None = None,
                  armed: bool | None = None) -> None:
        """The operator's hand on a probe (design.md §10.4, probe_signal.py)."""
        with self._lock:
            self._probes.set(which, deflect, battery, armed)

    # --- settings without motion ---------------------------------------------------------
    def change_tool(self, tool: int | None, offset_length: float) -> None:
        """Tool change; a new probe (or any other tool) replaces a broken stylus."""
        offset_length = finite(offset_length, "offset_length")
        if tool is not None and tool != self._scenario.probe.t and self._scenario.tool(tool) is None:
            # the simulator has no truth for it (spec/jog-measuring.md §10)
            raise MachineAlarm(self._raise_alarm(Alarm.of(alarms.NO_TOOL_FOR_IDENTIFIER, f"No tool for the given "
                                                          f"tool identifier: T{tool} is not in the magazine")))
        with self._lock:
            if self._motion.busy:
                raise MachineBusy("tool change while the axes move")
            self._tool = tool
            self._offset_length = offset_length
            broken = self._broken_alarm()
            self._alarms = [a for a in self._alarms if a is not broken]

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

    def spindle_position(self, angle: float) -> None:
        """SPOS: the probe turns with the spindle, its eccentricity (measuring-math §1.7) and, with
        ``probe.pretravel_frame`` "probe", its pre-travel lobing (contact.py)."""
        with self._lock:
            self._spindle_angle = finite(angle, "angle") % 360.0
            self._spindle_speed = 0.0

    def spindle_rotate(self, speed_rpm: float) -> None:
        with self._lock:
            self._spindle_speed = finite(speed_rpm, "speed_rpm")

    def set_override(self, percent: float) -> None:
        percent = finite(percent, "percent")
        if not 0.0 <= percent <= 120.0:
            raise ValueError(f"feed override must be within 0..120 %, got {percent}")
        with self._lock:
            self._override = percent

    # --- Reset / stop / alarms -----------------------------------------------------------
    def reset(self) -> None:
        """Abort any motion at its current position, stop the spindle, clear resettable alarms."""
        self._motion.abort()
        with self._lock:
            self._spindle_speed = 0.0          # NC Reset ends M3/M4 like a real control
            self._alarms = [a for a in self._alarms if not a.resettable]

    def stop(self) -> None:
        """Stop motion without an alarm (jog key released)."""
        self._motion.stop()

    def post_alarm(self, alarm: Alarm) -> None:
        """An alarm raised by a measuring cycle (e.g. probe not switched): shown until Reset."""
        self._raise_alarm(alarm)

    def _raise_alarm(self, alarm: Alarm) -> Alarm:
        with self._lock:
            return add_alarm_once(self._alarms, alarm)

    def _broken_alarm(self) -> Alarm | None:
        """The broken-stylus alarm: the probe is broken exactly while it is in the list."""
        return next((a for a in self._alarms if a.is_(alarms.PROBE_BROKEN)), None)

    def _break_probe(self) -> Alarm:
        return self._raise_alarm(Alarm.of(alarms.PROBE_BROKEN, "Probe broken: overtravel beyond the "
                                          "permissible deflection"))

    def _check_limits(self, target: np.ndarray) -> None:
        alarm = self._kinematics.limit_alarm(target)
        if alarm is not None:
            raise MachineAlarm(self._raise_alarm(alarm))

    # --- motions -------------------------------------------------------------------------
    def goto(self, target_mcs: dict[str, float], feed: float | None = None) -> MoveResult:
        """Straight positioning (rapid when feed is None), collision-monitored."""
        target = self._target(target_mcs)
        if feed is not None:
            feed = positive(feed, "feed")
        self._begin()
        try:
            return self._move_and_turn(target, feed)
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
            return self._move_and_turn(target, feed)
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
                result = self._move_and_turn(target, feed)
                if result.completed:   # ran onto the software limit
                    self._raise_alarm(Alarm.of(alarms.SOFTWARE_LIMIT, f"Axis {axis} at software limit switch"))
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
            kin = self._kinematics
            start = self._motion.position.copy()
            end = kin.along(start, d, distance)
            self._check_limits(end)
            override = self._override
            event = self._first_event(start, d, distance)
            if event is None or (event.kind == "switch" and event.s_switch > distance):
                reached, outcome = self._travel(start, end, feed)
                self._raise_if_aborted(outcome)
                return ProbeResult(False, None, kin.as_dict(reached), feed, override)
            if event.kind == "crash":
                reached, outcome = self._travel(start, kin.along(start, d, event.s_contact), feed)
                self._raise_if_aborted(outcome)
                raise MachineAlarm(self._raise_alarm(Alarm.of(alarms.PROBE_COLLISION, event.text)))
            stop = self._contact.measuring_stop(event, feed * override / 100.0, distance, self._tool)
            reached, outcome = self._travel(start, kin.along(start, d, stop.s_stop), feed)
            self._raise_if_aborted(outcome)
            if stop.breaks:
                raise MachineAlarm(self._break_probe())
            assert stop.s_latch is not None                 # a measuring stop has its latch
            latched = kin.along(start, d, stop.s_latch)
            return ProbeResult(True, kin.as_dict(latched), kin.as_dict(reached), feed, override)
        finally:
            self._motion.finish()

    # --- motion internals ----------------------------------------------------------------
    def _begin(self) -> None:
        """Claim the axes; a broken probe refuses every motion."""
        def probe_whole() -> None:
            broken = self._broken_alarm()
            if broken is not None:
                raise MachineAlarm(broken)

        self._motion.begin(probe_whole)

    def _first_event(self, start: np.ndarray, d: np.ndarray, length: float) -> Event | None:
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

    def _move_and_turn(self, target: np.ndarray, feed: float | None) -> MoveResult:
        """``_move``, then the part follows the rotary table axis (scenario machine.rotary_table).

        Simplification: the path is checked with the part where it stood at the start of the
        move; a table turn that ends with the probe inside the part is a collision (PROBE_COLLISION).
        """
        start = self._motion.position.copy()
        if self._kinematics.head_turns(start, target):
            alarm = self._swivel_collision(start, target)
            if alarm is not None:
                return MoveResult(self._kinematics.as_dict(start), False, alarm)
        result = self._move(target, feed)
        if not self._place_part():
            return result
        if self._contact.is_probe(self._tool):
            with self._lock:
                hit = self._contact.ball_in_solid(self._motion.position, self._spindle_angle)
            if hit:
                alarm = self._raise_alarm(Alarm.of(alarms.PROBE_COLLISION, "Probe collision: the rotary table "
                                                   "turned the workpiece into the probe"))
                return MoveResult(result.mcs, False, alarm)
        return result

    def _place_part(self) -> bool:
        """Re-place the part when the rotary table axis moved; True when it did."""
        with self._lock:
            angle = self._kinematics.table_angle(self._motion.position)
            return angle is not None and self._contact.place_part(angle)

    def _move(self, target: np.ndarray, feed: float | None) -> MoveResult:
        """Positioning with collision monitoring (rapid when feed is None); caller holds the busy flag."""
        kin = self._kinematics
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
        alarm = self._raise_alarm(Alarm.of(alarms.PROBE_COLLISION, event.text))
        if stop.breaks:
            self._break_probe()
        return MoveResult(kin.as_dict(reached), False, alarm)

    def _swivel_collision(self, start: np.ndarray, target: np.ndarray) -> Alarm | None:
        """Sample the swivel path (end pose included): the ball/cutter end must stay clear."""
        self._check_limits(target)
        with self._lock:
            tool, angle = self._tool, self._spindle_angle
        if not self._contact.swivel_hits(start, target, tool, angle):
            return None
        return self._raise_alarm(Alarm.of(alarms.PROBE_COLLISION, "Probe collision: the swivel "
                                          "would turn the tool into the workpiece"))

    def _raise_if_aborted(self, outcome: str) -> None:
        if outcome != "done":
            raise MachineAlarm(Alarm.of(alarms.RESET_ABORT, "Motion aborted by Reset" if outcome == "reset"
                                        else "Motion stopped"))

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

    # --- kinematic data (KinematicData, design.md §10.6) ----------------------------------
    def kinematic_data(self) -> dict[str, dict[str, Any]]:
        with self._lock:
            return self._kinematics.nc_lines()

    def write_kinematic_data(self, lines: dict) -> None:
        with self._lock:
            self._kinematics.set_nc_lines(lines)

    # --- swivel head (SwivelHead) --------------------------------------------------------
    def has_swivel(self) -> bool:
        return self._kinematics.has_swivel()

    def swivel_to(self, angles: dict[str, float]) -> MoveResult:
        """Turn the head axes to ``angles`` (deg), collision-checked at samples, rapid."""
        head_axes = self._kinematics.head_axes()
        unknown = set(angles) - set(head_axes)
        if unknown:
            raise ValueError(f"not a head axis: {sorted(unknown)}; the head has {list(head_axes)}")
        return self.goto(dict(angles), None)

    def head_angles_for(self, tool_axis) -> dict[str, float]:
        """CYCLE800-like: the head angles within the limits that put the tool axis ∥ ``tool_axis``."""
        self._kinematics.head_axes()                       # ValueError without a swivel head
        with self._lock:
            position = self._motion.position.copy()
        angles = self._kinematics.head_angles_for(tool_axis, position)
        if angles is None:
            raise MachineAlarm(self._raise_alarm(Alarm.of(alarms.SOFTWARE_LIMIT, "Swivel: the tool axis cannot "
                                                          "be reached within the limits of the head axes")))
        return angles

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
            position = self._motion.position.copy()
        if distance is not None:
            distance = finite(distance, "distance")
        return self.goto(self._kinematics.retract_target(position, distance), None)

    # --- protection model (the start guard, issue 24 §1) ----------------------------------
    def protection_model(self) -> dict:
        """The solids and axis limits the control protects (plain data, MCS): this machine's
        commissioned model of its work space is its scene (the guard computes on its own)."""
        with self._lock:
            scene = self._contact.scene
            limits = {a: [float(lo), float(hi)] for a, (lo, hi) in self._kinematics.limits.items()}
        return {"bodies": protection_data(scene), "limits": limits}

    # --- machine view (SimulatorControl) ---------------------------------------------------
    def scene_geometry(self) -> dict:
        """The true scene for the machine view (JSON-ready, MCS)."""
        sc = self._scenario
        out = outline(sc, self._contact.table_angle)
        with self._lock:
            position = self._motion.position.copy()
            tool, angle = self._tool, self._spindle_angle
        axes_xyz, tool_axis = position[XYZ], self._kinematics.tool_axis(position)
        cutter = sc.tool(tool) if tool is not None else None
        if self._contact.is_probe(tool):
            tip = self._kinematics.ball_centre(position, angle)
            probe: dict[str, object] = {"diameter": sc.probe.ball_diameter, "is_probe": True, "tool_radius": 0.0}
        elif cutter is not None:
            tip = self._kinematics.cutter_tip(position, cutter)
            probe = {"diameter": 2 * cutter.radius, "is_probe": False, "tool_radius": cutter.radius}
        else:
            tip = axes_xyz
            probe = {"diameter": 0.0, "is_probe": False, "tool_radius": 0.0}
        out["probe"] = {"tip": [float(v) for v in tip], **probe, "axis": [float(v) for v in tool_axis]}
        return out

    def setup_error(self, offset: str) -> dict:
        """The trainer's answer: offset ``offset`` as the NC holds it against the hidden part
        (sim_trainer.py)."""
        with self._lock:
            scenario, angle, offsets = self._scenario, self._contact.table_angle, self._nc.offsets
        return trainer_setup_error(scenario, angle, offsets, offset)

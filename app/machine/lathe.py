"""The simulated lathe behind the Machine Protocol: the facade (turning.md §10.2, turning §11).

It implements ``Machine`` and ``SimulatorControl`` (protocol.py) for a scenario with
``machine.kind: "lathe"`` (lathe_scenario) over its own objects:

- ``lathe_kinematics.LatheKinematics``: axes X (radius), Z, optional Y; limits; the true tip,
  nose centre and ball centre ``F − (L1·x̂ + L2·ẑ)``;
- ``lathe_scene.LatheContact``: the part turning with the main spindle (clamping eccentricity,
  face run-out), the chuck, the reference grooves, the tool probe cube; exact contact;
- ``motion.Motion``: the position and the one timed travel, shared with the milling machine;
- ``LatheNcData``: the NC's copy of the named offsets and the tool data (with ``sl``, ``l1``,
  ``l2`` and their wear) the HMI writes.

What the NC holds besides: the tool in the turret position, the active frame, DIAMON, the
main spindle's position (SPOS), override, alarms. The NC's reference point is the tip of the
active tool (the ball centre for the probe) from its **own tool data**: ``P = F − (L1, L2)``
with L = geometry + wear of the NC's copy (``write_tool``), so an HMI write of the tool data
moves the reference at once, as on a control. ``status().wcs`` shows it in the active WCS,
X as a diameter with DIAMON (``diameter_programming``).

Decisions (where the spec leaves room):
- Motion, limits, Reset, override, alarms and the broken stylus behave as on the milling
  machine (sim.py): a switch during positioning is 61302; a move ending beyond a limit is
  refused before it starts; a broken probe refuses motion until a tool change or a load.
- SPOS turns the workpiece (not the probe: it sits in the turret). A turn that would bring the
  part into the probe or the active tool is refused with 61302 and the spindle stays; without
  an SPOS-capable spindle (``machine.spos`` false) SPOS is refused with 61372.
- ``change_tool``'s offset length is not used: the lengths come from the NC's tool data of
  that T (as the control reads its D data); a T without truth in the scenario is refused.
- A machined-part series (``machine_part``): every profile item with ``machined_by`` is cut
  with the tool's true L1 against the L1 the NC holds: r_cut = r_programmed + (L1_NC − L1_true)
  (turning.md §11: L1 0.01 too long makes a bore or an OD 0.02 larger); then the tool wears by
  its ``wear_per_part`` (its true L1/L2 get shorter).
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

import numpy as np

from engine import alarms

from .checks import finite, positive
from .lathe_kinematics import LatheKinematics
from .lathe_scenario import LatheScenario
from .lathe_scene import LatheContact, lathe_outline, tool_outline
from .motion import Motion
from .nc_data import NcData, _number, _object
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

LATHE_TOOL_KEYS = ("type", "length", "radius", "wear", "sl", "l1", "l2")
LATHE_WEAR_KEYS = ("length", "radius", "l1", "l2")


class LatheNcData(NcData):
    """NcData whose tool data also hold the lathe fields ``sl``, ``l1``, ``l2``, ``wear.l1/l2``."""

    def write_tool(self, t: int, data: dict) -> None:
        if isinstance(t, bool) or not isinstance(t, int) or t < 1:
            raise ValueError(f"t: a tool number is an integer >= 1, got {t!r}")
        _object(data, "tool", LATHE_TOOL_KEYS)
        for key in ("type", "radius"):
            if key not in data:
                raise ValueError(f"{key}: missing in the tool data of T{t}")
        tool_type = data["type"]
        if isinstance(tool_type, bool) or not isinstance(tool_type, int):
            raise ValueError(f"type: must be an integer tool type, got {tool_type!r}")
        sl = data.get("sl", 0)
        if isinstance(sl, bool) or not isinstance(sl, int) or not 0 <= sl <= 9:
            raise ValueError(f"sl: a cutting edge position 0..9, got {sl!r}")
        wear = _object(data.get("wear") or {}, "wear", LATHE_WEAR_KEYS)
        self._tools[t] = {"type": tool_type, "sl": sl, "length": _number(data.get("length", 0.0), "length"),
                          "radius": _number(data["radius"], "radius"),
                          "l1": _number(data.get("l1", 0.0), "l1"), "l2": _number(data.get("l2", 0.0), "l2"),
                          "wear": {k: _number(wear.get(k, 0.0), f"wear.{k}") for k in LATHE_WEAR_KEYS}}

    def lengths(self, t: int | None) -> tuple[float, float]:
        """The effective (L1, L2) the NC uses for T ``t`` (geometry + wear); 0 when unknown."""
        data = self._tools.get(t) if t is not None else None
        if data is None:
            return 0.0, 0.0
        return data["l1"] + data["wear"]["l1"], data["l2"] + data["wear"]["l2"]


@dataclass(frozen=True)
class LatheStatus(MachineStatus):
    """MachineStatus of a lathe: the NC's effective lengths (L1, L2) of the active tool, DIAMON."""

    tool_lengths: tuple[float, float] = (0.0, 0.0)
    diameter_programming: bool = False
    kind: str = "lathe"


class LatheMachine:
    """A 2-axis (optionally 3-axis) lathe with a turret, a workpiece probe and a tool probe."""

    kind = "lathe"

    def __init__(self, scenario: LatheScenario) -> None:
        if getattr(scenario, "kind", None) != "lathe":
            raise ValueError("the simulated lathe plays a scenario with machine.kind \"lathe\"")
        self._lock = threading.RLock()
        self._motion = Motion(self._lock, np.zeros(3))
        self._install(scenario)

    # --- scenario (SimulatorControl) -------------------------------------------------------
    def _install(self, scenario: LatheScenario) -> None:
        if getattr(scenario, "kind", None) != "lathe":
            raise ValueError("the simulated lathe plays a scenario with machine.kind \"lathe\"; "
                             "start the HMI with a milling scenario for the milling machine")
        kinematics = LatheKinematics(scenario)
        start = kinematics.start_position()
        contact = LatheContact(scenario, kinematics)
        nc = LatheNcData(scenario.axes)
        with self._lock:
            self._scenario = scenario
            self._kinematics = kinematics
            self._motion.position = start
            self._contact = contact
            self._nc = nc
            self._tool: int | None = scenario.probe.t
            self._frame = ActiveFrame()
            self._bcs2wcs = np.eye(4)
            self._override = 100.0
            self._spindle_angle = float(scenario.spindle.angle) % 360.0
            self._spindle_speed = 0.0
            self._alarms: list[Alarm] = []
            self._worn: dict[int, tuple[float, float]] = {}
            self._parts = 0
            self._probes = ProbeSignals(scenario.probe.radio, scenario.tool_probe.radio if scenario.tool_probe
                                        else None, scenario.tool_probe is not None)

    def load(self, scenario: LatheScenario) -> None:
        self.reset()
        self._install(scenario)

    @property
    def scenario(self) -> LatheScenario:
        return self._scenario

    @property
    def axes(self) -> tuple[str, ...]:
        return self._kinematics.axes

    @property
    def controller(self) -> str:
        return "sim"

    @property
    def diameter_programming(self) -> bool:
        return bool(self._scenario.machine.diameter_programming)

    @property
    def spos_capable(self) -> bool:
        return bool(self._scenario.machine.spos)

    # --- the NC's data ----------------------------------------------------------------------
    def write_offset(self, name: str, frame: dict) -> None:
        with self._lock:
            self._nc.write_offset(name, frame)

    def write_tool(self, t: int, data: dict) -> None:
        with self._lock:
            self._nc.write_tool(t, data)

    @property
    def nc_offsets(self) -> dict[str, dict]:
        with self._lock:
            return self._nc.offsets

    @property
    def nc_tools(self) -> dict[int, dict]:
        with self._lock:
            return self._nc.tools

    def close(self) -> None:
        self.stop()

    # --- status -----------------------------------------------------------------------------
    def _lengths(self) -> tuple[float, float]:
        return self._nc.lengths(self._tool)

    def status(self) -> LatheStatus:
        with self._lock:
            position = self._motion.position.copy()
            l1, l2 = self._lengths()
            ref = self._kinematics.reference(position, l1, l2)
            p = self._bcs2wcs @ np.append(ref, 1.0)
            wcs = {"X": float(p[0]), "Y": float(p[1]), "Z": float(p[2])}
            if self.diameter_programming:
                wcs["X"] *= 2.0
            on_probe, on_tool_probe = self._contact.touching(position, self._tool, self._spindle_angle,
                                                             self._worn_of(self._tool))
            return LatheStatus(
                mcs=self._kinematics.as_dict(position), wcs=wcs, active_offset=self._frame.name, tool=self._tool,
                tool_length=float(l1), feed_override=self._override, spindle_angle=self._spindle_angle,
                spindle_speed=self._spindle_speed, busy=self._motion.busy, alarms=tuple(self._alarms),
                plane="G18", tool_axis=(1.0, 0.0, 0.0), tool_lengths=(float(l1), float(l2)),
                diameter_programming=self.diameter_programming,
                probe=self._probes.state(WORKPIECE, self._contact.is_probe(self._tool), on_probe),
                tool_probe=self._probes.state(TOOL, True, on_tool_probe) if self._probes.has(TOOL) else None)

    def set_probe(self, which: str, deflect: bool | None = None, battery: float | None = None,
                  armed: bool | None = None) -> None:
        """The operator's hand on a probe (design.md §10.4, probe_signal.py)."""
        with self._lock:
            self._probes.set(which, deflect, battery, armed)

    # --- settings without motion ------------------------------------------------------------
    def change_tool(self, tool: int | None, offset_length: float = 0.0) -> None:
        """Turret indexing; a new tool (or the probe again) replaces a broken stylus."""
        finite(offset_length, "offset_length")
        if tool is not None and tool != self._scenario.probe.t and self._scenario.tool(tool) is None:
            raise MachineAlarm(self._raise_alarm(Alarm.of(alarms.NO_TOOL_FOR_IDENTIFIER, f"No tool for the given "
                                                          f"tool identifier: T{tool} is not in the turret")))
        with self._lock:
            if self._motion.busy:
                raise MachineBusy("tool change while the axes move")
            self._tool = tool
            broken = self._broken_alarm()
            self._alarms = [a for a in self._alarms if a is not broken]

    def set_tool_offset(self, offset_length: float) -> None:
        """The lathe reads its lengths from its tool data (``write_tool``): nothing to do."""
        finite(offset_length, "offset_length")

    def activate_frame(self, frame: ActiveFrame) -> None:
        matrix = np.asarray(frame.wcs2bcs, dtype=float)
        if matrix.shape != (4, 4) or not np.all(np.isfinite(matrix)):
            raise ValueError("frame.wcs2bcs must be a finite 4x4 matrix")
        bcs2wcs = np.linalg.inv(matrix)
        with self._lock:
            self._frame, self._bcs2wcs = frame, bcs2wcs

    def spindle_position(self, angle: float) -> None:
        """SPOS of the main spindle: the clamped part turns with it (its eccentricity, run-out)."""
        angle = finite(angle, "angle") % 360.0
        if not self.spos_capable:
            raise MachineAlarm(self._raise_alarm(Alarm.of(alarms.NEEDS_SPOS, "The main spindle cannot be "
                                                          "positioned (SPOS): it is not SPOS-capable")))
        with self._lock:
            if self._motion.busy:
                raise MachineBusy("SPOS while the axes move")
            position = self._motion.position.copy()
            if self._contact.in_solid(position, self._tool, angle, self._worn_of(self._tool)):
                alarm = Alarm.of(alarms.PROBE_COLLISION, "Probe collision: SPOS would turn the workpiece into "
                                 "the probe or the tool")
                raise MachineAlarm(self._raise_alarm(alarm))
            self._spindle_angle = angle
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

    # --- Reset / stop / alarms --------------------------------------------------------------
    def reset(self) -> None:
        self._motion.abort()
        with self._lock:
            self._spindle_speed = 0.0
            self._alarms = [a for a in self._alarms if not a.resettable]

    def stop(self) -> None:
        self._motion.stop()

    def post_alarm(self, alarm: Alarm) -> None:
        self._raise_alarm(alarm)

    def _raise_alarm(self, alarm: Alarm) -> Alarm:
        with self._lock:
            return add_alarm_once(self._alarms, alarm)

    def _broken_alarm(self) -> Alarm | None:
        return next((a for a in self._alarms if a.is_(alarms.PROBE_BROKEN)), None)

    def _break(self) -> Alarm:
        if self._contact.is_probe(self._tool):
            return self._raise_alarm(Alarm.of(alarms.PROBE_BROKEN, "Probe broken: overtravel beyond the "
                                              "permissible deflection"))
        return self._raise_alarm(Alarm.of(alarms.PROBE_COLLISION, "Probe collision: the tool probe was pushed "
                                          "beyond its permissible deflection"))

    def _check_limits(self, target: np.ndarray) -> None:
        alarm = self._kinematics.limit_alarm(target)
        if alarm is not None:
            raise MachineAlarm(self._raise_alarm(alarm))

    # --- motions ----------------------------------------------------------------------------
    def goto(self, target_mcs: dict[str, float], feed: float | None = None) -> MoveResult:
        target = self._target(target_mcs)
        if feed is not None:
            feed = positive(feed, "feed")
        self._begin()
        try:
            return self._move(target, feed)
        finally:
            self._motion.finish()

    def jog(self, axis: str, distance: float, feed: float | None = None) -> MoveResult:
        index = self._kinematics.index(axis)
        distance = finite(distance, "distance")
        feed = self._scenario.machine.jog_feed if feed is None else positive(feed, "feed")
        self._begin()
        try:
            target = self._motion.position.copy()
            target[index] += distance
            return self._move(target, feed)
        finally:
            self._motion.finish()

    def jog_continuous(self, axis: str, direction: int, feed: float | None = None) -> None:
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
                result = self._move(target, feed)
                if result.completed:
                    self._raise_alarm(Alarm.of(alarms.SOFTWARE_LIMIT, f"Axis {axis} at software limit switch"))
            finally:
                self._motion.finish()

        self._motion.in_background(run)

    def probe(self, direction, distance: float, feed: float) -> ProbeResult:
        """Measuring move (MEAS): the workpiece probe, or the active tool on the tool probe."""
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
                raise MachineAlarm(self._break())
            assert stop.s_latch is not None                 # a measuring stop has its latch
            latched = kin.along(start, d, stop.s_latch)
            return ProbeResult(True, kin.as_dict(latched), kin.as_dict(reached), feed, override)
        finally:
            self._motion.finish()

    # --- motion internals -------------------------------------------------------------------
    def _begin(self) -> None:
        def probe_whole() -> None:
            broken = self._broken_alarm()
            if broken is not None:
                raise MachineAlarm(broken)

        self._motion.begin(probe_whole)

    def _worn_of(self, tool: int | None) -> tuple[float, float]:
        return self._worn.get(tool, (0.0, 0.0)) if tool is not None else (0.0, 0.0)

    def _first_event(self, start: np.ndarray, d: np.ndarray, length: float):
        with self._lock:
            tool, angle = self._tool, self._spindle_angle
        return self._contact.first_event(start, d, length, tool, angle, self._worn_of(tool))

    def _effective_feed(self, feed: float | None) -> float:
        if feed is None:
            return self._scenario.machine.rapid * min(self._override, 100.0) / 100.0
        return feed * self._override / 100.0

    def _travel(self, start: np.ndarray, end: np.ndarray, feed: float | None) -> tuple[np.ndarray, str]:
        return self._motion.travel(start, end, lambda: self._effective_feed(feed), self._scenario.machine.time_scale)

    def _move(self, target: np.ndarray, feed: float | None) -> MoveResult:
        kin = self._kinematics
        start = self._motion.position.copy()
        self._check_limits(target)
        delta = target - start
        length = float(np.linalg.norm(delta))
        event = self._first_event(start, delta / length, length) if length > 0.0 else None
        if event is None or (event.kind == "switch" and event.s_switch > length):
            reached, outcome = self._travel(start, target, feed)
            return self._move_result(reached, outcome)
        stop = self._contact.positioning_stop(event, self._effective_feed(feed), length, self._tool)
        stop_at = start + delta * (stop.s_stop / length)
        reached, outcome = self._travel(start, stop_at, feed)
        if outcome != "done":
            return self._move_result(reached, outcome)
        alarm = self._raise_alarm(Alarm.of(alarms.PROBE_COLLISION, event.text))
        if stop.breaks and self._contact.is_probe(self._tool):
            self._break()
        return MoveResult(kin.as_dict(reached), False, alarm)

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
            if axis == "Y" and "Y" not in self.axes:
                if abs(finite(value, "target.Y")) > 1e-9:
                    raise ValueError("unknown axis 'Y'; the lathe has no Y axis")
                continue
            target[self._kinematics.index(axis)] = finite(value, f"target.{axis}")
        return target

    # --- machined-part series (design.md §9.3, turning.md §11 closed loop) ----------------------
    def machine_part(self, scatter_sigma: float = 0.0) -> int:
        sigma = finite(scatter_sigma, "scatter_sigma")
        if not 0.0 <= sigma <= 1.0:
            raise ValueError("scatter_sigma must be 0..1 mm")
        with self._lock:
            if self._motion.busy:
                raise MachineBusy("the next part is clamped while the axes stand still")
            sc = self._scenario
            if sc.workpiece is None:
                raise ValueError("the scenario has no workpiece to cut")
            self._parts += 1
            rng = np.random.default_rng([sc.seed, self._parts])
            diameters = self._contact.diameters
            for i, item in enumerate(sc.workpiece.profile):
                if item.machined_by is None:
                    continue
                tool = sc.tool(item.machined_by.t)
                if tool is None:
                    raise ValueError(f"workpiece.profile[{i}].machined_by: T{item.machined_by.t} is not in tools")
                l1_nc, _l2 = self._nc.lengths(tool.t)
                l1_true = tool.l1 - self._worn_of(tool.t)[0]
                scatter = float(rng.normal(0.0, sigma)) if sigma > 0.0 else 0.0
                diameters[i] = item.diameter + 2.0 * (l1_nc - l1_true) + scatter
            for tool in sc.tools:
                w1, w2 = self._worn_of(tool.t)
                self._worn[tool.t] = (w1 + tool.wear_per_part.l1, w2 + tool.wear_per_part.l2)
            self._contact = LatheContact(sc, self._kinematics, diameters)
            return self._parts

    @property
    def part_diameters(self) -> dict[int, float]:
        """The true diameters of the profile items of the part now clamped (simulator only)."""
        with self._lock:
            wp = self._scenario.workpiece
            cut = self._contact.diameters
            return {i: cut.get(i, item.diameter) for i, item in enumerate(wp.profile)} if wp else {}

    # --- machine view (SimulatorControl) ----------------------------------------------------
    def scene_geometry(self) -> dict:
        with self._lock:
            position = self._motion.position.copy()
            tool, angle = self._tool, self._spindle_angle
            diameters = self._contact.diameters
        out = lathe_outline(self._scenario, angle, diameters)
        out["probe"] = tool_outline(self._kinematics, self._scenario, position, tool, self._worn_of(tool))
        out["diameter_programming"] = self.diameter_programming
        return out


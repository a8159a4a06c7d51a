"""Contact physics of the simulator: what happens first along a path, and where the axes stop.

The physics of one move is decided when the move starts (contact, switch, latch, braking: all
analytic, scene.py/physics.py); the motion then only plays it out. A path is the straight
line of the X/Y/Z axes from ``start`` along the unit ``d``; every answer is a path length s.

Decisions (where the spec leaves room):
- Probe: contact of the true ball (kinematics.ball_centre) with the scene; the probe switches
  after the pre-travel p(d) (design.md §5) with d in the probe's own axes: d_probe = Rᵀ·d,
  R = R_head·M·Rz(φ) (kinematics.probe_rotation; φ = SPOS, counter-clockwise about the spindle
  axis like the eccentricity), so the lobing turns with the spindle (``probe.pretravel_frame``
  "probe", the default). "machine" keeps the wave-1 model: d in the machine axes, turned only by
  a swivel head (R_headᵀ·d). An already deflected probe pressing deeper switches at once. The latch lies ``latency_s``·v behind the switch plus
  Gaussian noise from the scenario's seed (measuring-math §1.5, design.md §5); the axes stop
  after the braking distance (measuring-math §1.3). Pre-travel + braking beyond ``max_deflection`` breaks it.
- A switch during goto/jog is a collision (PROBE_COLLISION, the facade decides); braking and
  breaking apply alike: a rapid move into the part breaks the stylus, as on a real machine.
- Cutters: a flat-end cylinder, stationary or rotating alike (the full cylinder of radius R;
  the eccentricity of the ball probe is not smeared by rotation either). The tool probe
  contact is exact (Minkowski sum of two vertical cylinders); a cutter touching the
  workpiece or the ring gauge is a crash, detected for a ball of radius R at the tool end
  (approximate: the flat end reaches R·(1 − 1/√2) lower at an oblique approach, the shank is
  not checked). There is no braking/broken check for the tool probe. The tool probe's
  Minkowski sum assumes a cutter along the tool probe's axis (tool measuring with the head at
  0; the tool probe stands along the spindle axis, scene.py, so a horizontal spindle is exact too).
- Swivel: a motion that turns the head is checked at ``SWIVEL_SAMPLES`` poses along the path
  (end pose included; X/Y/Z interpolated with the angles): any contact is a collision.
- Rotary table: the part stands where ``place_part`` put it (the facade re-places it when a
  positioning ends); a path is checked with the part where it stood at the start of the move.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .kinematics import Kinematics
from .physics import braking_distance, latency_path, pretravel_along, pretravel_in_probe
from .scenario import Scenario, Tool
from .scene import Body, Scene, build_scene, tool_probe_cylinder

SWIVEL_SAMPLES = 16           # poses checked along a motion that turns the swivel head
OBSTACLES = {"part", "ring_gauge"}   # what a cutter crashes into (the tool probe switches)


@dataclass(frozen=True)
class Event:
    """What happens first on a path: a switch (probe or tool probe) or a crash (cutter vs part)."""

    kind: str                # "switch" or "crash"
    s_contact: float         # path length to first contact
    s_switch: float          # path length to the switching point (contact + pre-travel)
    text: str


@dataclass(frozen=True)
class Stop:
    """Where a motion stops after its first event: path lengths of the stop and the latch."""

    s_stop: float
    s_latch: float | None    # measuring moves only
    breaks: bool             # the probe's overtravel exceeds its permissible deflection


class Contact:
    """The true scene of one scenario with the part placed at the rotary table's angle."""

    def __init__(self, scenario: Scenario, kinematics: Kinematics, table_angle: float = 0.0) -> None:
        self._scenario = scenario
        self._kinematics = kinematics
        self._rng = np.random.default_rng(scenario.seed)     # the latch noise
        self._table_angle = float(table_angle)
        self._scene = build_scene(scenario, table_angle=self._table_angle)
        self._touching_last: tuple[tuple, tuple[bool, bool]] | None = None

    @property
    def scene(self) -> Scene:
        return self._scene

    @property
    def table_angle(self) -> float:
        """The rotary table angle the part is placed at (deg)."""
        return self._table_angle

    def place_part(self, table_angle: float) -> bool:
        """Re-place the part for the table at ``table_angle``; True when it moved."""
        if table_angle == self._table_angle:
            return False
        self._table_angle = table_angle
        self._scene = build_scene(self._scenario, table_angle=table_angle)
        self._touching_last = None
        return True

    # --- the first event on a path ---------------------------------------------------------
    def is_probe(self, tool: int | None) -> bool:
        return tool is not None and tool == self._scenario.probe.t

    def first_event(self, start: np.ndarray, d: np.ndarray, length: float, tool: int | None,
                    spindle_angle: float) -> Event | None:
        """First switch or crash along ``length`` of the path from the axes at ``start``."""
        if tool is None:
            return None
        if self.is_probe(tool):
            return self._probe_event(start, d, length, spindle_angle)
        return self._cutter_event(start, d, length, tool)

    def _probe_event(self, start, d, length, spindle_angle) -> Event | None:
        probe = self._scenario.probe
        centre = self._kinematics.ball_centre(start, spindle_angle)
        radius = probe.ball_diameter / 2.0
        s_contact = self._scene.first_contact(centre, d, length, radius)
        if s_contact is None:
            return None
        # already deflected and pressing deeper: the probe signal is on at once
        deflected = s_contact == 0.0 and self._scene.sdf(centre) <= radius
        if deflected:
            s_switch = s_contact
        elif probe.pretravel_frame == "machine":               # wave 1: lobing fixed to the machine axes
            head = self._kinematics.head(start)
            d_probe = d if head is None else head.T @ d
            s_switch = s_contact + pretravel_along(d_probe, probe.pretravel)
        else:                                                  # the lobing turns with the probe body
            rotation = self._kinematics.probe_rotation(start, spindle_angle)
            s_switch = s_contact + pretravel_in_probe(d, probe.pretravel, rotation, probe.lobing)
        return Event("switch", s_contact, s_switch, "Probe collision")

    def _cutter(self, tool: int) -> Tool:
        cutter = self._scenario.tool(tool)
        if cutter is None:      # the machine's change_tool refuses a number the scenario has no tool for
            raise ValueError(f"T{tool} is neither the probe nor one of the scenario's tools")
        return cutter

    def _cutter_event(self, start, d, length, tool: int) -> Event | None:
        cutter = self._cutter(tool)
        tool_axis = self._kinematics.tool_axis(start)
        tip = self._kinematics.cutter_tip(start, cutter)
        events = []
        tp = self._scenario.tool_probe
        if tp is not None:
            grown = Scene([Body("tool_probe", tool_probe_cylinder(tp, cutter.radius, cutter.length,
                                                                  self._kinematics.mount))])
            s_contact = grown.first_contact(tip, d, length, 0.0)
            if s_contact is not None:
                deflected = s_contact == 0.0 and grown.sdf(tip) <= 0.0
                s_switch = s_contact if deflected else s_contact + tp.pretravel
                events.append(Event("switch", s_contact, s_switch, "Probe collision (tool probe)"))
        s_crash = self._scene.subset(OBSTACLES).first_contact(tip + cutter.radius * tool_axis, d, length,
                                                              cutter.radius)
        if s_crash is not None:
            events.append(Event("crash", s_crash, s_crash, f"Probe collision: T{tool} hit the workpiece"))
        if not events:
            return None
        return min(events, key=lambda e: e.s_switch)

    # --- poses ----------------------------------------------------------------------------
    def ball_in_solid(self, position: np.ndarray, spindle_angle: float) -> bool:
        centre = self._kinematics.ball_centre(position, spindle_angle)
        return self._scene.sdf(centre) < self._scenario.probe.ball_diameter / 2.0

    def touching(self, position: np.ndarray, tool: int | None, spindle_angle: float) -> tuple[bool, bool]:
        """(workpiece probe, tool probe): does a solid deflect it at the axes ``position`` now?
        The ball deflects the workpiece probe against any solid and the tool probe against its
        disc; a cutter deflects the tool probe (design.md §10.4). Remembered for the last pose:
        every status read asks, and at rest the answer cannot change (issue 30)."""
        key = (np.asarray(position, dtype=float).tobytes(), tool, float(spindle_angle))
        last = self._touching_last
        if last is not None and last[0] == key:
            return last[1]
        answer = self._touching(position, tool, spindle_angle)
        self._touching_last = (key, answer)
        return answer

    def _touching(self, position: np.ndarray, tool: int | None, spindle_angle: float) -> tuple[bool, bool]:
        if tool is None:
            return False, False
        tp = self._scenario.tool_probe
        if self.is_probe(tool):
            centre = self._kinematics.ball_centre(position, spindle_angle)
            radius = self._scenario.probe.ball_diameter / 2.0
            on_tool_probe = tp is not None and self._scene.subset({"tool_probe"}).sdf(centre) < radius
            return bool(self._scene.sdf(centre) < radius), bool(on_tool_probe)
        if tp is None:
            return False, False
        cutter = self._cutter(tool)
        grown = tool_probe_cylinder(tp, cutter.radius, cutter.length, self._kinematics.mount)
        return False, bool(grown.sdf(self._kinematics.cutter_tip(position, cutter)) < 0.0)

    def swivel_hits(self, start: np.ndarray, target: np.ndarray, tool: int | None, spindle_angle: float) -> bool:
        """Sample the swivel path (end pose included): does the ball/cutter end touch a solid?"""
        if tool is None:
            return False
        for k in range(1, SWIVEL_SAMPLES + 1):
            pose = start + (target - start) * (k / SWIVEL_SAMPLES)
            if self.is_probe(tool):
                hit = self.ball_in_solid(pose, spindle_angle)
            else:
                cutter = self._cutter(tool)
                end = (pose[:3] + self._kinematics.head_shift(pose)
                       - (cutter.length - cutter.radius) * self._kinematics.tool_axis(pose))
                hit = self._scene.subset(OBSTACLES).sdf(end) < cutter.radius
            if hit:
                return True
        return False

    # --- after the event -------------------------------------------------------------------
    def braking(self, feed_in_effect: float) -> float:
        """Overtravel behind the switch at this feed (mm/min), measuring-math §1.3."""
        cfg = self._scenario.machine
        return braking_distance(feed_in_effect, cfg.latency_s, cfg.decel, cfg.kv)

    def breaks_probe(self, tool: int | None, deflection: float) -> bool:
        """Pre-travel + braking beyond the permissible deflection (measuring-math §1.3)."""
        return self.is_probe(tool) and deflection > self._scenario.probe.max_deflection

    def positioning_stop(self, event: Event, feed_in_effect: float, length: float, tool: int | None) -> Stop:
        """A goto/jog: a switch brakes (and may break the probe), a crash stops at the contact."""
        if event.kind != "switch":
            return Stop(event.s_contact, None, False)
        s_stop = min(event.s_switch + self.braking(feed_in_effect), length)
        return Stop(s_stop, None, self.breaks_probe(tool, s_stop - event.s_contact))

    def measuring_stop(self, event: Event, feed_in_effect: float, distance: float, tool: int | None) -> Stop:
        """A measuring move that switched: latch = switch + latency path + noise, stop after braking."""
        s_stop = min(event.s_switch + self.braking(feed_in_effect), distance)
        s_latch = min(event.s_switch + latency_path(feed_in_effect, self._scenario.machine.latency_s), s_stop)
        sigma = self._scenario.probe.noise_sigma
        if sigma > 0.0 and self.is_probe(tool):
            s_latch += float(self._rng.normal(0.0, sigma))
        return Stop(s_stop, s_latch, self.breaks_probe(tool, s_stop - event.s_contact))

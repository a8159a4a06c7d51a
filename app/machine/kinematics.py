"""Kinematics of the simulated machine: axes, limits, swivel head, where the tool is.

Pure geometry of the scenario's machine, no state: for axis positions (MCS of the tool
reference point, in the order of ``axes``) where the tool axis points, where the true ball
centre and a cutter's tip are, whether a target lies within the limits, and the swivel
solutions. Positions are numpy arrays; ``as_dict`` gives the Protocol's ``{axis: value}``.

Decisions (where the spec leaves room):
- Rotary axes are positions with limits; the axis named in ``machine.rotary_table`` turns the
  workpiece (not the gauges) about the vertical table axis (``table_angle``; the contact model
  places the part, scene.workpiece_pose).
- Swivel head (scenario ``machine.kinematics``, model in scenario.SwivelHead): the head axes
  are rotary axes of the machine; the ball centre is A + R_head·(e(φ) − L·ẑ) and the tool axis
  R_head·ẑ. ``head_angles_for`` is CYCLE800-like: it solves the head angles for a tool axis
  (the solution within the limits with the smallest axis motion; the twist about the tool axis
  is not aligned). ``retract_target`` goes up along the tool axis (to the limits by default).
- Horizontal spindle (scenario ``machine.spindle_axis`` "Y"/"X"): the tool points along
  −spindle_axis (tool axis = +spindle_axis, tip = A − L·axis); the probe is mounted by
  ``physics.SPINDLE_MOUNTS`` (its own x, y, z = the a, o, p of G18 resp. G19), so the ball
  centre is A + M·(e(φ) − L·ẑ) and SPOS turns the eccentricity about the spindle axis. A swivel
  head needs the vertical spindle (the scenario refuses the combination).
- The probe's frame (``probe_rotation``): R_head·M·Rz(φ), probe frame -> MCS; the pre-travel of
  ``probe.pretravel_frame`` "probe" is read in it (contact.py).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from engine import alarms

from .axis_lines import Line, as_line, head_transform
from .axis_lines import head_angles_for as head_angle_candidates
from .physics import SPINDLE_MOUNTS, Z_UNIT, ball_centre, probe_rotation
from .protocol import Alarm
from .scenario import GEOMETRY_AXES, Scenario, SwivelHead, Tool

XYZ = slice(0, 3)          # the geometry axes in a position array
LIMIT_EPS = 1e-9           # mm/deg a target may lie beyond a limit (rounding)


class Kinematics:
    """The machine of one scenario: its axes, their limits, the probe and the swivel head."""

    def __init__(self, scenario: Scenario) -> None:
        self._scenario = scenario
        self.axes: tuple[str, ...] = scenario.axes
        self.limits: dict[str, tuple[float, float]] = scenario.limits()
        axis = scenario.machine.spindle_axis
        self.spindle_axis: str = axis
        self._mount: np.ndarray | None = None if axis == "Z" else SPINDLE_MOUNTS[axis]
        head = scenario.machine.kinematics
        # the head's axis lines (design.md §10.6): the truth moves the ball, the NC's (its machine
        # data, nominal until written) compute the tool axis, the swivel angles and the display
        self._true_lines: dict[str, Line] = {} if head is None else \
            {a: as_line(line) for a, line in head.true_lines().items()}
        self._nc_lines: dict[str, Line] = {} if head is None else \
            {a: as_line(line) for a, line in head.nominal_lines().items()}
        table = scenario.machine.rotary_table        # the part follows the table's true line (scene.py)
        self._nc_table: dict[str, Line] = {} if table is None else \
            {a: as_line(line) for a, line in table.nominal_lines().items()}

    # --- axis positions ------------------------------------------------------------------
    def index(self, axis: str) -> int:
        if axis not in self.axes:
            raise ValueError(f"unknown axis {axis!r}; the machine has {list(self.axes)}")
        return self.axes.index(axis)

    def as_dict(self, position: np.ndarray) -> dict[str, float]:
        return {a: float(v) for a, v in zip(self.axes, position, strict=True)}

    def start_position(self) -> np.ndarray:
        start = self._scenario.start_position()
        return np.array([start[a] for a in self.axes], dtype=float)

    @staticmethod
    def along(start: np.ndarray, d: np.ndarray, s: float) -> np.ndarray:
        """``start`` moved by ``s`` along the unit X/Y/Z direction ``d`` (rotary axes stay)."""
        out = start.copy()
        out[XYZ] += s * d
        return out

    def limit_alarm(self, target: np.ndarray) -> Alarm | None:
        """The software-limit alarm for the first axis of ``target`` outside its limits."""
        for axis, value in zip(self.axes, target, strict=True):
            lo, hi = self.limits[axis]
            if not lo - LIMIT_EPS <= value <= hi + LIMIT_EPS:
                return Alarm.of(alarms.SOFTWARE_LIMIT, f"Software limit switch {axis}: {value:.3f} outside "
                                f"[{lo:g}, {hi:g}]")
        return None

    def table_angle(self, position: np.ndarray) -> float | None:
        """The rotary table axis position (deg), None without a rotary table."""
        table = self._scenario.machine.rotary_table
        if table is None or table.axis not in self.axes:
            return None
        return float(position[self.axes.index(table.axis)])

    # --- the tool ------------------------------------------------------------------------
    def _head_transform(self, position: np.ndarray, lines: dict[str, Line]) -> tuple[np.ndarray, np.ndarray] | None:
        swivel = self._swivel()
        if swivel is None:
            return None
        head_axes = swivel.axes
        return head_transform(lines, head_axes, [position[self.axes.index(a)] for a in head_axes])

    def head(self, position: np.ndarray) -> np.ndarray | None:
        """The true R_head at the axis ``position`` (None without a swivel head)."""
        moved = self._head_transform(position, self._true_lines)
        return None if moved is None else moved[0]

    def head_shift(self, position: np.ndarray) -> np.ndarray:
        """Where the true head kinematics move the spindle nose from the X/Y/Z axis position (MCS)."""
        moved = self._head_transform(position, self._true_lines)
        return np.zeros(3) if moved is None else moved[1]

    # --- the control's kinematic data (machine data, design.md §10.6) ---------------------
    def nc_lines(self) -> dict[str, dict[str, Any]]:
        """The axis lines the NC holds (head and table), ``{axis: {"point", "direction", "unit"}}``."""
        units = {**{a: "head" for a in self._nc_lines}, **{a: "table" for a in self._nc_table}}
        return {a: {"point": [float(v) for v in p], "direction": [float(v) for v in d], "unit": units[a]}
                for a, (p, d) in {**self._nc_lines, **self._nc_table}.items()}

    def set_nc_lines(self, lines: dict) -> None:
        """Replace NC axis lines (axes not given keep theirs); ValueError names a bad axis."""
        known = set(self._nc_lines) | set(self._nc_table)
        unknown = set(lines) - known
        if unknown:
            raise ValueError(f"kinematics: {sorted(unknown)} has no kinematic data on this machine "
                             f"(its rotary units: {sorted(known)})")
        converted = {a: as_line(line) for a, line in lines.items()}
        self._nc_lines = {**self._nc_lines, **{a: v for a, v in converted.items() if a in self._nc_lines}}
        self._nc_table = {**self._nc_table, **{a: v for a, v in converted.items() if a in self._nc_table}}

    def nc_tool_axis(self, position: np.ndarray) -> np.ndarray:
        """The tool axis as the NC computes it from its kinematic data."""
        moved = self._head_transform(position, self._nc_lines)
        axis = Z_UNIT.copy() if self._mount is None else self._mount @ Z_UNIT
        return axis if moved is None else moved[0] @ axis

    def nc_head_shift(self, position: np.ndarray) -> np.ndarray:
        """Where the NC's kinematic data put the spindle nose relative to the X/Y/Z axis position."""
        moved = self._head_transform(position, self._nc_lines)
        return np.zeros(3) if moved is None else moved[1]

    @property
    def mount(self) -> np.ndarray:
        """Probe frame -> MCS at SPOS 0 without a head (physics.SPINDLE_MOUNTS of the spindle axis)."""
        return np.eye(3) if self._mount is None else self._mount.copy()

    def tool_axis(self, position: np.ndarray) -> np.ndarray:
        """MCS unit vector tip -> spindle: the spindle axis, turned by a swivel head."""
        head = self.head(position)
        axis = Z_UNIT.copy() if self._mount is None else self._mount @ Z_UNIT
        return axis if head is None else head @ axis

    def ball_centre(self, position: np.ndarray, spindle_angle: float) -> np.ndarray:
        """The true ball centre with the axes at ``position`` (physics.ball_centre, this probe and head)."""
        probe = self._scenario.probe
        return ball_centre(position[XYZ] + self.head_shift(position), probe.length, probe.eccentricity,
                           spindle_angle, self.head(position), self._mount)

    def probe_rotation(self, position: np.ndarray, spindle_angle: float) -> np.ndarray:
        """Probe frame -> MCS at ``position`` and SPOS ``spindle_angle`` (physics.probe_rotation)."""
        return probe_rotation(spindle_angle, self._mount, self.head(position))

    def cutter_tip(self, position: np.ndarray, cutter: Tool) -> np.ndarray:
        """Centre of the cutter's flat end: ``length`` below the spindle nose along the tool axis."""
        return position[XYZ] + self.head_shift(position) - cutter.length * self.tool_axis(position)

    # --- swivel head (scenario.SwivelHead) -----------------------------------------------
    def _swivel(self) -> SwivelHead | None:
        """The swivel head, None without one (or when its axes are not this machine's)."""
        head = self._scenario.machine.kinematics
        return head if head is not None and all(a in self.axes for a in head.axes) else None

    def has_swivel(self) -> bool:
        return self._swivel() is not None

    def head_axes(self) -> tuple[str, ...]:
        swivel = self._swivel()
        if swivel is None:
            raise ValueError("this machine has no swivel head")
        return tuple(swivel.axes)

    def head_turns(self, start: np.ndarray, target: np.ndarray) -> bool:
        if not self.has_swivel():
            return False
        return any(target[self.axes.index(a)] != start[self.axes.index(a)] for a in self.head_axes())

    def head_angles_for(self, tool_axis, position: np.ndarray) -> dict[str, float] | None:
        """The head angles within the limits that put the tool axis ∥ ``tool_axis``, nearest to
        ``position`` (the smallest axis motion); None when no solution lies within the limits."""
        head_axes = self.head_axes()
        current = [float(position[self.axes.index(a)]) for a in head_axes]
        best = None
        for cand in head_angle_candidates(self._nc_lines, head_axes, tool_axis, current):
            shifted: list[float] = []
            for axis, value, now in zip(head_axes, cand, current, strict=True):
                lo, hi = self.limits[axis]
                value = value + 360.0 * round((now - value) / 360.0)   # nearest turn to the current angle
                while value > hi + LIMIT_EPS:
                    value -= 360.0
                while value < lo - LIMIT_EPS:
                    value += 360.0
                if lo - LIMIT_EPS <= value <= hi + LIMIT_EPS:
                    shifted.append(value)
            if len(shifted) < len(head_axes):               # an axis has no turn within its limits
                continue
            cost = max(abs(v - now) for v, now in zip(shifted, current, strict=True))
            if best is None or cost < best[0] - 1e-9:      # ties: the first candidate
                best = (cost, shifted)
        if best is None:
            return None
        return {a: float(v) for a, v in zip(head_axes, best[1], strict=True)}

    def retract_target(self, position: np.ndarray, distance: float | None) -> dict[str, float]:
        """X/Y/Z ``distance`` up along the NC's tool axis (default: as far as the X/Y/Z limits allow)."""
        axis = self.nc_tool_axis(position)
        xyz = position[XYZ]
        s_max = math.inf
        for i, name in enumerate(GEOMETRY_AXES):
            lo, hi = self.limits[name]
            if axis[i] > 1e-12:
                s_max = min(s_max, (hi - xyz[i]) / axis[i])
            elif axis[i] < -1e-12:
                s_max = min(s_max, (lo - xyz[i]) / axis[i])
        s = max(0.0, s_max) if distance is None else distance
        target = xyz + s * axis
        return {a: float(v) for a, v in zip(GEOMETRY_AXES, target, strict=True)}

"""The simulated milling machine behind the Machine Protocol (design.md §5).

It implements ``Machine``, ``SwivelHead`` and ``SimulatorControl`` (protocol.py)
as a ``simulated.SimulatedControl`` (alarms, busy/abort, motion and the probe loop written once
for the milling machine and the lathe) over its own objects, each with its own decisions in its
module docstring:

- ``kinematics.Kinematics``: axes, limits, swivel head, where the tool is for given axes;
- ``contact.Contact``: the true scene, the first switch or crash along a path, latch, braking;
- ``motion.Motion``: the position, the one timed travel, busy/abort/stop, the continuous jog;
- ``nc_data.NcData``: the NC's copy of the named offsets and tool data the HMI writes.

The facade (simulated.py) holds what the NC holds besides (tool in the spindle and its offset
length, the active frame, override, spindle, alarms) and decides what a motion means for the
alarms; its decisions (broken stylus, collisions, limits, Reset, override) are in its docstring.
One lock (shared with the motion) guards that state; it is never held while sleeping.

Decisions of the milling machine (where the spec leaves room):
- A tool change (any tool, also the same T = new stylus) or ``load()`` repairs a broken probe.
- Active alarms do not lock the axes (the operator may jog away before pressing Reset).
- Rotary table: the part is re-placed when a positioning of the table axis ends (see
  ``_positioning``); a table turn that ends with the probe inside the part is a collision.
- Swivel head: a motion that turns the head is refused before it starts when any sampled pose
  touches a solid (PROBE_COLLISION; the probe does not measure while swivelling).
  ``swivel_to_wcs`` aligns the tool axis with the WCS infeed axis (kinematics.head_angles_for).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from engine import alarms

from .checks import finite
from .contact import Contact
from .kinematics import XYZ, Kinematics
from .nc_data import NcData
from .probe_signal import TOOL, WORKPIECE
from .protocol import Alarm, MachineStatus, MoveResult
from .scenario import GEOMETRY_AXES, Scenario
from .scene import Scene, outline, protection_data
from .series import cut_part, new_tools, worn
from .sim_trainer import setup_error as trainer_setup_error
from .simulated import SimulatedControl


class SimulatedMachine(SimulatedControl):
    """A 3-axis (+ rotary) milling machine with a 3D touch probe; the scenario is its truth."""

    _scenario: Scenario
    _kinematics: Kinematics
    _contact: Contact
    _nc: NcData

    # --- scenario (SimulatorControl) -----------------------------------------------------
    def _build(self, scenario: Scenario) -> tuple[Kinematics, Contact, NcData]:
        kinematics = Kinematics(scenario)
        contact = Contact(scenario, kinematics, kinematics.table_angle(kinematics.start_position()) or 0.0)
        return kinematics, contact, NcData(scenario.axes)

    def _install_extra(self, scenario: Scenario) -> None:
        self._offset_length = scenario.probe.nominal_length
        self._series = (scenario, new_tools(scenario), 0)      # (programmed part, cutters, parts made)

    def _cut_next_part(self, sigma: float) -> int:
        """The next part of the series (app.machine.series) cut with the NC's tool data."""
        base, sizes, made = self._series
        rng = np.random.default_rng([base.seed, made + 1])
        part = cut_part(base, sizes, self._nc.tools, made + 1, rng, sigma)
        contact = Contact(part, self._kinematics, self._contact.table_angle)
        self._scenario, self._contact = part, contact
        self._series = (base, worn(base, sizes), made + 1)
        return made + 1

    @property
    def scene(self) -> Scene:
        return self._contact.scene

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
                busy=self._motion.busy, alarms=self._alarms.shown(),
                tool_axis=(float(axis[0]), float(axis[1]), float(axis[2])),
                head_shift=(float(shift[0]), float(shift[1]), float(shift[2])),
                probe=self._probes.state(WORKPIECE, self._contact.is_probe(self._tool), on_probe),
                tool_probe=self._probes.state(TOOL, True, on_tool_probe) if self._probes.has(TOOL) else None)

    # --- settings without motion ---------------------------------------------------------
    def spindle_position(self, angle: float) -> None:
        """SPOS: the probe turns with the spindle, its eccentricity (measuring-math §1.7) and, with
        ``probe.pretravel_frame`` "probe", its pre-travel lobing (contact.py)."""
        with self._lock:
            self._spindle_angle = finite(angle, "angle") % 360.0
            self._spindle_speed = 0.0

    # --- rotary table and swivel head in motion ----------------------------------------------
    def _positioning(self, target: np.ndarray, feed: float | None) -> MoveResult:
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
                alarm = self._alarms.raise_(Alarm.of(alarms.PROBE_COLLISION, "Probe collision: the rotary table "
                                                     "turned the workpiece into the probe"))
                return MoveResult(result.mcs, False, alarm)
        return result

    def _place_part(self) -> bool:
        """Re-place the part when the rotary table axis moved; True when it did."""
        with self._lock:
            angle = self._kinematics.table_angle(self._motion.position)
            return angle is not None and self._contact.place_part(angle)

    def _swivel_collision(self, start: np.ndarray, target: np.ndarray) -> Alarm | None:
        """Sample the swivel path (end pose included): the ball/cutter end must stay clear."""
        self._check_limits(target)
        with self._lock:
            tool, angle = self._tool, self._spindle_angle
        if not self._contact.swivel_hits(start, target, tool, angle):
            return None
        return self._alarms.raise_(Alarm.of(alarms.PROBE_COLLISION, "Probe collision: the swivel "
                                            "would turn the tool into the workpiece"))

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

    def head_axes(self) -> tuple[str, ...]:
        return self._kinematics.head_axes()

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
            raise self._alarms.refusal(alarms.SOFTWARE_LIMIT, "Swivel: the tool axis cannot be reached within "
                                       "the limits of the head axes")
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

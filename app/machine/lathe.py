"""The simulated lathe behind the Machine Protocol: the facade (turning.md §10.2, turning §11).

It implements ``Machine`` and ``SimulatorControl`` (protocol.py) for a scenario with
``machine.kind: "lathe"`` (lathe_scenario) as a ``simulated.SimulatedControl`` (alarms,
busy/abort, motion and the probe loop written once for both machines) over its own objects:

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
  machine (simulated.py): a switch during positioning is 61302; a move ending beyond a limit
  is refused before it starts; a broken probe refuses motion until a tool change or a load.
- Overtravel of the tool probe (a turning tool pushed beyond its ``max_deflection``) is a
  collision (61302), not a broken stylus.
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

from dataclasses import dataclass

import numpy as np

from engine import alarms
from engine.checks import real

from .checks import finite
from .lathe_kinematics import LatheKinematics
from .lathe_scenario import LatheScenario
from .lathe_scene import LatheContact, lathe_outline, tool_outline
from .nc_data import NcData, _object
from .probe_signal import TOOL, WORKPIECE
from .protocol import MachineBusy, MachineStatus
from .scene import protection_data
from .simulated import SimulatedControl

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
        self._tools[t] = {"type": tool_type, "sl": sl, "length": real("length", data.get("length", 0.0)),
                          "radius": real("radius", data["radius"]),
                          "l1": real("l1", data.get("l1", 0.0)), "l2": real("l2", data.get("l2", 0.0)),
                          "wear": {k: real(f"wear.{k}", wear.get(k, 0.0)) for k in LATHE_WEAR_KEYS}}

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


class LatheMachine(SimulatedControl):
    """A 2-axis (optionally 3-axis) lathe with a turret, a workpiece probe and a tool probe."""

    kind = "lathe"
    TOOL_STORE = "turret"
    _scenario: LatheScenario
    _kinematics: LatheKinematics
    _contact: LatheContact
    _nc: LatheNcData

    # --- scenario (SimulatorControl) -------------------------------------------------------
    def _build(self, scenario: LatheScenario) -> tuple[LatheKinematics, LatheContact, LatheNcData]:
        if getattr(scenario, "kind", None) != "lathe":
            raise ValueError("the simulated lathe plays a scenario with machine.kind \"lathe\"; "
                             "start the HMI with a milling scenario for the milling machine")
        kinematics = LatheKinematics(scenario)
        return kinematics, LatheContact(scenario, kinematics), LatheNcData(scenario.axes)

    def _install_extra(self, scenario: LatheScenario) -> None:
        self._spindle_angle = float(scenario.spindle.angle) % 360.0
        self._worn: dict[int, tuple[float, float]] = {}
        self._parts = 0

    @property
    def diameter_programming(self) -> bool:
        return bool(self._scenario.machine.diameter_programming)

    @property
    def spos_capable(self) -> bool:
        return bool(self._scenario.machine.spos)

    # --- protection model (the start guard, issue 24 §1) ------------------------------------------
    def protection_model(self) -> dict:
        """The solids and axis limits the control protects (plain data, MCS, X a radius): the
        lathe's commissioned model of its work space is its scene at the spindle's angle now
        (the part, the chuck, the reference grooves, the tool probe)."""
        with self._lock:
            scene = self._contact.scene(self._spindle_angle)
            limits = {a: [float(lo), float(hi)] for a, (lo, hi) in self._kinematics.limits.items()}
        return {"bodies": protection_data(scene), "limits": limits}

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
                spindle_speed=self._spindle_speed, busy=self._motion.busy, alarms=self._alarms.shown(),
                plane="G18", tool_axis=(1.0, 0.0, 0.0), tool_lengths=(float(l1), float(l2)),
                diameter_programming=self.diameter_programming,
                probe=self._probes.state(WORKPIECE, self._contact.is_probe(self._tool), on_probe),
                tool_probe=self._probes.state(TOOL, True, on_tool_probe) if self._probes.has(TOOL) else None)

    # --- settings without motion ------------------------------------------------------------
    def spindle_position(self, angle: float) -> None:
        """SPOS of the main spindle: the clamped part turns with it (its eccentricity, run-out)."""
        angle = finite(angle, "angle") % 360.0
        if not self.spos_capable:
            raise self._alarms.refusal(alarms.NEEDS_SPOS, "The main spindle cannot be positioned (SPOS): "
                                       "it is not SPOS-capable")
        with self._lock:
            if self._motion.busy:
                raise MachineBusy("SPOS while the axes move")
            position = self._motion.position.copy()
            if self._contact.in_solid(position, self._tool, angle, self._worn_of(self._tool)):
                raise self._alarms.refusal(alarms.PROBE_COLLISION, "Probe collision: SPOS would turn the "
                                           "workpiece into the probe or the tool")
            self._spindle_angle = angle
            self._spindle_speed = 0.0

    # --- motion internals -------------------------------------------------------------------
    def _worn_of(self, tool: int | None) -> tuple[float, float]:
        return self._worn.get(tool, (0.0, 0.0)) if tool is not None else (0.0, 0.0)

    def _first_event(self, start: np.ndarray, d: np.ndarray, length: float):
        with self._lock:
            tool, angle = self._tool, self._spindle_angle
        return self._contact.first_event(start, d, length, tool, angle, self._worn_of(tool))

    def _target(self, target_mcs: dict[str, float]) -> np.ndarray:
        """A Y of 0 is accepted (and ignored) on a lathe without a Y axis."""
        if isinstance(target_mcs, dict) and "Y" in target_mcs and "Y" not in self.axes:
            if abs(finite(target_mcs["Y"], "target.Y")) > 1e-9:
                raise ValueError("unknown axis 'Y'; the lathe has no Y axis")
            target_mcs = {axis: value for axis, value in target_mcs.items() if axis != "Y"}
        return super()._target(target_mcs)

    # --- machined-part series (design.md §9.3, turning.md §11 closed loop) ----------------------
    def _cut_next_part(self, sigma: float) -> int:
        """Each profile item with ``machined_by`` cut with the tool's true L1 against the NC's."""
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


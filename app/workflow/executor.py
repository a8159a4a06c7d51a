"""Executes the engine's planned steps on the machine (data flow of design.md §2).

The plan speaks the measuring WCS (or MCS for tool tasks) and the NC's reference point (ball
centre / tool tip); the machine speaks MCS axis positions of the tool reference point; the
conversion between the two is ``engine.coords.ToolTip``, on a lathe ``engine.coords.LatheToolTip``
(``P = F − (L1·x̂ + L2·ẑ)``, handed in as ``tip``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from app.machine.protocol import Alarm, Machine, MachineAlarm
from engine.coords import GEOMETRY_AXES, LatheToolTip, ToolTip, head_shift_of, length_axis
from engine.frames import Frame
from engine.types import Latch, MoveStep, ProbeStep, RotaryStep, SpindleStep, Step


class MotionAborted(Exception):
    """The motion was stopped without an alarm (Reset)."""


@dataclass
class StepExecutor:
    machine: Machine
    wcs2bcs: Frame              # measuring chain, BCS = MCS (no kinematic transformation)
    tool_length: float          # the NC's offset length L1 of the active tool
    infeed_unit: np.ndarray     # the plane's infeed axis (G17: +Z): where L acts on a 3-axis machine
    tip: ToolTip | LatheToolTip | None = None    # None: the milling convention from the above
    _own_tip: bool = field(default=False, init=False)   # built here: rebuilt after a rotary axis moved

    def __post_init__(self) -> None:
        self._own_tip = self.tip is None
        if self.tip is None:
            self.tip = self._milling_tip()

    def _milling_tip(self) -> ToolTip:
        """tip = A + shift − L·axis with the control's tool axis and head shift as they are now."""
        status = self.machine.status()
        axis = length_axis(status.tool_axis, self.infeed_unit)
        return ToolTip(self.wcs2bcs, float(self.tool_length), axis, head_shift_of(status.head_shift))

    @property
    def tip_conversion(self) -> ToolTip | LatheToolTip:
        """``tip`` as set up: never None once ``__post_init__`` has run."""
        assert self.tip is not None, "StepExecutor.__post_init__ sets tip"
        return self.tip

    def axes_mcs(self) -> np.ndarray:
        mcs = self.machine.status().mcs
        return np.array([mcs[a] for a in GEOMETRY_AXES])

    def current(self, coords: str) -> np.ndarray:
        """Where the NC's tool reference is now, in ``coords``."""
        return self.tip_conversion.tip_in(self.axes_mcs(), coords)

    # --- execution ----------------------------------------------------------------------
    def _alarms(self) -> tuple[Alarm, ...]:
        """The alarms shown: the simulator tells them without building its whole status."""
        shown = getattr(type(self.machine), "shown_alarms", None)
        return tuple(shown(self.machine)) if callable(shown) else tuple(self.machine.status().alarms)

    def _raise_for(self, alarm: Alarm | None) -> None:
        if alarm is not None:
            raise MachineAlarm(alarm)
        raise MotionAborted("motion aborted")

    def run(self, step: Step) -> Latch | None:
        if isinstance(step, MoveStep):
            axes = self.tip_conversion.axes_for_tip(step.target, step.coords)
            result = self.machine.goto({"X": axes[0], "Y": axes[1], "Z": axes[2]}, step.feed)
            if not result.completed:
                self._raise_for(result.alarm)
            return None
        if isinstance(step, ProbeStep):
            alarms_before = len(self._alarms())
            probed = self.machine.probe(self.tip_conversion.direction_in_mcs(step.direction, step.coords),
                                        step.distance, step.feed)
            new_alarms = self._alarms()[alarms_before:]
            if new_alarms:  # broken probe, limit: the point ends, nothing is stored
                raise MachineAlarm(new_alarms[-1])
            if not probed.triggered:
                return Latch(triggered=False)
            assert probed.latched_mcs is not None, "every machine latches the axes on a trip"
            latched = np.array([probed.latched_mcs[a] for a in GEOMETRY_AXES])
            rec = self.tip_conversion.tip_in(latched, step.coords)
            return Latch(triggered=True, rec=rec, latched_mcs=latched)
        if isinstance(step, RotaryStep):
            target = dict(step.axes)
            if step.tip is not None:          # to the zero position: tip = A − L·spindle axis
                if any(abs(v) > 1e-12 for v in target.values()):
                    raise ValueError(f"RotaryStep.tip: only with every rotary axis at 0, got {target}")
                axes = np.asarray(step.tip, dtype=float) + float(self.tool_length) * np.asarray(self.infeed_unit)
                target.update({a: float(v) for a, v in zip(GEOMETRY_AXES, axes, strict=True)})
            result = self.machine.goto(target, None)
            if not result.completed:
                self._raise_for(result.alarm)
            if self._own_tip:                 # a head axis turned the NC's tool axis (design.md §10.6)
                self.tip = self._milling_tip()
            return None
        if isinstance(step, SpindleStep):
            if step.angle is not None:
                self.machine.spindle_position(step.angle)
            if step.speed is not None:
                self.machine.spindle_rotate(step.speed)
            return None
        raise TypeError(f"unknown step {step!r}")

"""Executes the engine's planned steps on the machine (data flow of design.md §2).

The plan speaks the measuring WCS (or MCS for tool tasks) and the NC's reference point (ball
centre / tool tip); the machine speaks MCS axis positions of the tool reference point. This
module is the only place where the two meet.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from app.machine.protocol import Alarm, Machine, MachineAlarm
from engine.frames import Frame
from engine.types import Latch, MoveStep, ProbeStep, SpindleStep, Step


class MotionAborted(Exception):
    """The motion was stopped without an alarm (Reset)."""


def length_axis(status, infeed_unit) -> np.ndarray:
    """Direction of the tool length L in MCS: the plane's infeed unit while the tool axis is +Z
    (3-axis convention, any plane); TRAORI-like, a swivelled head's actual tool axis (status)."""
    axis = getattr(status, "tool_axis", None)
    if axis is not None:
        axis = np.asarray(axis, dtype=float)
        if axis.shape == (3,) and float(np.linalg.norm(axis - np.array([0.0, 0.0, 1.0]))) >= 1e-12:
            return axis
    return np.asarray(infeed_unit, dtype=float)


@dataclass
class StepExecutor:
    machine: Machine
    wcs2bcs: Frame              # measuring chain, BCS = MCS (no kinematic transformation)
    tool_length: float          # the NC's offset length L1 of the active tool
    tool_axis_mcs: np.ndarray   # unit vector from tool tip to spindle (G17: +Z)

    def __post_init__(self) -> None:
        self.tool_axis_mcs = length_axis(self.machine.status(), self.tool_axis_mcs)

    # --- conversions (names carry the direction) ----------------------------------------
    def axes_mcs(self) -> np.ndarray:
        mcs = self.machine.status().mcs
        return np.array([mcs["X"], mcs["Y"], mcs["Z"]])

    def tip_in_mcs(self, axes_mcs) -> np.ndarray:
        return np.asarray(axes_mcs, dtype=float) - self.tool_length * self.tool_axis_mcs

    def axes_for_tip_mcs(self, tip_mcs) -> np.ndarray:
        return np.asarray(tip_mcs, dtype=float) + self.tool_length * self.tool_axis_mcs

    def tip_in_wcs(self, axes_mcs) -> np.ndarray:
        return self.wcs2bcs.parent2child(self.tip_in_mcs(axes_mcs))

    def current(self, coords: str) -> np.ndarray:
        axes = self.axes_mcs()
        return self.tip_in_wcs(axes) if coords == "WCS" else self.tip_in_mcs(axes)

    def axes_for_tip(self, target, coords: str) -> np.ndarray:
        tip_mcs = self.wcs2bcs.child2parent(target) if coords == "WCS" else np.asarray(target, float)
        return self.axes_for_tip_mcs(tip_mcs)

    def _dir_mcs(self, direction, coords: str) -> np.ndarray:
        d = np.asarray(direction, dtype=float)
        return self.wcs2bcs.dir_child2parent(d) if coords == "WCS" else d

    # --- execution ----------------------------------------------------------------------
    def _raise_for(self, alarm: Alarm | None) -> None:
        if alarm is not None:
            raise MachineAlarm(alarm)
        raise MotionAborted("motion aborted")

    def run(self, step: Step) -> Latch | None:
        if isinstance(step, MoveStep):
            axes = self.axes_for_tip(step.target, step.coords)
            result = self.machine.goto({"X": axes[0], "Y": axes[1], "Z": axes[2]}, step.feed)
            if not result.completed:
                self._raise_for(result.alarm)
            return None
        if isinstance(step, ProbeStep):
            alarms_before = len(self.machine.status().alarms)
            result = self.machine.probe(self._dir_mcs(step.direction, step.coords), step.distance, step.feed)
            new_alarms = self.machine.status().alarms[alarms_before:]
            if new_alarms:  # broken probe, limit: the point ends, nothing is stored
                raise MachineAlarm(new_alarms[-1])
            if not result.triggered:
                return Latch(triggered=False)
            latched = np.array([result.latched_mcs[a] for a in ("X", "Y", "Z")])
            rec = self.tip_in_wcs(latched) if step.coords == "WCS" else self.tip_in_mcs(latched)
            return Latch(triggered=True, rec=rec, latched_mcs=latched)
        if isinstance(step, SpindleStep):
            if step.angle is not None:
                self.machine.spindle_position(step.angle)
            if step.speed is not None:
                self.machine.spindle_rotate(step.speed)
            return None
        raise TypeError(f"unknown step {step!r}")

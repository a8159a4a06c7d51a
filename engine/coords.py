"""Tool tip <-> axis positions: where WCS coordinates and machine axes meet (design.md §3, §4).

MCS axis positions are those of the tool reference point (spindle nose); the NC's tool tip
(probe ball centre, cutter tip) is ``axes − L·tool_axis`` with L the NC's offset length, and
the WCS is below the BCS by the measuring chain: ``tip_mcs = wcs2bcs(p_wcs)`` (BCS = MCS, no
kinematic transformation). The tool length acts along the plane's infeed axis while the tool
axis is +Z (3-axis convention, any plane); TRAORI-like, along a swivelled head's actual tool
axis. Names carry the direction (``tip_in_wcs``, ``axes_for_tip``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from engine.frames import GEOMETRY_AXES, Frame
from engine.types import FloatArray

__all__ = ["GEOMETRY_AXES", "LatheToolTip", "ToolTip", "head_shift_of", "length_axis"]
_Z = np.array([0.0, 0.0, 1.0])


def length_axis(tool_axis: npt.ArrayLike | None, infeed_unit: npt.ArrayLike) -> FloatArray:
    """Direction of the tool length L in MCS: the plane's infeed unit while the tool axis is +Z;
    the machine's actual tool axis when a swivel head has turned it."""
    if tool_axis is not None:
        axis = np.asarray(tool_axis, dtype=float)
        if axis.shape == (3,) and float(np.linalg.norm(axis - _Z)) >= 1e-12:
            return axis
    return np.asarray(infeed_unit, dtype=float)


def head_shift_of(head_shift: npt.ArrayLike | None) -> FloatArray:
    """The status' ``head_shift`` as a (3,) vector, 0 when the controller reports none."""
    shift = np.zeros(3) if head_shift is None else np.asarray(head_shift, dtype=float)
    return shift if shift.shape == (3,) else np.zeros(3)


@dataclass(frozen=True)
class ToolTip:
    """The conversions of one measuring chain and one tool (``coords`` "WCS" or "MCS")."""

    wcs2bcs: Frame              # measuring chain, BCS = MCS
    tool_length: float          # the NC's offset length L1 of the active tool
    tool_axis_mcs: FloatArray   # unit vector from tool tip to spindle (``length_axis``)
    # spindle nose minus X/Y/Z axis position by the control's head kinematics (design.md §10.6):
    # a head whose axes do not pass through the tool reference point moves the nose as it turns
    head_shift: FloatArray = field(default_factory=lambda: np.zeros(3))

    def tip_in_mcs(self, axes_mcs: npt.ArrayLike) -> FloatArray:
        """tip = A + shift − L·axis (the TRAORI-like forward transform of the NC's kinematic data)."""
        return np.asarray(axes_mcs, dtype=float) + self.head_shift - self.tool_length * self.tool_axis_mcs

    def axes_for_tip_mcs(self, tip_mcs: npt.ArrayLike) -> FloatArray:
        return np.asarray(tip_mcs, dtype=float) - self.head_shift + self.tool_length * self.tool_axis_mcs

    def tip_in_wcs(self, axes_mcs: npt.ArrayLike) -> FloatArray:
        return self.wcs2bcs.parent2child(self.tip_in_mcs(axes_mcs))

    def tip_in(self, axes_mcs: npt.ArrayLike, coords: str) -> FloatArray:
        return self.tip_in_wcs(axes_mcs) if coords == "WCS" else self.tip_in_mcs(axes_mcs)

    def axes_for_tip(self, target: npt.ArrayLike, coords: str) -> FloatArray:
        tip_mcs = self.wcs2bcs.child2parent(target) if coords == "WCS" else np.asarray(target, float)
        return self.axes_for_tip_mcs(tip_mcs)

    def direction_in_mcs(self, direction: npt.ArrayLike, coords: str) -> FloatArray:
        d = np.asarray(direction, dtype=float)
        return self.wcs2bcs.dir_child2parent(d) if coords == "WCS" else d


@dataclass(frozen=True)
class LatheToolTip:
    """The same conversions on a lathe (turning.md §0.4): the NC's reference point (the tip P of a
    turning tool, the ball centre of the probe) is ``P = F − (L1·x̂ + L2·ẑ)`` with the NC's
    effective lengths L1 (acting in X) and L2 (in Z), F = the turret's axis positions (MCS, X a
    radius). Milling's ``tip = A − L·axis`` is ``ToolTip``; DIAMON is a display matter, every
    value here is a radius."""

    wcs2bcs: Frame
    l1: float
    l2: float

    @property
    def offset(self) -> FloatArray:
        return np.array([float(self.l1), 0.0, float(self.l2)])

    def tip_in_mcs(self, axes_mcs: npt.ArrayLike) -> FloatArray:
        return np.asarray(axes_mcs, dtype=float) - self.offset

    def axes_for_tip_mcs(self, tip_mcs: npt.ArrayLike) -> FloatArray:
        return np.asarray(tip_mcs, dtype=float) + self.offset

    def tip_in_wcs(self, axes_mcs: npt.ArrayLike) -> FloatArray:
        return self.wcs2bcs.parent2child(self.tip_in_mcs(axes_mcs))

    def tip_in(self, axes_mcs: npt.ArrayLike, coords: str) -> FloatArray:
        return self.tip_in_wcs(axes_mcs) if coords == "WCS" else self.tip_in_mcs(axes_mcs)

    def axes_for_tip(self, target: npt.ArrayLike, coords: str) -> FloatArray:
        tip_mcs = self.wcs2bcs.child2parent(target) if coords == "WCS" else np.asarray(target, float)
        return self.axes_for_tip_mcs(tip_mcs)

    def direction_in_mcs(self, direction: npt.ArrayLike, coords: str) -> FloatArray:
        d = np.asarray(direction, dtype=float)
        return self.wcs2bcs.dir_child2parent(d) if coords == "WCS" else d

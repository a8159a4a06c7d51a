"""Value objects shared by planning, evaluation and correction (the engine's contracts).

All coordinates are in the WCS that was active while measuring ("measuring WCS") unless a
name says otherwise. Vectors are numpy arrays of shape (3,) in X, Y, Z order.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


class MeasuringError(Exception):
    """A measurement that cannot give a result; ``alarm`` is the manual's alarm number."""

    def __init__(self, alarm: int, message: str):
        super().__init__(f"{alarm}: {message}")
        self.alarm = alarm
        self.message = message


# --- probe data -----------------------------------------------------------------------

TRIGGER_KEYS = ("X-", "X+", "Y-", "Y+", "Z-", "Z+")


@dataclass(frozen=True)
class ProbeRecord:
    """Workpiece probe data record _WP[k] (spec/jog-measuring.md §8.4, measuring-math §5).

    ``trigger[dir]`` = ball-centre coordinate at switching minus surface coordinate along
    that axis (ideal probe: t(-) = +r, t(+) = -r). ``skew`` = ball centre minus spindle axis
    (X, Y in machine axes at spindle 0°). ``length_to_tip`` is _CBIT[14].
    """

    number: int = 1
    ball_diameter: float = 4.0          # nominal DP6*2, from the tool data
    effective_diameter: float = 0.0     # _WP[k,0]; 0 = not calibrated
    trigger: dict[str, float] = field(default_factory=dict)  # keys of TRIGGER_KEYS
    skew: tuple[float, float] = (0.0, 0.0)
    length_to_tip: bool = False
    calibrated_radius: bool = False
    calibrated_length: bool = False
    calibration_feed: float | None = None
    calibration_override: float | None = None


# --- what one measuring point stores (P1..P4) ------------------------------------------

@dataclass(frozen=True)
class Touch:
    """One compensated probing: ball centre at switching, probing direction, surface point."""

    ball_centre: np.ndarray      # compensated ball-centre estimate c = rec + skew (WCS)
    direction: np.ndarray        # unit travel direction (WCS)
    surface: np.ndarray          # point-wise surface estimate s (measuring-math §5.3)
    latched_mcs: np.ndarray | None = None  # raw axis positions, for the log


@dataclass(frozen=True)
class EdgePoint:
    """A stored point of an edge/corner/plane task: one touch."""

    touch: Touch


@dataclass(frozen=True)
class CirclePoint:
    """A stored hole/spigot centre (4 touches, circle fit)."""

    center: np.ndarray           # WCS; infeed coordinate = measuring height
    diameter: float
    touches: tuple[Touch, ...] = ()


@dataclass(frozen=True)
class RectPoint:
    """A stored rectangular pocket/spigot centre (4 touches)."""

    center: np.ndarray
    length: float                # along the plane's 1st axis
    width: float                 # along the plane's 2nd axis
    touches: tuple[Touch, ...] = ()


StoredPoint = EdgePoint | CirclePoint | RectPoint


# --- what a task's evaluation hands to the correction ------------------------------------

@dataclass(frozen=True)
class FeatureFix:
    """The measured feature, expressed in the measuring WCS, and the DOFs it fixes.

    - ``position``: measured coordinates of the feature's reference point per axis name,
      only for the axes the task determines (e.g. {"X": 12.3} for set edge X).
    - ``angle``: measured angle (deg) of the feature about ``angle_axis`` relative to its
      reference axis, when the task measures a rotation in the plane.
    - ``normal``: measured unit normal of a plane (orient plane), pointing to +infeed side.
    """

    position: dict[str, float] = field(default_factory=dict)
    angle: float | None = None
    angle_axis: str | None = None
    reference_axis: str | None = None
    normal: np.ndarray | None = None
    # full 3D reference point in the measuring WCS (e.g. the surface point of set edge, the
    # corner/centre at measuring height); its undetermined components place the feature when
    # the target system is rotated against the measuring WCS (jog-measuring §2.5.1 [I] uses
    # the 3D contact point). ``position`` overrides its determined axes. None = zeros.
    point: np.ndarray | None = None


@dataclass(frozen=True)
class TaskResult:
    """``values``: the design.md §4 result keys (JSON-ready). ``fix``: input to correction."""

    task: str
    values: dict
    fix: FeatureFix


# --- the steps a point program yields (engine.plan); the workflow only executes them -----

@dataclass(frozen=True)
class MoveStep:
    """Intermediate positioning of the NC's tool reference (ball centre or tool tip).

    ``target`` in ``coords`` ("WCS" = measuring WCS, "MCS" = machine, tool tip); ``feed``
    None = rapid. ``monitored``: collision-monitored (a switch -> alarm 61302).
    """

    target: np.ndarray
    feed: float | None
    monitored: bool = True
    coords: str = "WCS"
    label: str = ""


@dataclass(frozen=True)
class ProbeStep:
    """Measuring move from the current position along ``direction`` over ``distance``."""

    direction: np.ndarray
    distance: float
    feed: float
    coords: str = "WCS"
    label: str = ""
    expected: float | None = None   # travel at which the nominal geometry switches (preview only)


@dataclass(frozen=True)
class SpindleStep:
    """SPOS to ``angle`` (deg) and/or spindle rotation at ``speed`` rpm (0 = stop)."""

    angle: float | None = None
    speed: float | None = None
    label: str = ""


Step = MoveStep | ProbeStep | SpindleStep


@dataclass(frozen=True)
class Latch:
    """What the workflow sends back for a ProbeStep (None is sent for other steps).

    ``rec``: the NC's tool reference (nominal ball centre, or tip with _CBIT[14]=1; tool tip
    for tool measuring) at the trigger, in the step's coords. ``latched_mcs``: raw axes.
    """

    triggered: bool
    rec: np.ndarray | None = None
    latched_mcs: np.ndarray | None = None

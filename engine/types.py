"""Value objects shared by planning, evaluation and correction (the engine's contracts).

All coordinates are in the WCS that was active while measuring ("measuring WCS") unless a
name says otherwise. Vectors are numpy arrays of shape (3,) in X, Y, Z order.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np
import numpy.typing as npt

from engine.alarms import AlarmDef

if TYPE_CHECKING:                      # engine.lobing needs nothing from here
    from _typeshed import DataclassInstance

    from engine.lobing import LobingMap

_Point = TypeVar("_Point", bound="DataclassInstance")   # a stored point (value dataclass)
_T = TypeVar("_T")

# the engine's vectors (shape (3,)), matrices and point lists: float64 arrays
FloatArray = npt.NDArray[np.float64]


class MeasuringError(Exception):
    """A measurement that cannot give a result: an alarm of ``engine.alarms`` and what happened.

    ``alarm`` is the manual's alarm number, ``definition`` the catalogue entry (text, remedy).
    ``result``: what was measured when a tolerance band refused the write (``_TSA``, ``_TDIF``,
    a form-error limit; design.md §10.2), else None.
    """

    def __init__(self, alarm: AlarmDef, message: str, result: dict[str, Any] | None = None):
        if not isinstance(alarm, AlarmDef):
            raise TypeError(f"MeasuringError needs an engine.alarms entry, got {alarm!r}")
        super().__init__(f"{alarm.number}: {message}")
        self.definition = alarm
        self.alarm = alarm.number
        self.message = message
        self.result = result


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
    # the direction-dependent trigger map of an n-direction ring calibration (engine.lobing,
    # design.md §9.8): every touch's surface point then follows it; None: the trigger values
    lobing: LobingMap | None = field(default=None, compare=False)


class NoProbeRecord(ValueError):
    """A workpiece probe's geometry was needed but no probe record was given (no probe in the
    spindle): the engine never assumes a ball (it once quietly took a 4 mm one)."""

    def __init__(self, what: str):
        super().__init__(f"{what}: no workpiece probe record (is a probe in the spindle?)")
        self.what = what


def probe_record(probe: ProbeRecord | None, what: str) -> ProbeRecord:
    """``probe`` itself; :class:`NoProbeRecord` naming ``what`` needed it when it is None."""
    if probe is None:
        raise NoProbeRecord(what)
    return probe


# --- what one measuring point stores (P1..P4) ------------------------------------------

@dataclass(frozen=True)
class Touch:
    """One compensated probing: ball centre at switching, probing direction, surface point."""

    ball_centre: FloatArray      # compensated ball-centre estimate c = rec + skew (WCS)
    direction: FloatArray        # unit travel direction (WCS)
    surface: FloatArray          # point-wise surface estimate s (measuring-math §5.3)
    latched_mcs: FloatArray | None = None  # raw axis positions, for the log


@dataclass(frozen=True)
class EdgePoint:
    """A stored point of an edge/corner/plane task: one touch."""

    touch: Touch


@dataclass(frozen=True)
class CirclePoint:
    """A stored hole/spigot centre (4 touches, circle fit)."""

    center: FloatArray           # WCS; infeed coordinate = measuring height
    diameter: float
    touches: tuple[Touch, ...] = ()


@dataclass(frozen=True)
class RectPoint:
    """A stored rectangular pocket/spigot centre (4 touches)."""

    center: FloatArray
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
    normal: FloatArray | None = None
    # full 3D reference point in the measuring WCS (e.g. the surface point of set edge, the
    # corner/centre at measuring height); its undetermined components place the feature when
    # the target system is rotated against the measuring WCS (jog-measuring §2.5.1 [I] uses
    # the 3D contact point). ``position`` overrides its determined axes. None = zeros.
    point: FloatArray | None = None


@dataclass(frozen=True)
class TaskResult:
    """``values``: the design.md §4 result keys (JSON-ready). ``fix``: input to correction."""

    task: str
    values: dict[str, Any]
    fix: FeatureFix


# --- the steps a point program yields (engine.plan); the workflow only executes them -----

@dataclass(frozen=True)
class MoveStep:
    """Intermediate positioning of the NC's tool reference (ball centre or tool tip).

    ``target`` in ``coords`` ("WCS" = measuring WCS, "MCS" = machine, tool tip); ``feed``
    None = rapid. ``monitored``: collision-monitored (a switch -> alarm 61302).
    """

    target: FloatArray
    feed: float | None
    monitored: bool = True
    coords: str = "WCS"
    label: str = ""


@dataclass(frozen=True)
class ProbeStep:
    """Measuring move from the current position along ``direction`` over ``distance``."""

    direction: FloatArray
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


@dataclass(frozen=True)
class RotaryStep:
    """Positioning of rotary axes (deg, rapid; design.md §10.6): a swivel head or a rotary table.
    A head axis turns the NC's tool axis, so the tip <-> axes conversion is taken anew after it.
    ``tip`` (MCS, only for a step to the zero position of every rotary axis): X/Y/Z move in the
    same motion so that the NC's tool reference ends there (L along the spindle axis)."""

    axes: tuple[tuple[str, float], ...]
    label: str = ""
    tip: FloatArray | None = None


Step = MoveStep | ProbeStep | SpindleStep | RotaryStep


@dataclass(frozen=True)
class Latch:
    """What the workflow sends back for a ProbeStep (None is sent for other steps).

    ``rec``: the NC's tool reference (nominal ball centre, or tip with _CBIT[14]=1; tool tip
    for tool measuring) at the trigger, in the step's coords. ``latched_mcs``: raw axes.
    """

    triggered: bool
    rec: FloatArray | None = None
    latched_mcs: FloatArray | None = None


if TYPE_CHECKING:
    class HitLatch(Latch):
        """A Latch that switched, as ``engine.plan_base.hit`` checks it: ``rec`` is set.

        For the type checker only (no such class at run time: the objects are Latch)."""

        rec: FloatArray


# --- moving a stored point between measuring systems ------------------------------------------

_POSITION_FIELDS = ("ball_centre", "surface", "center")


def translated(point: _Point, delta: npt.ArrayLike) -> _Point:
    """The stored point (EdgePoint, CirclePoint, RectPoint, Touch) shifted by ``delta`` (WCS mm).

    For points taken in measuring systems that differ by a translation only: positions move,
    directions and sizes stay, raw machine positions (``latched_mcs``) stay as latched."""
    shift = np.asarray(delta, dtype=float)
    changes: dict[str, Any] = {}
    for name in _POSITION_FIELDS:
        value = getattr(point, name, None)
        if value is not None:
            changes[name] = np.asarray(value, dtype=float) + shift
    touch = getattr(point, "touch", None)
    if isinstance(touch, Touch):
        changes["touch"] = translated(touch, shift)
    touches = getattr(point, "touches", None)
    if touches:
        changes["touches"] = tuple(translated(t, shift) for t in touches)
    return replace(point, **changes) if changes else point


def averaged(points: Iterable[_T]) -> _T:
    """The mean of the same point measured n times at the same place (_NMSP, measuring-math §1.4).

    Field by field: arrays and numbers are averaged, nested value objects and their tuples
    recursively, everything else (directions' labels, keys, flags) must agree. Directions stay
    unit vectors (the mean of equal directions)."""
    taken = list(points)
    if not taken:
        raise ValueError("averaged() needs at least one point")
    if len(taken) == 1:
        return taken[0]
    mean: _T = _mean_of(taken)
    return mean


def _mean_of(values: Sequence[Any]) -> Any:      # any field type of the stored points
    first = values[0]
    if first is None or isinstance(first, bool | str | int | float | np.floating | np.ndarray):
        return _mean_of_leaves(values)
    return _mean_of_nested(values)


def _mean_of_leaves(values: Sequence[Any]) -> Any:
    """None; labels, keys and flags that must agree; numbers and arrays averaged."""
    first = values[0]
    if first is None:
        return None
    if isinstance(first, bool) or isinstance(first, str | int) and not isinstance(first, float):
        if any(v != first for v in values):
            raise ValueError(f"measurements at one place disagree: {values!r}")
        return first
    if isinstance(first, float | np.floating):
        return float(np.mean(values))
    return np.mean(np.stack([np.asarray(v, dtype=float) for v in values]), axis=0)


def _mean_of_nested(values: Sequence[Any]) -> Any:
    """Tuples and lists (of touches), dicts and value objects, averaged field by field."""
    first = values[0]
    if isinstance(first, tuple | list):
        if any(len(v) != len(first) for v in values):
            raise ValueError("measurements at one place have different numbers of touches")
        return type(first)(_mean_of([v[i] for v in values]) for i in range(len(first)))
    if isinstance(first, dict):
        return {key: _mean_of([v[key] for v in values]) for key in first}
    if hasattr(first, "__dataclass_fields__"):
        return replace(first, **{name: _mean_of([getattr(v, name) for v in values])
                                 for name in first.__dataclass_fields__})
    raise TypeError(f"cannot average {type(first).__name__}")

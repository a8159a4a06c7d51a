"""Lathe conventions shared by the turning measuring cycles (spec/turning.md §0).

Coordinates. Every vector is a numpy array of shape (3,) in X, Y, Z order (engine.types); on
a lathe X is always a **radius** (distance from the turning centre), whatever DIAMON says,
Z runs along the spindle axis, Y exists only on some machines (turning.md §0.1, turning §11). DIAMON
is applied only where a cycle reads its inputs (``to_radius``) and writes its results
(``to_display``) (turning.md §0.3). Plane G18: ``_MA`` 1 = Z (abscissa), 2 = X (ordinate),
3 = Y (applicate) [L28910–L28915].

The NC reference point the steps move is the tool tip P (tool measuring, 972/982) or the ball
centre (workpiece probe, 973/974/994) as the NC computes it from the stored lengths:
``P = F − (L1·x̂ + L2·ẑ)`` (turning.md §0.4). ``coords`` of a step is "MCS" (machine-related
variants, the groove of 973) or "WCS" (workpiece-related variants, 973 surface, 974, 994).

This module holds: the SL table (turning §0.5), the lathe tool and probe data records (turning §0.4, turning §0.7),
the measuring feed (turning §0.8), the channel settings (turning §0.10), the probing helper ``LatheMotion``
(MM turning §1.1, turning §1.6; turning.md §0.8) and the raw stored points (``LatheTouch``, ``LathePoint``).
"""

from __future__ import annotations

import math
from collections.abc import Generator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any, TypeGuard

import numpy as np
import numpy.typing as npt

from engine import alarms
from engine.types import FloatArray, Latch, MeasuringError, MoveStep, ProbeStep, SpindleStep, Step

if TYPE_CHECKING:
    from engine.types import HitLatch

AXES = ("X", "Y", "Z")
_INDEX = {"X": 0, "Y": 1, "Z": 2}

# G18: _MA 1 = abscissa Z, 2 = ordinate X, 3 = applicate Y [L28910–L28915], turning.md §0.1
MA_AXIS = {1: "Z", 2: "X", 3: "Y"}
AXIS_MA = {v: k for k, v in MA_AXIS.items()}

TWO_TOUCH_RETRACT = 2.0     # mm back after the fast first touch, _CHBIT[17] [L26085–L26090]


# --- axes, directions ---------------------------------------------------------------------------

def index(axis: str) -> int:
    try:
        return _INDEX[axis]
    except KeyError:
        raise ValueError(f"axis must be X, Y or Z, got {axis!r}") from None


def unit(axis: str, sign: float = 1.0) -> FloatArray:
    e = np.zeros(3)
    e[index(axis)] = 1.0 if sign > 0 else -1.0
    return e


def key(axis: str, sign: float) -> str:
    """Travel-direction key "X-", "Z+" (turning.md §0.7: records are keyed by travel direction)."""
    return f"{axis}{'+' if sign > 0 else '-'}"


def parse_key(k: str) -> tuple[str, int]:
    if len(k) != 2 or k[0] not in _INDEX or k[1] not in "+-":
        raise ValueError(f"direction key must be like 'X-' or 'Z+', got {k!r}")
    return k[0], (1 if k[1] == "+" else -1)


def axis_of_ma(ma: int, allowed: tuple[int, ...] = (1, 2, 3)) -> str:
    """The axis of ``_MA`` (1 Z, 2 X, 3 Y); a value the cycle does not accept -> 61325 (turning §0.9)."""
    if isinstance(ma, bool) or ma not in allowed:
        raise MeasuringError(alarms.MEASURING_AXIS, f"_MA={ma!r} is not allowed here (allowed: {allowed})")
    return MA_AXIS[int(ma)]


def direction_of_md(md: int | None) -> int:
    """``_MD`` 0 = +, 1 = − (MM turning §0.1); any other value -> 61326 (turning.md §0.6, turning §12 Q22)."""
    if isinstance(md, bool) or md not in (0, 1):
        raise MeasuringError(alarms.MEASURING_DIRECTION, f"_MD={md!r} must be 0 (+) or 1 (-)")
    return 1 if md == 0 else -1


def other_plane_axis(axis: str) -> str:
    """The other G18 plane axis (Z <-> X); Y has none (CYCLE982 never moves Y, turning §0.1)."""
    return {"Z": "X", "X": "Z"}[axis]


# --- cutting-edge positions (turning.md §0.5) ---------------------------------------------------

# s(SL) = direction from the nose centre S to the theoretical tip P, (s_X, s_Z); P = S + R·s.
# SL 3 [M-derived: Z30 = (50+20)/2 − 5, L17888–L17892], 7/8 [M-derived: grooves L25658–L25666],
# the others from the ISO grid (turning.md §0.5 [I], turning §12 Q1).
SL_TIP: dict[int, tuple[int, int]] = {
    1: (+1, +1), 2: (+1, -1), 3: (-1, -1), 4: (-1, +1),
    5: (0, +1), 6: (+1, 0), 7: (0, -1), 8: (-1, 0), 9: (0, 0),
}


def sl_vector(sl: int, *, recode: bool = False) -> dict[str, int]:
    """{"X": s_X, "Y": 0, "Z": s_Z} of a cutting-edge position; unknown SL -> 61315.

    ``recode`` = _CHBIT[23] (CYCLE982): the SL mirrored at X, s_X := −s_X, i.e. SL 1<->4,
    2<->3, 6<->8 [L26297–L26299, L26560–L26564], turning.md §0.5 [I derived].
    """
    if isinstance(sl, bool) or sl not in SL_TIP:
        raise MeasuringError(alarms.CUTTING_EDGE_POSITION, f"cutting edge position SL={sl!r} is not 1..9")
    sx, sz = SL_TIP[int(sl)]
    if recode:
        sx = -sx
    return {"X": sx, "Y": 0, "Z": sz}


def leading_offset(d: int, s: int, radius: float) -> float:
    """(d − s)·R: the nose circle's leading point travelling d, relative to the tip (turning §0.5)."""
    return (d - s) * radius


def probe_directions(sl: int) -> tuple[str, ...]:
    """Travel directions a workpiece probe of SL 5..8 may use: every axis direction except −s,
    into its own stylus (turning.md §0.6 [I]); SL 7: −Z, ±X, ±Y; SL 8: −X, ±Z, ±Y."""
    if isinstance(sl, bool) or sl not in (5, 6, 7, 8):
        raise MeasuringError(alarms.CUTTING_EDGE_POSITION,
                             f"a workpiece probe needs SL 5..8, got SL={sl!r} (turning.md §0.6)")
    s = sl_vector(sl)
    out = []
    for axis in ("X", "Y", "Z"):
        for sign in (1, -1):
            if s[axis] != 0 and sign == -s[axis]:
                continue                                      # into the stylus
            out.append(key(axis, sign))
    return tuple(out)


def check_probe_direction(sl: int, k: str) -> None:
    """A direction into the stylus -> 61315 in every turning cycle (turning.md §0.6, turning §12 Q22)."""
    if k not in probe_directions(sl):
        raise MeasuringError(alarms.CUTTING_EDGE_POSITION,
                             f"a probe with SL {sl} cannot travel {k}: that is into its stylus")


# --- tool types (turning.md §0.4) -------------------------------------------------------------

def tool_family(tool_type: int) -> str | None:
    """'turning' (5xy: turning tools, calibration tool, lathe probe), 'mill' (1xy and 711–799
    [L17684–L17686]), 'drill' (2xy), else None (turning §0.4)."""
    try:
        t = int(tool_type)
    except (TypeError, ValueError):
        return None
    if 500 <= t <= 599:
        return "turning"
    if 100 <= t <= 199 or 711 <= t <= 799:
        return "mill"
    if 200 <= t <= 299:
        return "drill"
    return None


# --- DIAMON (turning.md §0.3) ----------------------------------------------------------------

def is_diameter(axis: str, diamon: bool, y_like_x: bool = False) -> bool:
    """Does a cycle read/write values on ``axis`` as diameters? X with DIAMON; Y with DIAMON and
    _CHBIT[19]=1 ("parametrised like X" [L26271–L26279]); never Z (turning.md §0.3)."""
    return bool(diamon) and (axis == "X" or (axis == "Y" and y_like_x))


def to_radius(value: float, axis: str, diamon: bool, y_like_x: bool = False) -> float:
    """Input: a diameter value on X with DIAMON becomes a radius (turning §0.3 engine rule)."""
    return float(value) / 2.0 if is_diameter(axis, diamon, y_like_x) else float(value)


def to_display(value: float, axis: str, diamon: bool, y_like_x: bool = False) -> float:
    """Output: a radius value on X with DIAMON becomes a diameter (turning §0.3 engine rule)."""
    return 2.0 * float(value) if is_diameter(axis, diamon, y_like_x) else float(value)


# --- measuring feed (turning.md §0.8, MM turning §1.2) ---------------------------------------------------

def measuring_feed(vms: float, fa: float) -> float:
    """_VMS > 0, else 150 mm/min for _FA ≤ 1 and 300 for _FA > 1 [L1274–L1280, L21070–L21076]."""
    if vms and vms > 0.0:
        return float(vms)
    return 150.0 if fa <= 1.0 else 300.0


def check_fa(fa: float | str) -> float:
    """_FA > 0, else 61308 "check measuring path 2a" (MM turning §1.1, turning.md §8)."""
    try:
        value = float(fa)
    except (TypeError, ValueError):
        raise MeasuringError(alarms.MEASURING_PATH, f"_FA={fa!r} is not a number") from None
    if not math.isfinite(value) or value <= 0.0:
        raise MeasuringError(alarms.MEASURING_PATH, f"_FA={fa!r} must be > 0")
    return value


def check_nmsp(nmsp: float) -> int:
    if isinstance(nmsp, bool) or int(nmsp) != nmsp or int(nmsp) < 1:
        raise ValueError(f"_NMSP must be an integer >= 1, got {nmsp!r}")
    return int(nmsp)


def ev_mv_numbers(evnum: int) -> tuple[int, int]:
    """(EV memory, MV memory) of _EVNUM (MM turning §3.3): ≤ 9999 both = _EVNUM; else MV·10000 + EV."""
    n = int(evnum)
    if n < 0:
        raise ValueError(f"_EVNUM must be >= 0, got {evnum!r}")
    if n <= 9999:
        return n, n
    return n % 10000, n // 10000


# --- tool data (turning.md §0.4) ----------------------------------------------------------------

LENGTH_OF_AXIS = {"X": "l1", "Z": "l2", "Y": "l3"}   # G18, types 5xy (and SD 42950=2): L1 X, L2 Z [L624–L632]


@dataclass(frozen=True)
class LatheTool:
    """Tool data of one T/D on a lathe (radius values, turning.md §0.4, turning §10.2).

    DP1 ``type``, DP2 ``sl``, DP3/DP4(/DP5) ``l1``/``l2``/``l3`` geometry, DP6 ``radius``,
    DP12/DP13/DP14 length wear, DP15 radius wear, DP21.. base lengths. Effective values are
    geometry + wear (+ base): what the NC uses for P = F − (L1·x̂ + L2·ẑ).
    """

    t: int = 0
    d: int = 1
    type: int = 500
    sl: int = 0
    l1: float = 0.0
    l2: float = 0.0
    l3: float = 0.0
    radius: float = 0.0
    wear_l1: float = 0.0
    wear_l2: float = 0.0
    wear_l3: float = 0.0
    wear_radius: float = 0.0
    base_l1: float = 0.0
    base_l2: float = 0.0
    base_l3: float = 0.0

    def effective(self, name: str) -> float:
        """Effective 'l1' / 'l2' / 'l3' (geometry + wear + base) or 'radius' (geometry + wear)."""
        if name == "radius":
            return self.radius + self.wear_radius
        return float(getattr(self, name) + getattr(self, f"wear_{name}") + getattr(self, f"base_{name}"))

    def length_on(self, axis: str) -> float:
        """The effective length acting along ``axis`` (X -> L1, Z -> L2, Y -> L3)."""
        return self.effective(LENGTH_OF_AXIS[axis])

    @property
    def family(self) -> str | None:
        return tool_family(self.type)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> LatheTool:
        """From the API's tool dict (turning §10.2): {"t", "d", "type", "sl", "l1", "l2", "radius",
        "wear": {"l1", "l2", "radius"}, optional "l3", "base": {"l1", "l2", "l3"}}."""
        wear = dict(data.get("wear") or {})
        base = dict(data.get("base") or {})
        return cls(t=int(data.get("t", 0)), d=int(data.get("d", data.get("edge", 1)) or 1),
                   type=int(data.get("type", 500)), sl=int(data.get("sl", 0) or 0),
                   l1=float(data.get("l1", 0.0)), l2=float(data.get("l2", 0.0)), l3=float(data.get("l3", 0.0)),
                   radius=float(data.get("radius", 0.0)),
                   wear_l1=float(wear.get("l1", 0.0)), wear_l2=float(wear.get("l2", 0.0)),
                   wear_l3=float(wear.get("l3", 0.0)), wear_radius=float(wear.get("radius", 0.0)),
                   base_l1=float(base.get("l1", 0.0)), base_l2=float(base.get("l2", 0.0)),
                   base_l3=float(base.get("l3", 0.0)))

    def to_dict(self) -> dict[str, Any]:
        return {"t": self.t, "d": self.d, "type": self.type, "sl": self.sl,
                "l1": self.l1, "l2": self.l2, "l3": self.l3, "radius": self.radius,
                "wear": {"l1": self.wear_l1, "l2": self.wear_l2, "l3": self.wear_l3,
                         "radius": self.wear_radius},
                "base": {"l1": self.base_l1, "l2": self.base_l2, "l3": self.base_l3}}


# --- tool probe record _TP / _TPW (turning.md §0.7) ---------------------------------------------

TP_KEYS = ("Z-", "Z+", "X-", "X+")    # _TP[k,0..3]: Z minus, Z plus, X minus, X plus [L25369–L25378]


def tp_to_list(record: Mapping[str, float]) -> list[float]:
    return [float(record.get(k, 0.0)) for k in TP_KEYS]


def tp_face(record: Mapping[str, float] | None, k: str) -> float:
    """The stored face (switching point) touched travelling ``k``; missing -> 61341."""
    if not record or k not in record:
        raise MeasuringError(alarms.NOT_CALIBRATED_IN_PLANE,
                             f"tool probe value {k} (_TP[k,{TP_KEYS.index(k) if k in TP_KEYS else '?'}]) is missing: "
                             "enter the rough values / calibrate the tool probe")
    return float(record[k])


def tp_centre(record: Mapping[str, float] | None, axis: str) -> float:
    """Probe centre on ``axis``: (_TP[a−] + _TP[a+])/2 (turning.md §0.7)."""
    return 0.5 * (tp_face(record, key(axis, -1)) + tp_face(record, key(axis, 1)))


# --- workpiece probe record _WP (turning.md §0.7) -----------------------------------------------

WP_TRIGGER_INDEX = {"Z-": 1, "Z+": 2, "X-": 3, "X+": 4, "Y-": 5, "Y+": 6}   # [L25511–L25521]
WP_SKEW_INDEX = {"Z": 7, "X": 8}


@dataclass(frozen=True)
class LatheProbe:
    """Workpiece probe data record _WP[k] in the turning layout (turning.md §0.7).

    ``trigger[dir]`` = ball-centre coordinate at switching (``rec + skew``) minus the surface
    coordinate along that axis, ideally +r travelling −, −r travelling + (MM turning §5.1); 0 = not
    calibrated (the manual's default). ``skew`` = true ball centre − the centre the NC computes
    from L1/L2 (_WP[k,7] Z, [k,8] X; turning §12 Q16). ``effective_diameter`` = _WP[k,0].
    """

    number: int = 1
    effective_diameter: float = 0.0
    trigger: Mapping[str, float] = field(default_factory=dict)
    skew: Mapping[str, float] = field(default_factory=dict)
    status: tuple[float, float] = (0.0, 0.0)

    def trigger_value(self, k: str) -> float:
        return float(self.trigger.get(k, 0.0))

    def skew_vector(self) -> FloatArray:
        """Skew as an XYZ vector (Y: none on a lathe probe)."""
        return np.array([float(self.skew.get("X", 0.0)), 0.0, float(self.skew.get("Z", 0.0))])

    def wp(self) -> list[float]:
        """The 11 values _WP[k,0..10]."""
        out = [0.0] * 11
        out[0] = float(self.effective_diameter)
        for k, i in WP_TRIGGER_INDEX.items():
            out[i] = self.trigger_value(k)
        for a, i in WP_SKEW_INDEX.items():
            out[i] = float(self.skew.get(a, 0.0))
        out[9], out[10] = float(self.status[0]), float(self.status[1])
        return out

    @classmethod
    def from_wp(cls, values: Sequence[float], number: int = 1) -> LatheProbe:
        vals = [float(v) for v in values] + [0.0] * max(0, 11 - len(values))
        return cls(number=number, effective_diameter=vals[0],
                   trigger={k: vals[i] for k, i in WP_TRIGGER_INDEX.items()},
                   skew={a: vals[i] for a, i in WP_SKEW_INDEX.items()},
                   status=(vals[9], vals[10]))

    def replace(self, *, trigger: Mapping[str, float] | None = None, skew: Mapping[str, float] | None = None,
                effective_diameter: float | None = None) -> LatheProbe:
        return LatheProbe(number=self.number,
                          effective_diameter=self.effective_diameter if effective_diameter is None
                          else float(effective_diameter),
                          trigger=dict(self.trigger if trigger is None else trigger),
                          skew=dict(self.skew if skew is None else skew), status=self.status)

    def to_dict(self) -> dict[str, Any]:
        """JSON view (the ``probe`` result key of turning §10.2): the _WP record and its named values."""
        return {"number": self.number, "wp": self.wp(), "effective_diameter": float(self.effective_diameter),
                "trigger": {k: self.trigger_value(k) for k in WP_TRIGGER_INDEX},
                "skew": {a: float(self.skew.get(a, 0.0)) for a in WP_SKEW_INDEX}}


# --- channel settings (turning.md §0.10) --------------------------------------------------------

CHBIT_DEFAULTS = {0: 0, 1: 1, 2: 1}    # [L26183–L26191]; every other bit defaults to 0


@dataclass(frozen=True)
class LatheContext:
    """What a turning cycle reads besides its call parameters.

    Settings: ``chbit`` (_CHBIT[n], defaults of turning §0.10), ``speed`` (_SPEED[0..3]), ``diamon``,
    ``has_y``, ``spos`` (SPOS-capable spindle, 61372), ``tool_length_type`` (SD 42950),
    ``plane`` (the active plane: G18, or G17/G19 for drills with SD 42950=0, turning §3.4),
    ``fine_offset`` (MD 18600 MM_FRAME_FINE_TRANS), ``scale_active`` / ``rotation_active`` (a
    scale factor ≠ 1 / a rotation in the active plane in the frame chain, 61310 / 61330, turning §0.2).
    Data: ``tool`` (the active T/D: the tool measured, the calibration tool, or the probe),
    ``tp`` / ``tpw`` (tool probe records _TP[k] / _TPW[k], dicts keyed "Z-", "Z+", "X-", "X+"),
    ``wp`` (workpiece probe records _WP[k]), ``kb`` (reference grooves _KB[k] as 7 values).
    Record counts are the lengths of those tuples (_CVAL, turning §0.7).
    """

    chbit: Mapping[int, int] = field(default_factory=dict)
    speed: tuple[float, float, float, float] = (50.0, 1000.0, 1000.0, 900.0)
    diamon: bool = False
    has_y: bool = False
    spos: bool = True
    tool_length_type: int = 2
    plane: str = "G18"
    fine_offset: bool = False
    scale_active: bool = False
    rotation_active: bool = False
    tool: LatheTool | None = None
    tp: tuple[Mapping[str, float], ...] = ()
    tpw: tuple[Mapping[str, float], ...] = ()
    wp: tuple[LatheProbe, ...] = ()
    kb: tuple[tuple[float, ...], ...] = ()

    def bit(self, n: int) -> bool:
        return bool(self.chbit.get(n, CHBIT_DEFAULTS.get(n, 0)))

    @property
    def attempts(self) -> int:
        """_CHBIT[15]: 0 -> up to 5 probing attempts, 1 -> one [L26252, L26520]."""
        return 1 if self.bit(15) else 5

    def with_tool(self, tool: LatheTool | None) -> LatheContext:
        return replace(self, tool=tool)


def check_frames(ctx: LatheContext, *, rotation_refused: bool = True) -> None:
    """Frames the turning cycles refuse (turning.md §0.2): a scale factor ≠ 1 -> 61310
    [L16429]; a rotation in the active plane -> 61330 (CYCLE972/973/974/994 [L27895–L27899])."""
    if ctx.scale_active:
        raise MeasuringError(alarms.SCALE_FACTOR, "a scale factor is active in the frame chain")
    if rotation_refused and ctx.rotation_active:
        raise MeasuringError(alarms.ROTATION_ACTIVE, "a coordinate rotation in the active plane is active")


def record_index(prnum: float | str, count: int, what: str) -> int:
    """k = _PRNUM − 1 (workpiece probes: the hundreds digit 0/1 = multi/mono is dropped,
    [L3611–L3625]); beyond the records -> 61313 (turning.md §0.7)."""
    try:
        n = int(prnum)
    except (TypeError, ValueError):
        raise MeasuringError(alarms.PROBE_NUMBER, f"_PRNUM={prnum!r} is not a number") from None
    k = (n % 100) - 1
    if n <= 0 or k < 0 or k >= count:
        raise MeasuringError(alarms.PROBE_NUMBER, f"_PRNUM={prnum!r}: no {what} record (there are {count})")
    return k


# --- raw stored points --------------------------------------------------------------------------

@dataclass(frozen=True)
class LatheTouch:
    """One probing place: the NC reference at each of the ``_NMSP`` switches.

    ``key`` = travel direction ("X-", "Z+", ...); ``recs`` in the point's coords (X radius);
    ``angle`` = SPOS angle during the touch (None: not positioned); ``role`` names the place
    ("P1".."P4", "bottom", "wall"...).
    """

    key: str
    recs: tuple[FloatArray, ...]
    angle: float | None = None
    role: str = ""
    latched_mcs: tuple[FloatArray | None, ...] = ()

    @property
    def axis(self) -> str:
        return self.key[0]

    @property
    def sign(self) -> int:
        return 1 if self.key[1] == "+" else -1

    @property
    def rec(self) -> FloatArray:
        """Mean latched position: _NMSP measurements at the same place are averaged (MM turning §1.4)."""
        mean: FloatArray = np.mean(np.stack([np.asarray(r, float) for r in self.recs]), axis=0)
        return mean

    @property
    def value(self) -> float:
        """Mean latched coordinate on the travel axis."""
        return float(self.rec[index(self.axis)])


@dataclass(frozen=True)
class LathePoint:
    """What a turning point program returns: its touches in probing order and its decisions."""

    cycle: int
    mvar: int
    coords: str
    start: FloatArray
    touches: tuple[LatheTouch, ...]
    info: Mapping[str, Any] = field(default_factory=dict)

    def by_role(self, role: str) -> tuple[LatheTouch, ...]:
        return tuple(t for t in self.touches if t.role == role)


LatheProgram = Generator[Step, Latch | None, LathePoint]    # a turning point program
LatheSteps = Generator[Step, Latch | None, None]            # a part of one (moves and touches)


# --- positioning and probing (MM turning §1.1, turning §1.6; turning.md §0.8) ---------------------------------

def _hit(latch: Latch | None) -> TypeGuard[HitLatch]:
    return latch is not None and latch.triggered and latch.rec is not None


class LatheMotion:
    """Tracks the NC reference position and builds the steps of a turning point program.

    ``offset`` = true ball centre − NC reference (the stored skew, turning §12 Q16): ``ball`` commands
    the reference so that the ball centre reaches a target (MM turning §5.2 "positioning q − e").
    Intermediate positioning [L26040–L26075]: _CHBIT[2]=1 monitored at _SPEED[1] (X/Z) or
    _SPEED[2] (a pure Y move), _CHBIT[2]=0 unmonitored at rapid (``feed`` None); returns from a
    measuring position at the positioning feed, or rapid with _CHBIT[16]=1 [L26255–L26258].
    """

    def __init__(self, start: npt.ArrayLike, ctx: LatheContext, coords: str,
                 offset: npt.ArrayLike | None = None) -> None:
        self.pos = np.asarray(start, dtype=float).copy()
        self.start = self.pos.copy()
        self.ctx = ctx
        self.coords = coords
        self.offset = np.zeros(3) if offset is None else np.asarray(offset, dtype=float)
        self.angle: float | None = None

    def _feed(self, delta: FloatArray) -> float | None:
        if not self.ctx.bit(2):
            return None
        pure_y = abs(delta[1]) > 0.0 and abs(delta[0]) == 0.0 and abs(delta[2]) == 0.0
        return float(self.ctx.speed[2] if pure_y else self.ctx.speed[1])

    def move(self, target: npt.ArrayLike, label: str = "", *, returning: bool = False) -> list[Step]:
        to = np.asarray(target, dtype=float)
        if np.allclose(to, self.pos, rtol=0.0, atol=1e-12):
            return []
        feed = self._feed(to - self.pos)
        if returning and self.ctx.bit(16) and self.ctx.bit(2):
            feed = None                              # _CHBIT[16]=1: return at rapid (% _SPEED[0])
        step = MoveStep(target=to.copy(), feed=feed, monitored=self.ctx.bit(2), coords=self.coords,
                        label=label)
        self.pos = to.copy()
        return [step]

    def move_axis(self, axis: str, value: float, label: str = "", *, ball: bool = False,
                  returning: bool = False) -> list[Step]:
        """Move one axis: the NC reference (``ball`` False) or the ball centre to ``value``."""
        target = self.pos.copy()
        j = index(axis)
        target[j] = float(value) - (self.offset[j] if ball else 0.0)
        return self.move(target, label, returning=returning)

    def ball_pos(self) -> FloatArray:
        ball: FloatArray = self.pos + self.offset
        return ball

    def spos(self, angle: float, label: str = "") -> list[Step]:
        """SPOS to ``angle`` (deg, 0..360) unless the spindle is already there."""
        a = float(angle) % 360.0
        if self.angle is not None and abs(self.angle - a) < 1e-12:
            return []
        self.angle = a
        return [SpindleStep(angle=a, label=label)]

    def probe(self, direction: FloatArray, distance: float, feed: float, label: str,
              expected: float | None = None) -> Generator[Step, Latch | None, HitLatch]:
        """One probing from the current position (MM turning §1.1): attempts per _CHBIT[15], then 61301;
        _CHBIT[17]=1 with a path > 2 mm: first touch at _SPEED[3], back 2 mm, second touch at the
        measuring feed [L26085–L26090]. Ends at the latched position (not returned)."""
        d = np.asarray(direction, dtype=float)
        origin = self.pos.copy()
        two = self.ctx.bit(17) and distance > 2.0          # _CHBIT[17] with a path > 2 mm
        first_feed = float(self.ctx.speed[3]) if two else float(feed)
        for attempt in range(self.ctx.attempts):
            if attempt:
                yield from self.move(origin, f"{label} retry {attempt + 1}", returning=True)
            latch = yield ProbeStep(direction=d.copy(), distance=float(distance), feed=first_feed,
                                    coords=self.coords, label=label, expected=expected)
            if not _hit(latch):
                self.pos = origin + float(distance) * d
                continue
            self.pos = np.asarray(latch.rec, dtype=float).copy()
            if two:
                yield from self.move(self.pos - TWO_TOUCH_RETRACT * d, f"{label} retract")
                fine = yield ProbeStep(direction=d.copy(), distance=2.0 * TWO_TOUCH_RETRACT, feed=float(feed),
                                       coords=self.coords, label=f"{label} fine", expected=TWO_TOUCH_RETRACT)
                if not _hit(fine):
                    self.pos = self.pos + 2.0 * TWO_TOUCH_RETRACT * d
                    continue
                latch = fine
                self.pos = np.asarray(latch.rec, dtype=float).copy()
            return latch
        raise MeasuringError(alarms.PROBE_NOT_SWITCHED, f"{label}: probe not switched within {distance:g} mm "
                                                         f"({self.ctx.attempts} attempt(s))")

    def touch(self, k: str, distance: float, feed: float, nmsp: int, label: str, *,
              expected: float | None = None, role: str = "") -> Generator[Step, Latch | None, LatheTouch]:
        """``_NMSP`` probings from the current position (the start of probing), each followed by
        the return to it (MM turning §1.1 step 4, turning §1.4); returns the touch with all latches."""
        axis, sign = parse_key(k)
        d = unit(axis, sign)
        origin = self.pos.copy()
        recs, mcs = [], []
        for i in range(nmsp):
            tag = label if nmsp == 1 else f"{label} #{i + 1}"
            latch = yield from self.probe(d, distance, feed, tag, expected)
            recs.append(np.asarray(latch.rec, dtype=float).copy())
            mcs.append(latch.latched_mcs)
            yield from self.move(origin, f"{tag} return", returning=True)
        return LatheTouch(key=k, recs=tuple(recs), angle=self.angle, role=role, latched_mcs=tuple(mcs))


def calibration_check(new: float, old: float, tzl: float, tsa: float, what: str) -> tuple[float, bool]:
    """MM measuring-math §3.5 calibration rule (turning.md §0.11): Δ = new − old; |Δ| > _TSA -> 61303 (nothing
    stored); |Δ| < _TZL -> the old value is kept; else the new one is stored. -> (value, stored)."""
    delta = float(new) - float(old)
    if abs(delta) > tsa:
        raise MeasuringError(alarms.SAFE_AREA, f"{what}: new {new:.4f} differs from {old:.4f} by {delta:+.4f} "
                                               f"> _TSA {tsa:g}; nothing stored")
    if abs(delta) < tzl:
        return float(old), False
    return float(new), True


def ovr_list() -> list[float]:
    return [0.0] * 32


def ovi_list() -> list[int]:
    return [0] * 14

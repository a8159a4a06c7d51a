"""CYCLE972/CYCLE982: tool probe calibration and turning-tool measuring (turning.md §1, turning §2).

Steps: coords "MCS" for the machine-related variants (_TP), "WCS" for the workpiece-related
ones (_TPW, SW 6.3); the NC reference is the tool tip P = F − (L1·x̂ + L2·ẑ) as the NC computes
it from the stored (effective) lengths; X radius. Y is never moved [L17529–L17534].

Geometry (turning.md §0.4, turning §0.5): nose centre S = P − R·s(SL); travelling d on an axis the nose
circle touches first with its leading point ``P + (d − s)·R``; a tool probe value f (_TP[k,i])
is the coordinate of the face at which the leading point stands when the probe switches
[L16612–L16614].

Public: ``Cycle982`` (call parameters), ``decode_982`` (_MVAR digits), ``check_982`` (tool and
variant checks), ``toolprobe_program`` / ``evaluate_toolprobe`` (calibration, turning §1),
``turning_tool_program`` / ``evaluate_turning_tool`` (L1/L2 of turning tools, turning §2),
``tool_checks`` (the turning §0.11 tool measuring rule), ``tool_ovr`` (the _OVR/_OVI lists).
Mills and drills on a lathe: engine.turning_mills.
"""

from __future__ import annotations

from collections.abc import Generator, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from engine import alarms
from engine.alarms import AlarmDef
from engine.turning import (
    LatheContext,
    LatheMotion,
    LathePoint,
    LatheProgram,
    LatheTool,
    LatheTouch,
    axis_of_ma,
    calibration_check,
    check_fa,
    check_frames,
    check_nmsp,
    direction_of_md,
    ev_mv_numbers,
    key,
    leading_offset,
    measuring_feed,
    other_plane_axis,
    ovi_list,
    ovr_list,
    record_index,
    sl_vector,
    tp_centre,
    tp_face,
    tp_to_list,
)
from engine.turning_offsets import tool_dict, tool_measure_update
from engine.types import FloatArray, Latch, MeasuringError, Step

_TOL = 1e-9


# --- call parameters and _MVAR (turning.md §1.1, turning §2.1, turning §3.1) ---------------------------------

@dataclass(frozen=True)
class Cycle982:
    """Parameters of CYCLE982 (``cycle`` = 972 for CYCLE972: _MVAR 0 and 1 only [L16519–L16530]).

    Defaults per MM turning §4.1 / turning.md §0.9. ``md`` only for the incremental variants; ``sta1``,
    ``cora`` only for mills.
    """

    mvar: int
    ma: int = 1
    md: int | None = None
    prnum: int = 1
    fa: float = 2.0
    vms: float = 0.0
    nmsp: int = 1
    tzl: float = 0.001
    tsa: float = 2.0
    tdif: float = 1.2
    evnum: int = 0
    sta1: float = 0.0
    cora: float = 0.0
    cycle: int = 982


@dataclass(frozen=True)
class Variant982:
    """_MVAR of CYCLE982, digit by digit (turning.md §3.1 [L17536–L17610, L30493–L30516])."""

    kind: str            # digit 1: "calibrate" (0), "measure" (1), "auto" (2)
    workpiece: bool      # digit 2: _TPW (1) instead of _TP (0)
    reversal: bool       # digit 3 (mills): second edge at 180° + _CORA
    d4: int              # digit 4 (mills): 0 length / auto, 1 radius, 2 length+radius, 3/4 upper edge
    radial: bool         # digit 5 (mills/drills): radial position (radius on Z)
    incremental: bool    # digit 6


def decode_982(mvar: object, cycle: int = 982) -> Variant982:
    """The digits of _MVAR; a value the cycle does not have -> 61307 (turning.md §3.1).

    Not incremental: 1xxxx2, 102xx1, 112xx1 [L17611–L17614]; calibration has no mill digits;
    CYCLE972 knows only 0 and 1 [L16519–L16530]. Tool-dependent rules: ``check_982``.
    """
    if isinstance(mvar, bool) or not isinstance(mvar, int | np.integer) or not 0 <= int(mvar) <= 999_999:
        raise MeasuringError(alarms.WRONG_VARIANT, f"_MVAR={mvar!r} is not a CYCLE{cycle} variant")
    n = int(mvar)
    if cycle == 972 and n not in (0, 1):
        raise MeasuringError(alarms.WRONG_VARIANT, f"CYCLE972 has _MVAR 0 and 1 only, got {n}")
    if cycle not in (972, 982):
        raise ValueError(f"cycle must be 972 or 982, got {cycle!r}")
    d = [(n // 10 ** i) % 10 for i in range(6)]
    if not _digits_982_valid(d):
        raise MeasuringError(alarms.WRONG_VARIANT, f"_MVAR={n} is not a CYCLE982 variant (turning.md §3.1)")
    return Variant982(kind=("calibrate", "measure", "auto")[d[0]], workpiece=d[1] == 1, reversal=d[2] == 1,
                      d4=d[3], radial=d[4] == 1, incremental=d[5] == 1)


def _digits_982_valid(d: list[int]) -> bool:
    """The digit rules of _MVAR (units first) [L17611–L17614]."""
    if not (d[0] in (0, 1, 2) and d[1] in (0, 1) and d[2] in (0, 1) and d[4] in (0, 1) and d[5] in (0, 1)):
        return False
    if d[0] == 0 and not d[2] == d[3] == d[4] == 0:          # calibration: no mill digits
        return False
    if d[0] == 1 and d[3] not in (0, 1, 2):
        return False
    if d[0] == 2 and not (d[3] in (0, 3, 4) and d[5] == 0):  # 1xxxx2 not incremental
        return False
    return not (d[5] == 1 and d[3] not in (0, 1))             # 102xx1, 112xx1 not incremental


def tool_probe_record(call: Cycle982, variant: Variant982, ctx: LatheContext) -> tuple[int, Mapping[str, float]]:
    """(k, _TP[k] or _TPW[k]) of _PRNUM; beyond the records -> 61313 (turning.md §0.7)."""
    records = ctx.tpw if variant.workpiece else ctx.tp
    k = record_index(call.prnum, len(records), "_TPW" if variant.workpiece else "_TP")
    return k, records[k]


def check_982(call: Cycle982, ctx: LatheContext) -> tuple[Variant982, LatheTool]:
    """The checks before any motion: variant (61307), frames (61310; 61330 for CYCLE972 only, as
    the alarm list names it), D active (61311), tool type (61314),
    _MA (61325), _FA (61308), _PRNUM (61313), _MD (61326), SL (61315), mill rules
    (turning.md §1.2, turning §2.2, turning §3.1, turning §8)."""
    variant = decode_982(call.mvar, call.cycle)
    check_frames(ctx, rotation_refused=call.cycle == 972)
    tool = ctx.tool
    if tool is None or tool.d <= 0:
        raise MeasuringError(alarms.NO_D_NUMBER, "no tool with a D number active")
    family = tool.family
    if family is None or (family != "turning" and (variant.kind == "calibrate" or call.cycle == 972)):
        raise MeasuringError(alarms.TOOL_TYPE, f"tool type {tool.type} cannot be used for this CYCLE{call.cycle} "
                                               "variant (turning.md §1.2, turning §2.2; mills and drills: CYCLE982)")
    drill_applicate = family == "drill" and ctx.tool_length_type == 0 and ctx.plane in ("G17", "G19")
    if not drill_applicate:
        axis_of_ma(call.ma, (1, 2))
    check_fa(call.fa)
    check_nmsp(call.nmsp)
    tool_probe_record(call, variant, ctx)
    if variant.incremental:
        direction_of_md(call.md)
    if variant.kind == "calibrate":
        if tool.sl != 3:
            raise MeasuringError(alarms.CUTTING_EDGE_POSITION,
                                 f"the calibration tool must have SL 3, got SL {tool.sl} [L16622–L16630]")
    elif family == "turning":
        _check_turning_tool(call, variant, tool)
    else:
        _check_mill_rules(call, variant, ctx, drill_applicate)
    return variant, tool


def _check_turning_tool(call: Cycle982, variant: Variant982, tool: LatheTool) -> None:
    """A turning tool: no mill digits in _MVAR, SL 1..8 (turning.md §1.2)."""
    if variant.reversal or variant.d4 or variant.radial:
        raise MeasuringError(alarms.WRONG_VARIANT, f"_MVAR={call.mvar}: mill digits with a turning tool")
    if tool.sl not in range(1, 9):
        raise MeasuringError(alarms.CUTTING_EDGE_POSITION, f"a turning tool needs SL 1..8, got {tool.sl}")


def _check_mill_rules(call: Cycle982, variant: Variant982, ctx: LatheContext, drill_applicate: bool) -> None:
    """Mills and drills on a lathe (turning.md §3.1, §3.4): SD 42950, _CHBIT[20] or SPOS, digit 4."""
    if drill_applicate:
        if variant.kind == "auto" or variant.d4 or variant.reversal:
            raise MeasuringError(alarms.WRONG_VARIANT, f"_MVAR={call.mvar}: a drill with SD 42950=0 is "
                                                       "measured with 1, 11 or 1000x1 only (turning.md §3.4)")
    elif ctx.tool_length_type != 2:
        raise MeasuringError(alarms.TOOL_TYPE, "mills and drills on a lathe need SD 42950 "
                                               "TOOL_LENGTH_TYPE=2 (turning.md §3.1)")
    if ctx.bit(20):
        if not (variant.kind == "measure" and not variant.reversal and variant.d4 in (0, 1)):
            raise MeasuringError(alarms.WRONG_VARIANT, f"_MVAR={call.mvar} is not allowed with _CHBIT[20]=1 "
                                                       "(only xxx0x1, [L17615–L17618])")
    elif not ctx.spos:
        raise MeasuringError(alarms.NEEDS_SPOS, "measuring a milling tool needs an SPOS-capable spindle")
    if variant.d4 in (3, 4):
        raise MeasuringError(alarms.WRONG_VARIANT, f"_MVAR={call.mvar}: the upper-edge variants (digit 4 = 3/4) "
                                                   "are not supported by this product")


# --- direction from the start position (turning.md §1.3, turning §2.3) -------------------------------

def travel_direction(p0: float, s: int, radius: float, f_minus: float, f_plus: float, fa: float,
                     allowed: tuple[int, ...] = (1, -1), what: str = "tool") -> int:
    """d on the measuring axis from the start (turning.md §1.3, turning §2.3 [I]): the tool's leading
    point must stand at least _FA outside the face it travels to; in between -> 61332; a side
    that ``allowed`` excludes (SL 1–4 travel only d = s) -> 61332 as well."""
    minus_ok = p0 + leading_offset(-1, s, radius) >= f_minus + fa - _TOL
    plus_ok = p0 + leading_offset(1, s, radius) <= f_plus - fa + _TOL
    if minus_ok and -1 in allowed:
        return -1
    if plus_ok and 1 in allowed:
        return 1
    if minus_ok or plus_ok:
        side = "above/right of" if minus_ok else "below/left of"
        raise MeasuringError(alarms.TOOL_TIP_POSITION,
                             f"the {what} starts {side} the probe, but its cutting edge position only allows "
                             f"travelling {'+' if 1 in allowed else '-'} on this axis (turning.md §2.3)")
    raise MeasuringError(alarms.TOOL_TIP_POSITION,
                         f"the {what} starts inside the forbidden band: its leading point must be at least "
                         f"_FA={fa:g} outside the probe faces {f_plus:g} / {f_minus:g} (turning.md §1.3)")


def _coords(variant: Variant982) -> str:
    return "WCS" if variant.workpiece else "MCS"


# --- tool probe calibration (turning.md §1) -----------------------------------------------------

def toolprobe_program(call: Cycle982, start: npt.ArrayLike, ctx: LatheContext, label: str = "P1") -> LatheProgram:
    """CYCLE982 _MVAR 0/10/100000/100010 (turning.md §1.3): one face per call.

    Non-incremental: direction from the start (turning §1.3); cross axis first: the calibration tool's
    nose centre S on the probe centre (tip = centre + s·R, e.g. Z30 = (50+20)/2 − 5 [L17888]);
    then the measuring axis to ``P = f − (d − s)·R − d·_FA``; probe over 2·_FA; back to the
    start of probing (the tool ends _FA in front of the face [L16706–L16708]).
    Incremental: probe from the current position in _MA/_MD; back to the start [L19414–L19416].
    Returns a LathePoint with one touch (key = travel direction).
    """
    variant, tool = check_982(call, ctx)
    if variant.kind != "calibrate":
        raise ValueError(f"_MVAR={call.mvar} is not a calibration")
    _, record = tool_probe_record(call, variant, ctx)
    a = axis_of_ma(call.ma, (1, 2))
    b = other_plane_axis(a)
    s = sl_vector(tool.sl, recode=ctx.bit(23))
    r = tool.effective("radius")
    fa = check_fa(call.fa)
    feed = measuring_feed(call.vms, fa)
    m = LatheMotion(start, ctx, _coords(variant))
    p0 = np.asarray(start, float)
    if variant.incremental:
        d = direction_of_md(call.md)
        touch = yield from m.touch(key(a, d), 2.0 * fa, feed, call.nmsp, f"{label} {key(a, d)}", role=label)
        yield from m.move(m.start, f"{label} back to the start", returning=True)
    else:
        f_minus, f_plus = tp_face(record, key(a, -1)), tp_face(record, key(a, 1))
        d = travel_direction(float(p0["XYZ".index(a)]), s[a], r, f_minus, f_plus, fa, what="calibration tool")
        f = f_minus if d < 0 else f_plus
        yield from m.move_axis(b, tp_centre(record, b) + s[b] * r, f"{label} nose centre on the probe centre")
        yield from m.move_axis(a, f - leading_offset(d, s[a], r) - d * fa, f"{label} start of probing")
        touch = yield from m.touch(key(a, d), 2.0 * fa, feed, call.nmsp, f"{label} {key(a, d)}",
                                   expected=fa, role=label)
    return LathePoint(cycle=call.cycle, mvar=call.mvar, coords=m.coords, start=p0.copy(), touches=(touch,),
                      info={"direction": key(a, d), "radius": r, "sl": s})


@dataclass(frozen=True)
class ToolProbeResult:
    """Calibration result: the new record (_TP[k]/_TPW[k]), the face calibrated, its value and
    difference, whether it was stored (|Δ| ≥ _TZL), the turning §10.2 values and _OVR/_OVI."""

    record: dict[str, Any]
    key: str
    trigger: float
    difference: float
    stored: bool
    values: dict[str, Any]
    ovr: tuple[float, ...]
    ovi: tuple[int, ...]


def evaluate_toolprobe(call: Cycle982, point: LathePoint, ctx: LatheContext) -> ToolProbeResult:
    """f_new = rec + (d − s)·R (turning.md §1.4; SL 3: travel − f = rec, travel + f = rec + 2R);
    MM measuring-math §3.5 calibration rule (turning.md §0.11), none for the incremental variants [L19389–L19399]."""
    variant, tool = check_982(call, ctx)
    k, record = tool_probe_record(call, variant, ctx)
    (touch,) = point.touches
    s = sl_vector(tool.sl, recode=ctx.bit(23))
    r = tool.effective("radius")
    f_new = touch.value + leading_offset(touch.sign, s[touch.axis], r)          # turning.md §1.4
    old = float(record.get(touch.key, 0.0))
    if variant.incremental:
        value, stored = f_new, True
    else:
        value, stored = calibration_check(f_new, old, call.tzl, call.tsa, f"tool probe {touch.key}")
    new_record = {kk: float(v) for kk, v in record.items()}
    new_record[touch.key] = value
    difference = f_new - old
    ovr, ovi = ovr_list(), ovi_list()
    slots = {"Z-": 8, "Z+": 10, "X-": 12, "X+": 14}               # [L17628–L17643], turning.md §1.4
    for kk, i in slots.items():
        ovr[i] = float(new_record.get(kk, 0.0))
    ovr[slots[touch.key]] = f_new
    ovr[slots[touch.key] + 1] = difference
    ovr[27], ovr[28] = float(call.tzl), float(call.tsa)
    ovi[2], ovi[3], ovi[5] = call.cycle, call.mvar, int(call.prnum)
    values = {"tool_probe": {"number": k + 1, "reference": "workpiece" if variant.workpiece else "machine",
                             "record": tp_to_list(new_record), "faces": dict(new_record)},
              "trigger": {touch.key: f_new}, "difference": {touch.key: difference}, "stored": stored}
    return ToolProbeResult(record=new_record, key=touch.key, trigger=f_new, difference=difference, stored=stored,
                           values=values, ovr=tuple(ovr), ovi=tuple(ovi))


# --- turning tools L1/L2 (turning.md §2) -------------------------------------------------------

def _tip_axis(s: Mapping[str, int]) -> str:
    return "X" if s["X"] != 0 else "Z"


def _allowed(s: Mapping[str, int], axis: str) -> tuple[int, ...]:
    """SL 1–4 and the tip axis of SL 5–8 travel only d = s; the other axis of SL 5–8 either way
    (turning.md §2.3 [I])."""
    return (s[axis],) if s[axis] != 0 else (1, -1)


@dataclass(frozen=True)
class _ToolMoves:
    """The moves of a turning tool (SL ``sl``, cutting radius ``r``) against the tool probe ``record``."""

    m: LatheMotion
    record: Mapping[str, float]
    s: Mapping[str, int]
    r: float
    fa: float
    feed: float
    nmsp: int
    p0: FloatArray
    sl: int

    def measure(self, a: str, d: int, tag: str) -> Generator[Step, Latch | None, LatheTouch]:
        """Nose centre on the probe centre in the other axis, then probe ``a`` travelling ``d``."""
        m, record, s, r, fa = self.m, self.record, self.s, self.r, self.fa
        f = tp_face(record, key(a, d))
        b = other_plane_axis(a)
        yield from m.move_axis(b, tp_centre(record, b) + s[b] * r, f"{tag} nose centre on the probe centre")
        yield from m.move_axis(a, f - leading_offset(d, s[a], r) - d * fa, f"{tag} start of probing")
        touch = yield from m.touch(key(a, d), 2.0 * fa, self.feed, self.nmsp, f"{tag} {key(a, d)}", expected=fa,
                                   role=tag)
        return touch

    def direction(self, a: str) -> int:
        j = "XYZ".index(a)
        return travel_direction(float(self.p0[j]), self.s[a], self.r, tp_face(self.record, key(a, -1)),
                                tp_face(self.record, key(a, 1)), self.fa, _allowed(self.s, a),
                                what=f"tool (SL {self.sl})")

    def incremental(self, a: str, d: int, label: str) -> Generator[Step, Latch | None, LatheTouch]:
        """Probe in _MA/_MD from the current position, back to the start."""
        if d not in _allowed(self.s, a):
            raise MeasuringError(alarms.TOOL_TIP_POSITION, f"SL {self.sl} cannot be measured travelling {key(a, d)}")
        touch = yield from self.m.touch(key(a, d), 2.0 * self.fa, self.feed, self.nmsp, f"{label} {key(a, d)}",
                                        role=label)
        yield from self.m.move(self.m.start, f"{label} back to the start", returning=True)
        return touch

    def both_lengths(self) -> Generator[Step, Latch | None, list[LatheTouch]]:
        """SL 1–4, automatic: (a)..(g) of turning_tool_program's docstring, L2 then L1."""
        m, record, s, r, fa, p0 = self.m, self.record, self.s, self.r, self.fa, self.p0
        dz, dx = self.direction("Z"), self.direction("X")
        fz, fx = tp_face(record, key("Z", dz)), tp_face(record, key("X", dx))
        yield from m.move_axis("X", tp_centre(record, "X") + s["X"] * r, "P1 (a) nose centre on the X centre")
        yield from m.move_axis("Z", fz - leading_offset(dz, s["Z"], r) - dz * fa, "P1 (b) start of probing")
        touches = [(yield from m.touch(key("Z", dz), 2.0 * fa, self.feed, self.nmsp, f"P1 {key('Z', dz)}",
                                       expected=fa, role="P1"))]
        yield from m.move_axis("X", fx - leading_offset(dx, s["X"], r) - dx * fa, "P2 (d) start of probing")
        yield from m.move_axis("Z", tp_centre(record, "Z") + s["Z"] * r, "P2 (e) nose centre on the Z centre")
        touches.append((yield from m.touch(key("X", dx), 2.0 * fa, self.feed, self.nmsp, f"P2 {key('X', dx)}",
                                           expected=fa, role="P2")))
        yield from m.move_axis("Z", float(p0[2]), "(g) back to the start Z", returning=True)
        yield from m.move_axis("X", float(p0[0]), "(g) back to the start X", returning=True)
        return touches


def turning_tool_program(call: Cycle982, start: npt.ArrayLike, ctx: LatheContext, label: str = "P1") -> LatheProgram:
    """CYCLE982 _MVAR 1/11 (one length), 2/12 (automatic), 100001/100011 (incremental) for a
    turning tool SL 1..8 (turning.md §2.3).

    1/11: cross axis first (S on the probe centre, R = 0: the tip [L16976–L16978]), then the
    measuring axis to ``f − (d − s)·R − d·_FA``, probe 2·_FA, back to the start of probing.
    2/12, SL 1–4: (a) X: S_x = x_c; (b) Z to the start of probing; (c) probe Z (L2), back;
    (d) X to its start of probing; (e) Z: S_z = z_c; (f) probe X (L1), back; (g) Z, then X back
    to the start [L18726–L18740]. SL 5–8: the tip axis only, then back to the start.
    Incremental: probe in _MA/_MD from the current position, back to the start [L19729–L19731].
    """
    variant, tool = check_982(call, ctx)
    if tool.family != "turning" or variant.kind == "calibrate":
        raise ValueError("turning_tool_program measures turning tools (use engine.turning_mills for mills)")
    _, record = tool_probe_record(call, variant, ctx)
    s = sl_vector(tool.sl, recode=ctx.bit(23))
    r = tool.effective("radius")
    fa = check_fa(call.fa)
    feed = measuring_feed(call.vms, fa)
    p0 = np.asarray(start, float)
    m = LatheMotion(p0, ctx, _coords(variant))
    moves = _ToolMoves(m, record, s, r, fa, feed, call.nmsp, p0, tool.sl)
    touches: list[LatheTouch] = []
    if variant.incremental:
        touches.append((yield from moves.incremental(axis_of_ma(call.ma, (1, 2)), direction_of_md(call.md), label)))
    elif variant.kind == "measure":
        a = axis_of_ma(call.ma, (1, 2))
        touches.append((yield from moves.measure(a, moves.direction(a), label)))
    elif s["X"] != 0 and s["Z"] != 0:                                   # automatic, SL 1–4
        touches += yield from moves.both_lengths()
    else:                                                               # automatic, SL 5–8: tip axis
        a = _tip_axis(s)
        touches.append((yield from moves.measure(a, moves.direction(a), "P1")))
        yield from m.move_axis(a, float(p0["XYZ".index(a)]), "back to the start", returning=True)
        yield from m.move(p0, "back to the start", returning=True)
    return LathePoint(cycle=call.cycle, mvar=call.mvar, coords=m.coords, start=p0.copy(), touches=tuple(touches),
                      info={"radius": r, "sl": s})


@dataclass(frozen=True)
class ToolResult:
    """Tool measuring result (turning.md §2.4, turning §3.2).

    ``measured`` {"L1"/"L2"/"R": {"actual", "difference"}} (effective values, Δ = actual − stored
    after EV, turning §12 Q15); ``written`` the quantities written; ``alarm`` a 62306 warning (no write
    for that quantity); ``before``/``after`` the tool dicts; ``values`` the turning §10.2 result keys.
    """

    measured: dict[str, Any]
    written: tuple[str, ...]
    alarm: AlarmDef | None
    before: dict[str, Any]
    after: dict[str, Any]
    values: dict[str, Any]
    ovr: tuple[float, ...]
    ovi: tuple[int, ...]
    notes: tuple[str, ...] = field(default_factory=tuple)


QUANTITY_NAME = {"l1": "L1", "l2": "L2", "radius": "R"}


def tool_checks(delta: float, call: Cycle982, what: str) -> tuple[bool, AlarmDef | None]:
    """MM measuring-math §3.5 tool measuring rule (turning.md §0.11): |Δ| > _TSA -> 61303 (raised);
    |Δ| ≥ _TDIF -> 62306, no correction; |Δ| < _TZL -> no correction. -> (write, warning)."""
    if abs(delta) > call.tsa:
        raise MeasuringError(alarms.SAFE_AREA, f"{what}: difference {delta:+.4f} > _TSA {call.tsa:g}; nothing written")
    if abs(delta) >= call.tdif:
        return False, alarms.DIMENSION_DIFFERENCE
    if abs(delta) < call.tzl:
        return False, None
    return True, None


def _writable(call: Cycle982, variant: Variant982, deltas: dict[str, float]) -> tuple[list[str], list[AlarmDef]]:
    """The quantities the tool measuring rule lets write, and its warnings: every _TSA check
    before anything is written; incremental measuring writes without the rule."""
    warnings: list[AlarmDef] = []
    write = []
    for q, delta in deltas.items():
        if variant.incremental:
            write.append(q)
            continue
        ok, warning = tool_checks(delta, call, QUANTITY_NAME[q])
        if ok:
            write.append(q)
        if warning:
            warnings.append(warning)
    return write, warnings


def _written(tool: LatheTool, write: list[str], measured: dict[str, float], ctx: LatheContext,
             variant: Variant982) -> tuple[dict[str, Any], dict[str, Any]]:
    """(tool before, tool after) the writes per _CHBIT[3], one quantity after the other."""
    current = tool
    before = after = None
    for q in write:
        b, a = tool_measure_update(current, q, measured[q], remeasure=ctx.bit(3), incremental=variant.incremental)
        before = before or b
        after = a
        current = LatheTool.from_dict(a)
    before = before or tool_dict(tool)
    after = after or tool_dict(tool)
    after["sl"], after["type"], after["t"], after["d"] = tool.sl, tool.type, tool.t, tool.d
    return before, after


def finish_tool(call: Cycle982, variant: Variant982, tool: LatheTool, measured_values: dict[str, float],
                ev: float, ctx: LatheContext) -> ToolResult:
    """Checks and writing for measured effective values {"l1"/"l2"/"radius": value} (turning.md
    turning §2.4, turning §0.11): EV (only _EVNUM > 0, not incremental: subtracted, added with _CHBIT[5]=1),
    the tool measuring rule (none for incremental), write per _CHBIT[3] (incremental: geometry)."""
    use_ev = call.evnum > 0 and not variant.incremental
    ev_value = float(ev) if use_ev else 0.0
    measured, deltas = {}, {}
    for q, value in measured_values.items():
        actual = value + ev_value if ctx.bit(5) else value - ev_value
        measured[q] = actual
        deltas[q] = actual - tool.effective(q)
    write, warnings = _writable(call, variant, deltas)
    before, after = _written(tool, write, measured, ctx, variant)
    ovr, ovi = tool_ovr(call, {QUANTITY_NAME[q]: (measured[q], deltas[q]) for q in measured}, ev_value, tool)
    ovi[9] = warnings[0].number if warnings else 0
    result_measured = {QUANTITY_NAME[q]: {"actual": measured[q], "difference": deltas[q]} for q in measured}
    values: dict[str, Any] = {"tool": after, "written": [QUANTITY_NAME[q] for q in write]}
    lengths = {k: v for k, v in result_measured.items() if k in ("L1", "L2")}
    if lengths:
        values["length"] = lengths
    if "R" in result_measured:
        values["radius"] = result_measured["R"]
    if warnings:
        values["alarm"] = warnings[0].number
    return ToolResult(measured=result_measured, written=tuple(QUANTITY_NAME[q] for q in write),
                      alarm=warnings[0] if warnings else None, before=before, after=after, values=values,
                      ovr=tuple(ovr), ovi=tuple(ovi))


def tool_ovr(call: Cycle982, measured: dict[str, tuple[float, float]], ev: float, tool: LatheTool
             ) -> tuple[list[float], list[int]]:
    """_OVR/_OVI of tool measuring [L17645–L17675]: [8]/[9] L1 actual/difference, [10]/[11] L2,
    [12]/[13] radius, [27] _TZL, [28] _TSA, [29] _TDIF, [30] EV; _OVI [0] D, [2] cycle, [3] _MVAR,
    [5] _PRNUM, [7] EV memory, [8] T, [9] alarm."""
    ovr, ovi = ovr_list(), ovi_list()
    for name, slot in (("L1", 8), ("L2", 10), ("R", 12)):
        if name in measured:
            ovr[slot], ovr[slot + 1] = measured[name]
    ovr[27], ovr[28], ovr[29], ovr[30] = float(call.tzl), float(call.tsa), float(call.tdif), float(ev)
    ovi[0], ovi[2], ovi[3], ovi[5] = tool.d, call.cycle, call.mvar, int(call.prnum)
    ovi[7] = ev_mv_numbers(call.evnum)[0] if call.evnum else 0
    ovi[8] = tool.t
    return ovr, ovi


def evaluate_turning_tool(call: Cycle982, point: LathePoint, ctx: LatheContext, ev: float = 0.0) -> ToolResult:
    """L_meas = L_stored + (rec − f) + (d − s)·R per touch (turning.md §2.4; d = s:
    L_meas = L_stored + rec − f; 2-C: 295.750 − 220.350 − 0.4 = 75.000); X -> L1, Z -> L2.
    ``ev`` = the value of the EV memory of _EVNUM (_EV[n−1]); then ``finish_tool``."""
    variant, tool = check_982(call, ctx)
    _, record = tool_probe_record(call, variant, ctx)
    s = sl_vector(tool.sl, recode=ctx.bit(23))
    r = tool.effective("radius")
    measured = {}
    for touch in point.touches:
        q = "l1" if touch.axis == "X" else "l2"
        f = tp_face(record, touch.key)
        measured[q] = tool.effective(q) + (touch.value - f) + leading_offset(touch.sign, s[touch.axis], r)
    return finish_tool(call, variant, tool, measured, ev, ctx)

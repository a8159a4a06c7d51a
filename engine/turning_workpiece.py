"""What CYCLE974 and CYCLE994 share: parameters, checks, the measured deviation, the correction.

The mean-value strategy (MM measuring-math §3.5 decision table, EV/MV memories) is **not** here: an
evaluation returns a ``WorkpieceMeasurement`` — the actual value and the deviation
``D = (actual − EV) − SETVAL_eff`` in the cycle's display unit (a diameter on X with DIAMON,
turning.md §0.3, turning §0.11) and the symmetrised band (MM turning §3.2) — and the strategy decides on it.
``finish_workpiece`` then turns the strategy's decision and amount A into the compensation
value c (radius, ``_OVR[20]``), the tool-data update and the result lists (turning.md §0.11).

Directions/units: ``scale`` = ½ when the display unit is a diameter (Δ = A/2), else 1.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from engine import alarms
from engine.alarms import AlarmDef
from engine.turning import (
    LatheContext,
    LatheProbe,
    LatheTool,
    axis_of_ma,
    check_fa,
    check_frames,
    check_nmsp,
    ev_mv_numbers,
    is_diameter,
    ovi_list,
    ovr_list,
    probe_directions,
    record_index,
    tool_family,
)
from engine.turning_offsets import (
    ToolTarget,
    correction_value,
    decode_tool_knum,
    workpiece_tool_update,
    zero_offset_update,
)
from engine.types import FeatureFix, FloatArray, MeasuringError

DECISIONS = ("none", "mean", "full", "oversize", "undersize", "dimension_difference", "safe_area")


@dataclass(frozen=True)
class WorkpieceCall:
    """Parameters of CYCLE974 (``cycle`` 974: _MVAR 0, 100, 1000) and CYCLE994 (994: _MVAR 1, 2)
    (turning.md §5.4, turning §5.5, turning §5.6, turning §6.2); tolerances per MM turning §3.2 in the display unit of _MA."""

    cycle: int
    mvar: int
    setval: float
    ma: int = 2
    knum: int = 0
    tnum: int = 0
    tname: str = ""
    dlnum: int = 0
    tenv: str = ""
    sta1: float = 0.0
    sza: float = 0.0
    szo: float = 0.0
    prnum: int = 1
    fa: float = 2.0
    vms: float = 0.0
    nmsp: int = 1
    tzl: float = 0.001
    tmv: float = 0.7
    tul: float = 1.0
    tll: float = -1.0
    tdif: float = 1.2
    tsa: float = 2.0
    evnum: int = 0
    k: float = 1.0

    @property
    def zero_offset(self) -> bool:
        return self.cycle == 974 and self.mvar == 100


def symmetrise(setval: float, tul: float, tll: float) -> tuple[float, float, float]:
    """MM turning §3.2 [M §2.3.11]: SETVAL_eff = _SETVAL + (_TUL + _TLL)/2, TUL_eff = (_TUL − _TLL)/2,
    TLL_eff = −TUL_eff (5-B: 45, 0, −0.01 -> 44.995, 0.005, −0.005)."""
    half = (float(tul) - float(tll)) / 2.0
    return float(setval) + (float(tul) + float(tll)) / 2.0, half, -half


ZO_NUMBERS = set(range(1, 100)) | {1000} | set(range(1011, 1027)) | set(range(1051, 1067)) | {2000, 9999}


@dataclass(frozen=True)
class CheckedWorkpiece:
    probe: LatheTool
    k: int
    record: LatheProbe
    axis: str
    y_like_x: bool
    diameter: bool            # the cycle's values on _MA are diameters (X with DIAMON, turning §0.3)
    target: ToolTarget | None


def check_workpiece(call: WorkpieceCall, ctx: LatheContext, target: ToolTarget | None = None) -> CheckedWorkpiece:
    """Before any motion (turning.md §5.2, turning §6.2, turning §8): _MVAR 61307, frames 61310/61330, D 61311,
    probe type 61309,
    _MA 61325 (Y only where it exists), _FA 61308, _PRNUM 61313, SL 5..8 61315, _K = 0 61318,
    ZO number 61321, _KNUM digits 61322–61324/61407, D 0 61328, tool 61320, _TENV/_DLNUM
    61405/61406, reversal without SPOS 61372. ``target`` replaces _KNUM (design jog-measuring §9.3 object)."""
    valid = {974: (0, 100, 1000), 994: (1, 2)}.get(call.cycle)
    if valid is None:
        raise ValueError(f"cycle must be 974 or 994, got {call.cycle!r}")
    if isinstance(call.mvar, bool) or call.mvar not in valid:
        raise MeasuringError(alarms.WRONG_VARIANT, f"_MVAR={call.mvar!r} is not a CYCLE{call.cycle} variant")
    check_frames(ctx)
    probe = ctx.tool
    if probe is None or probe.d <= 0:
        raise MeasuringError(alarms.NO_D_NUMBER, "no probe with a D number active")
    if tool_family(probe.type) != "turning":
        raise MeasuringError(alarms.PROBE_TYPE, f"the lathe probe must be a tool type 5xy, got {probe.type}")
    axis = axis_of_ma(call.ma, (1, 2, 3) if ctx.has_y else (1, 2))
    check_fa(call.fa)
    check_nmsp(call.nmsp)
    k = record_index(call.prnum, len(ctx.wp), "_WP")
    probe_directions(probe.sl)                                   # SL 5..8 (61315)
    y_like_x = axis == "Y" and ctx.bit(19)
    if call.zero_offset:
        if call.knum and int(call.knum) not in ZO_NUMBERS:
            raise MeasuringError(alarms.ZO_NUMBER, f"_KNUM={call.knum} is not a zero offset (MM turning §2.1)")
    else:
        if call.k == 0:
            raise MeasuringError(alarms.WEIGHTING_FACTOR, "the weighting factor _K must not be 0")
        if target is None:
            target = decode_tool_knum(call.knum, tnum=call.tnum, tname=call.tname, dlnum=call.dlnum,
                                      tenv=call.tenv, geometry=ctx.bit(6), setup=ctx.bit(8))
    if call.cycle == 974 and call.mvar == 1000 and not ctx.spos:
        raise MeasuringError(alarms.NEEDS_SPOS, "the reversal measurement needs an SPOS-capable spindle")
    return CheckedWorkpiece(probe=probe, k=k, record=ctx.wp[k], axis=axis, y_like_x=y_like_x,
                            diameter=is_diameter(axis, ctx.diamon, y_like_x), target=target)


def trigger_for(record: LatheProbe, k: str) -> float:
    """The calibrated trigger value of a direction; 0 (the manual's default) = not calibrated
    in that direction -> 61341 (turning.md §5.2)."""
    t = record.trigger_value(k)
    if t == 0.0:
        raise MeasuringError(alarms.NOT_CALIBRATED_IN_PLANE, f"the probe is not calibrated travelling {k} "
                                                             "(trigger value 0): calibrate it (CYCLE973)")
    return t


@dataclass(frozen=True)
class WorkpieceMeasurement:
    """The evaluated measurement, before any decision (turning.md §5.4–turning §5.6, turning §6.4).

    ``actual``, ``setpoint`` (_SETVAL), ``setpoint_eff``/``upper_eff``/``lower_eff`` (MM turning §3.2; for
    the ZO variant _SETVAL and no band), ``difference`` = actual − SETVAL_eff (raw, _OVR[16]),
    ``deviation`` = D = (actual ∓ EV) − SETVAL_eff (what the decision uses), ``ev`` the EV applied:
    all in the display unit (diameter when ``diameter``). ``surface`` = the measured radius
    coordinate (974; 994: ½ diameter); ``surfaces`` the single points (974 per spindle angle,
    994 s1/s2); ``direction`` = travel direction (974); ``inside`` (994); ``scale`` ½ or 1.
    """

    cycle: int
    mvar: int
    axis: str
    diameter: bool
    actual: float
    setpoint: float
    setpoint_eff: float
    upper_eff: float
    lower_eff: float
    difference: float
    deviation: float
    ev: float
    surface: float
    surfaces: Mapping[str, float]
    direction: int = 0
    inside: bool = False
    scale: float = 1.0
    start: FloatArray = field(default_factory=lambda: np.zeros(3))
    y_like_x: bool = False

    @property
    def zero_offset(self) -> bool:
        return self.cycle == 974 and self.mvar == 100


def measurement(call: WorkpieceCall, chk: CheckedWorkpiece, ctx: LatheContext, surface_r: float, *,
                ev: float, surfaces: Mapping[str, float], start: npt.ArrayLike, direction: int = 0, inside: bool = False,
                actual_display: float | None = None) -> WorkpieceMeasurement:
    """The deviation of a measured radius coordinate ``surface_r`` (turning.md §5.4, turning §5.5, turning §6.4):
    act = 2·s on X with DIAMON (else s); D = act − EV − SETVAL_eff (EV added with _CHBIT[5]=1,
    only with _EVNUM > 0); the ZO variant uses _SETVAL without symmetrisation."""
    scale = 0.5 if chk.diameter else 1.0
    actual = surface_r / scale if actual_display is None else float(actual_display)
    ev_value = float(ev) if call.evnum > 0 else 0.0
    if call.zero_offset:
        set_eff, up, low = float(call.setval), 0.0, 0.0
    else:
        set_eff, up, low = symmetrise(call.setval, call.tul, call.tll)
    corrected = actual + ev_value if ctx.bit(5) else actual - ev_value
    return WorkpieceMeasurement(cycle=call.cycle, mvar=call.mvar, axis=chk.axis, diameter=chk.diameter,
                                actual=actual, setpoint=float(call.setval), setpoint_eff=set_eff, upper_eff=up,
                                lower_eff=low, difference=actual - set_eff, deviation=corrected - set_eff,
                                ev=ev_value, surface=float(surface_r), surfaces=dict(surfaces),
                                direction=direction, inside=inside, scale=scale,
                                start=np.asarray(start, float).copy(), y_like_x=chk.y_like_x)


@dataclass(frozen=True)
class WorkpieceResult:
    """Result of a 974/994 measurement after the decision: the turning §10.2 values, _OVR/_OVI, the
    compensation value c (radius, 0 if none), the tool-data or frame update (before/after)."""

    values: dict[str, Any]
    ovr: tuple[float, ...]
    ovi: tuple[int, ...]
    compensation: float
    quantity: str | None
    tool_before: dict[str, Any] | None = None
    tool_after: dict[str, Any] | None = None
    frame_before: dict[str, Any] | None = None
    frame_after: dict[str, Any] | None = None
    fix: FeatureFix | None = None
    alarm: AlarmDef | None = None


def frame_axis(m: WorkpieceMeasurement) -> str:
    """The ZO component corrected: the measuring axis; X for Y with _CHBIT[19]=1 [L26271–L26279]."""
    return "X" if m.axis == "Y" and m.y_like_x else m.axis


def zero_offset_decision(call: WorkpieceCall, m: WorkpieceMeasurement) -> tuple[str, float]:
    """974 _MVAR=100 (turning.md §5.4, turning §0.11): |D| > _TSA -> 61303; else 100 % of D: the frame
    shift d_r = D/2 (diameter) or D on the measuring axis. -> (decision "full", d_r)."""
    if abs(m.deviation) > call.tsa:
        raise MeasuringError(alarms.SAFE_AREA, f"difference {m.deviation:+.4f} > _TSA {call.tsa:g}; no correction")
    return "full", m.deviation * m.scale


def finish_workpiece(call: WorkpieceCall, m: WorkpieceMeasurement, ctx: LatheContext, *,
                     decision: str | None = None, amount: float = 0.0, mean_value: float | None = None,
                     warning: AlarmDef | None = None, tool: LatheTool | Mapping[str, Any] | None = None,
                     target: ToolTarget | None = None, frame: Mapping[str, Any] | None = None) -> WorkpieceResult:
    """Apply a decision to a measurement (turning.md §0.11, turning §5.4, turning §5.5, turning §6.4).

    Tool offset (974 0/1000, 994): ``decision`` and ``amount`` A come from the strategy
    (MM measuring-math §3.5; A = D, the mean value or 0); c = correction_value(A, ...) on the quantity of
    ``target`` (from _KNUM, or given), written into ``tool`` per MM turning §2.3 when given and c ≠ 0.
    ZO (974 100): the decision is made here (``zero_offset_decision``); ``frame`` {"coarse",
    "fine"} (an unrotated frame's translations) is updated when given; the FeatureFix serves
    engine.correction.correct for any other frame.
    """
    chk = check_workpiece(call, ctx, target)
    ovr, ovi = ovr_list(), ovi_list()
    values: dict[str, Any] = {"actual": m.actual, "setpoint": m.setpoint, "difference": m.difference,
                    "deviation": m.deviation, "axis": m.axis, "unit": "diameter" if m.diameter else "radius"}
    if m.zero_offset:
        done = _zero_offset_correction(call, m, ctx, frame, values, ovr, ovi)
    else:
        done = _tool_correction(call, m, ctx, chk.target, decision, amount, mean_value, tool, values, ovr, ovi)
    ovi[2], ovi[3], ovi[5] = call.cycle, call.mvar, int(call.prnum)
    ovi[9] = warning.number if warning is not None else 0
    if warning is not None:
        values["alarm"] = warning.number
    return WorkpieceResult(values=values, ovr=tuple(ovr), ovi=tuple(ovi), compensation=done.compensation,
                           quantity=done.quantity, tool_before=done.tool_before, tool_after=done.tool_after,
                           frame_before=done.frame_before, frame_after=done.frame_after, fix=done.fix,
                           alarm=warning)


_SLOTS = {"Z": 0, "X": 1, "Y": 2}        # an axis's place in _OVR's groups of three


@dataclass(frozen=True)
class _Correction:
    """What a decision changed: the compensation value c and the tool or frame update."""

    compensation: float = 0.0
    quantity: str | None = None
    tool_before: dict[str, Any] | None = None
    tool_after: dict[str, Any] | None = None
    frame_before: dict[str, Any] | None = None
    frame_after: dict[str, Any] | None = None
    fix: FeatureFix | None = None


def _zero_offset_correction(call: WorkpieceCall, m: WorkpieceMeasurement, ctx: LatheContext,
                            frame: Mapping[str, Any] | None, values: dict[str, Any], ovr: list[float],
                            ovi: list[int]) -> _Correction:
    """974 _MVAR=100: the decision, the frame update (when ``frame`` is given) and _OVR/_OVI."""
    decision, shift = zero_offset_decision(call, m)
    if not call.knum:                                   # _KNUM=0: measure only [L20956–L20978]
        decision, shift = "none", 0.0
    axis = frame_axis(m)
    slot = _SLOTS[m.axis]
    frame_before = frame_after = None
    if frame is not None and call.knum:
        fine = bool(ctx.fine_offset) and not ctx.bit(21) and int(call.knum) != 2000     # MM turning §2.1
        frame_before, frame_after = zero_offset_update(frame.get("coarse", (0, 0, 0)), frame.get("fine", (0, 0, 0)),
                                                       axis, shift, fine_mode=fine)
    values.update({"decision": decision, "compensation": shift, "frame_axis": axis,
                   "setpoint_radius": m.setpoint * m.scale})
    if frame_after is not None:
        values["frame"] = {"before": frame_before, "after": frame_after}
    ovr[0], ovr[4], ovr[16], ovr[28], ovr[30] = m.setpoint, m.actual, m.difference, float(call.tsa), m.ev
    ovr[1 + slot], ovr[5 + slot], ovr[17 + slot] = m.setpoint, m.actual, m.difference
    ovi[0], ovi[11] = int(call.knum), 1 if call.knum else 0
    return _Correction(compensation=shift, frame_before=frame_before, frame_after=frame_after,
                       fix=FeatureFix(position={axis: m.surface}, point=None))


def _tool_correction(call: WorkpieceCall, m: WorkpieceMeasurement, ctx: LatheContext, tgt: ToolTarget | None, decision: str | None,
                     amount: float, mean_value: float | None, tool: LatheTool | Mapping[str, Any] | None,
                     values: dict[str, Any], ovr: list[float], ovi: list[int]) -> _Correction:
    """974 0/1000, 994: the strategy's decision applied to the tool data of ``tgt``; _OVR/_OVI."""
    if decision not in DECISIONS:
        raise ValueError(f"decision must be one of {', '.join(DECISIONS)}, got {decision!r}")
    if decision in ("none", "dimension_difference", "safe_area"):
        amount = 0.0
    c = 0.0
    quantity = None
    tool_before = tool_after = None
    if tgt is not None:
        quantity = tgt.resolve(m.axis, m.y_like_x)
        if amount:
            c = correction_value(amount, scale=m.scale, radius=quantity == "radius", direction=m.direction,
                                 two_point=m.cycle == 994, inside=m.inside, inverse=tgt.inverse)
        if tool is not None and c != 0.0:
            tool_before, tool_after = workpiece_tool_update(tool, quantity, c, tgt)
    values.update({"decision": decision, "compensation": c, "quantity": quantity})
    if mean_value is not None:
        values["mean_value"] = mean_value
    if tool_after is not None:
        values["tool"] = {"before": tool_before, "after": tool_after}
    _tool_ovr(call, m, ctx, c, mean_value, ovr)
    ovi[0] = tgt.d if tgt is not None else 0
    ovi[4] = int(call.k)
    ev_no, mv_no = ev_mv_numbers(call.evnum)
    ovi[6], ovi[7] = (mv_no, ev_no) if call.evnum else (0, 0)
    ovi[8] = tgt.t if tgt is not None else int(call.tnum or 0)
    return _Correction(compensation=c, quantity=quantity, tool_before=tool_before, tool_after=tool_after)


def _tool_ovr(call: WorkpieceCall, m: WorkpieceMeasurement, ctx: LatheContext, c: float, mean_value: float | None,
              ovr: list[float]) -> None:
    slot = _SLOTS[m.axis]
    ovr[0], ovr[4], ovr[8], ovr[12], ovr[16] = m.setpoint_eff, m.actual, m.upper_eff, m.lower_eff, m.difference
    if m.cycle != 994:                   # [I] the start position with the setpoint / actual on _MA
        for a, j, i in (("Z", 2, 0), ("X", 0, 1), ("Y", 1, 2)):
            ovr[1 + i] = ovr[5 + i] = (2.0 * float(m.start[j]) if is_diameter(a, ctx.diamon, m.y_like_x)
                                       else float(m.start[j]))
    ovr[1 + slot], ovr[5 + slot] = m.setpoint_eff, m.actual
    ovr[17 + slot] = m.difference
    ovr[20] = c
    ovr[27], ovr[28], ovr[29], ovr[30] = float(call.tzl), float(call.tsa), float(call.tdif), m.ev
    ovr[31] = float(mean_value or 0.0)

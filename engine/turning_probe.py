"""CYCLE973: calibrating the workpiece probe in a reference groove or on a surface (turning.md §4).

Steps: the NC reference is the ball centre as the NC computes it from L1/L2 (turning.md §0.4);
the groove variant is machine-related (coords "MCS", `_KB` always machine-related radius values
[L25669–L25670]), the surface variant workpiece-related (coords "WCS"); X radius. A stored skew
e (_WP[k,7] Z, [k,8] X) is the true ball centre minus the NC's: positions are commanded as
``q − e`` and the ball centre at a switch is ``rec + e`` (MM turning §5.2, turning.md §12 Q16).

Trigger values (turning.md §0.7, turning §4.4): ``t(dir) = c_switch − S`` along the axis, c = rec + e;
ideally +r travelling −, −r travelling +. The expected switch for planning is ``S − d·r`` with
r = DP6, so a zeroed record works (turning §0.8).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from engine import alarms
from engine.turning import (
    LatheContext,
    LatheMotion,
    LathePoint,
    LatheProbe,
    LatheProgram,
    LatheTool,
    axis_of_ma,
    calibration_check,
    check_fa,
    check_frames,
    check_nmsp,
    check_probe_direction,
    direction_of_md,
    key,
    measuring_feed,
    ovi_list,
    ovr_list,
    record_index,
    to_radius,
    tool_family,
)
from engine.types import MeasuringError


@dataclass(frozen=True)
class Cycle973:
    """Parameters of CYCLE973 (turning.md §4.2): groove ``_MVAR`` x x x 1 3 with ``_CALNUM``,
    surface ``_MVAR=0`` with ``_SETVAL`` (relative to W, a diameter on X with DIAMON)."""

    mvar: int
    ma: int = 1
    md: int = 0
    setval: float = 0.0
    calnum: int = 0
    prnum: int = 1
    fa: float = 2.0
    vms: float = 0.0
    nmsp: int = 1
    tzl: float = 0.001
    tsa: float = 2.0


@dataclass(frozen=True)
class Variant973:
    surface: bool
    both: bool            # digit 4 = 2: both directions of _MA
    ball: bool            # digit 3 = 1: effective ball diameter
    skew: bool            # digit 5 = 1: position deviation


def decode_973(mvar: object) -> Variant973:
    """_MVAR of CYCLE973 (turning.md §4.1 [L20275–L20295]): 0 surface; d5 d4 d3 1 3 groove.
    Digit 4 = 0 (the manual's own ``_MVAR=13`` [L20545, L22168]) means one direction; one
    direction with skew or ball diameter (e.g. 11013, 01113) -> 61307 [I]."""
    if isinstance(mvar, bool) or not isinstance(mvar, int | np.integer) or not 0 <= int(mvar) <= 99_999:
        raise MeasuringError(alarms.WRONG_VARIANT, f"_MVAR={mvar!r} is not a CYCLE973 variant")
    n = int(mvar)
    if n == 0:
        return Variant973(surface=True, both=False, ball=False, skew=False)
    d3, d4, d5 = (n // 100) % 10, (n // 1000) % 10, (n // 10_000) % 10
    if n % 100 != 13 or d3 not in (0, 1) or d4 not in (0, 1, 2) or d5 not in (0, 1):
        raise MeasuringError(alarms.WRONG_VARIANT, f"_MVAR={n} is not a CYCLE973 variant (turning.md §4.1)")
    both = d4 == 2
    if not both and (d3 or d5):
        raise MeasuringError(alarms.WRONG_VARIANT, f"_MVAR={n}: in one direction neither the position deviation "
                                                   "nor the ball diameter can be determined [L20293]")
    return Variant973(surface=False, both=both, ball=d3 == 1, skew=d5 == 1)


@dataclass(frozen=True)
class Groove:
    """A reference groove _KB[k,0..6] (turning.md §0.6): SL 7 (axial) walls [0] +X side,
    [1] −X side, bottom [2]; SL 8 (radial) walls [3] +Z side, [4] −Z side, opening [5],
    bottom [6]. Machine-related radius values; 0 = not entered."""

    kb: tuple[float, ...]

    def __post_init__(self) -> None:
        values = tuple(float(v) for v in self.kb) + (0.0,) * max(0, 7 - len(self.kb))
        object.__setattr__(self, "kb", values[:7])

    def surface(self, sl: int, k: str) -> float:
        """The groove surface touched travelling ``k`` (turning.md §4.3, turning §4.4)."""
        table = {7: {"X+": 0, "X-": 1, "Z-": 2}, 8: {"Z+": 3, "Z-": 4, "X-": 6}}[sl]
        return self.kb[table[k]]

    @property
    def depth(self) -> float | None:
        """h = _KB[5] − _KB[6], known only when both are entered (turning.md §0.6)."""
        if self.kb[5] != 0.0 and self.kb[6] != 0.0:
            return self.kb[5] - self.kb[6]
        return None

    def width(self, sl: int) -> float:
        return self.kb[0] - self.kb[1] if sl == 7 else self.kb[3] - self.kb[4]

    def centre(self, sl: int) -> float:
        """Groove centre across the walls: X (SL 7) or Z (SL 8)."""
        return 0.5 * (self.kb[0] + self.kb[1]) if sl == 7 else 0.5 * (self.kb[3] + self.kb[4])


GROOVE_KEYS = {(7, "Z"): ("Z-",), (7, "X"): ("X+", "X-"), (8, "Z"): ("Z+", "Z-"), (8, "X"): ("X-",)}


@dataclass(frozen=True)
class Checked973:
    variant: Variant973
    probe: LatheTool
    k: int
    record: LatheProbe
    groove: Groove | None
    axis: str
    keys: tuple[str, ...]
    r: float

    @property
    def groove_record(self) -> Groove:
        """The groove of a groove variant (check_973 gives every one its _KB record)."""
        if self.groove is None:
            raise ValueError("a surface calibration (CYCLE973 _MVAR 0) has no groove")
        return self.groove


def check_973(call: Cycle973, ctx: LatheContext) -> Checked973:
    """Before any motion (turning.md §4.2, turning §4.3, turning §8): variant 61307, frames 61310/61330, D 61311,
    probe type 61309,
    _MA 61325, _FA 61308, _PRNUM 61313, _CALNUM 61333, _MD 61326, SL / direction into the stylus
    61315, groove width/depth for r and _FA 61333."""
    variant = decode_973(call.mvar)
    check_frames(ctx)
    probe = ctx.tool
    if probe is None or probe.d <= 0:
        raise MeasuringError(alarms.NO_D_NUMBER, "no probe with a D number active")
    if tool_family(probe.type) != "turning":
        raise MeasuringError(alarms.PROBE_TYPE, f"the lathe probe must be a tool type 5xy, got {probe.type}")
    allowed_ma = (1, 2, 3) if variant.surface and ctx.has_y else (1, 2)
    axis = axis_of_ma(call.ma, allowed_ma)
    fa = check_fa(call.fa)
    check_nmsp(call.nmsp)
    k = record_index(call.prnum, len(ctx.wp), "_WP")
    r = probe.effective("radius")
    groove = None
    if variant.surface:
        d = direction_of_md(call.md)
        check_probe_direction(probe.sl, key(axis, d))       # SL 5..8, not into the stylus (turning §0.6)
        keys: tuple[str, ...] = (key(axis, d),)
    else:
        if isinstance(call.calnum, bool) or not 1 <= int(call.calnum) <= len(ctx.kb):
            raise MeasuringError(alarms.CALIBRATION_BODY, f"_CALNUM={call.calnum!r}: no groove record "
                                                          f"(there are {len(ctx.kb)})")
        groove = Groove(tuple(ctx.kb[int(call.calnum) - 1]))
        if probe.sl not in (7, 8):
            raise MeasuringError(alarms.CUTTING_EDGE_POSITION, f"a probe in the groove needs SL 7 or 8, got {probe.sl}")
        if variant.both:
            keys = (key(axis, 1), key(axis, -1))                  # + before − (turning.md §4.3)
        else:
            keys = (key(axis, direction_of_md(call.md)),)
        for kk in keys:
            check_probe_direction(probe.sl, kk)                   # the directions turning §4.3 leaves out
        walls = len(GROOVE_KEYS[(probe.sl, axis)]) == 2
        w = groove.width(probe.sl)
        need = 2.0 * r + fa if walls else 2.0 * r
        if not w > need:
            raise MeasuringError(alarms.CALIBRATION_BODY, f"groove {call.calnum}: width {w:g} must exceed {need:g} "
                                                          f"(2r{' + _FA' if walls else ''}, turning.md §4.3)")
        h = groove.depth
        if walls and h is not None and h < 2.0 * r + fa:
            raise MeasuringError(alarms.CALIBRATION_BODY, f"groove {call.calnum}: depth {h:g} < 2r + _FA = "
                                                          f"{2.0 * r + fa:g} (turning.md §4.3)")
    return Checked973(variant=variant, probe=probe, k=k, record=ctx.wp[k], groove=groove, axis=axis, keys=keys, r=r)


def probe_calibration_program(call: Cycle973, start: npt.ArrayLike, ctx: LatheContext, label: str = "P1") -> LatheProgram:
    """The point program of CYCLE973 (turning.md §4.3 [I]).

    Groove SL 7: ball X to the groove centre (at the start Z), Z into the groove to
    ``_KB[2] + r + _FA``; probe the bottom −Z there, or each wall from ``S − d·(r + _FA)``
    (+ before −). SL 8 likewise with Z to the centre and X to ``_KB[6] + r + _FA``. Surface:
    along _MA to ``s_set − d·r − d·_FA``, probe 2·_FA. Every touch returns to its start of
    probing: the probe ends _FA in front of the last surface [L20485–L20486].
    """
    c = check_973(call, ctx)
    fa = check_fa(call.fa)
    feed = measuring_feed(call.vms, fa)
    p0 = np.asarray(start, float)
    m = LatheMotion(p0, ctx, "WCS" if c.variant.surface else "MCS", offset=c.record.skew_vector())
    touches = []
    info: dict[str, Any] = {"axis": c.axis, "keys": c.keys}
    if c.variant.surface:
        (k,) = c.keys
        d = 1 if k[1] == "+" else -1
        s_set = to_radius(call.setval, c.axis, ctx.diamon)
        info["setpoint"] = s_set
        yield from m.move_axis(c.axis, s_set - d * (c.r + fa), f"{label} start of probing", ball=True)
        touches.append((yield from m.touch(k, 2.0 * fa, feed, call.nmsp, f"{label} {k}", expected=fa, role=label)))
    else:
        sl, g = c.probe.sl, c.groove_record
        across, into = ("X", "Z") if sl == 7 else ("Z", "X")
        depth_pos = (g.kb[2] if sl == 7 else g.kb[6]) + c.r + fa
        yield from m.move_axis(across, g.centre(sl), f"{label} to the groove centre", ball=True)
        yield from m.move_axis(into, depth_pos, f"{label} into the groove", ball=True)
        for k in c.keys:
            axis, d = k[0], (1 if k[1] == "+" else -1)
            if axis == across:
                yield from m.move_axis(axis, g.surface(sl, k) - d * (c.r + fa), f"{label} {k} start of probing",
                                       ball=True)
            touches.append((yield from m.touch(k, 2.0 * fa, feed, call.nmsp, f"{label} {k}", expected=fa,
                                               role=label)))
        info["groove"] = g.kb
    return LathePoint(cycle=973, mvar=call.mvar, coords=m.coords, start=p0.copy(), touches=tuple(touches), info=info)


@dataclass(frozen=True)
class ProbeCalibrationResult:
    """The new _WP[k] record, what was measured/stored, the turning §10.2 values and _OVR/_OVI."""

    record: LatheProbe
    trigger: dict[str, Any]
    difference: dict[str, Any]
    stored: tuple[str, ...]
    skew: dict[str, Any]
    effective_diameter: float | None
    values: dict[str, Any]
    ovr: tuple[float, ...]
    ovi: tuple[int, ...]


def _checked_diameter(d_eff: float, stored_d: float, nominal_d: float, call: Cycle973, stored: list[str]) -> float:
    """The effective ball diameter to store (turning §0.11 rule; one never entered, 0, is checked
    against 2·DP6 and always stored [I]); "diameter" appended to ``stored`` when it is written."""
    if stored_d == 0.0:
        calibration_check(d_eff, nominal_d, 0.0, call.tsa, "effective ball diameter")
        stored.append("diameter")
        return d_eff
    d_out, changed = calibration_check(d_eff, stored_d, call.tzl, call.tsa, "effective ball diameter")
    if changed:
        stored.append("diameter")
    return d_out


def evaluate_probe_calibration(call: Cycle973, point: LathePoint, ctx: LatheContext) -> ProbeCalibrationResult:
    """turning.md §4.4:

        t(dir) = rec + e − S                       (e = stored skew on that axis)
        skew, both directions of axis j:  e_j = (S(+j) + S(−j))/2 − (rec(+j) + rec(−j))/2,
                                          t(±j) = rec(±j) + e_j − S(±j)
        ball diameter (both):             d_eff = t(−j) − t(+j)
        surface:                          t = rec + e − s_set

    Each stored value passes the turning §0.11 calibration rule (61303 before anything is stored); an
    effective diameter never entered (0) is checked against 2·DP6 instead and always stored [I].
    """
    c = check_973(call, ctx)
    old = c.record
    triggers, new_skew, d_eff = _measured(c, point, ctx, call)
    # turning §0.11 calibration rule, every value checked before anything is stored
    stored: list[str] = []
    stored_values, differences = _checked_triggers(triggers, old, call, stored)
    skew_out = dict(old.skew)
    if new_skew is not None:
        value, changed = calibration_check(new_skew, float(old.skew.get(c.axis, 0.0)), call.tzl, call.tsa,
                                           f"position deviation {c.axis}")
        skew_out[c.axis] = value
        differences[f"skew {c.axis}"] = new_skew - float(old.skew.get(c.axis, 0.0))
        if changed:
            stored.append(f"skew {c.axis}")
    d_out = old.effective_diameter
    if d_eff is not None:
        d_out = _checked_diameter(d_eff, old.effective_diameter, 2.0 * c.r, call, stored)
        differences["diameter"] = d_eff - (old.effective_diameter or 2.0 * c.r)
    trig = dict(old.trigger)
    trig.update(stored_values)
    record = old.replace(trigger=trig, skew=skew_out, effective_diameter=d_out)
    ovr, ovi = _calibration_ovr(call, record, triggers, differences, d_eff)
    values: dict[str, Any] = {"probe": record.to_dict(), "trigger": dict(triggers),
              "difference": {k: differences[k] for k in triggers}, "stored": list(stored)}
    if new_skew is not None:
        values["skew"] = {c.axis: new_skew}
    if d_eff is not None:
        values["effective_diameter"] = d_eff
    return ProbeCalibrationResult(record=record, trigger=dict(triggers), difference=differences,
                                  stored=tuple(stored), skew={c.axis: new_skew} if new_skew is not None else {},
                                  effective_diameter=d_eff, values=values, ovr=tuple(ovr), ovi=tuple(ovi))


def _measured(c: Checked973, point: LathePoint, ctx: LatheContext, call: Cycle973
              ) -> tuple[dict[str, float], float | None, float | None]:
    """(trigger value per direction, the new skew of the axis or None, the effective ball diameter
    or None) from the touches (turning.md §4.4)."""
    old = c.record
    e = {"Z": float(old.skew.get("Z", 0.0)), "X": float(old.skew.get("X", 0.0)), "Y": 0.0}
    by_key = {t.key: t for t in point.touches}
    if c.variant.surface:
        (k,) = c.keys
        surfaces = {k: to_radius(call.setval, c.axis, ctx.diamon)}
    else:
        surfaces = {k: c.groove_record.surface(c.probe.sl, k) for k in c.keys}
    new_skew = None
    if c.variant.skew:
        plus, minus = key(c.axis, 1), key(c.axis, -1)
        new_skew = (0.5 * (surfaces[plus] + surfaces[minus])
                    - 0.5 * (by_key[plus].value + by_key[minus].value))          # turning.md §4.4
        e[c.axis] = new_skew
    triggers = {k: by_key[k].value + e[k[0]] - surfaces[k] for k in c.keys}
    d_eff = None
    if c.variant.ball:
        d_eff = triggers[key(c.axis, -1)] - triggers[key(c.axis, 1)]            # independent of the skew
    return triggers, new_skew, d_eff


def _checked_triggers(triggers: dict[str, float], old: LatheProbe, call: Cycle973, stored: list[str]
                      ) -> tuple[dict[str, float], dict[str, float]]:
    """(the trigger values to store, the differences to the stored ones); the directions whose
    value is written are appended to ``stored``."""
    stored_values: dict[str, float] = {}
    differences: dict[str, float] = {}
    for k, t in triggers.items():
        value, changed = calibration_check(t, old.trigger_value(k), call.tzl, call.tsa, f"trigger value {k}")
        stored_values[k] = value
        differences[k] = t - old.trigger_value(k)
        if changed:
            stored.append(k)
    return stored_values, differences


def _calibration_ovr(call: Cycle973, record: LatheProbe, triggers: dict[str, float], differences: dict[str, float],
                     d_eff: float | None) -> tuple[list[float], list[int]]:
    ovr, ovi = ovr_list(), ovi_list()
    slots = {"Z-": 8, "Z+": 10, "X-": 12, "X+": 14, "Y-": 16, "Y+": 18}      # [L20296–L20320]
    for k, i in slots.items():
        ovr[i] = record.trigger_value(k)
    for k, t in triggers.items():
        ovr[slots[k]], ovr[slots[k] + 1] = t, differences[k]
    ovr[4] = float(record.effective_diameter)
    if d_eff is not None:
        ovr[4], ovr[5] = d_eff, differences["diameter"]
    ovr[20], ovr[21] = float(record.skew.get("Z", 0.0)), float(record.skew.get("X", 0.0))
    ovr[27], ovr[28] = float(call.tzl), float(call.tsa)
    ovi[2], ovi[3], ovi[5] = 973, int(call.mvar), int(call.prnum)
    return ovr, ovi


__all__ = ["Cycle973", "Groove", "ProbeCalibrationResult", "Variant973", "check_973", "decode_973",
           "evaluate_probe_calibration", "probe_calibration_program"]

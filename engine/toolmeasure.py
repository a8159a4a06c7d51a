"""Tool measuring math: tool-probe calibration, length, radius, offsets, spindle speed/feed.

Spec: measuring-math §14 (CYCLE971), spec/jog-measuring.md §7.2, jog-measuring §7.3, jog-measuring §11 Q12/Q13.

Tool probe record ``_TP[n]`` is a dict keyed by the travel direction of the touch (MCS axis
letter + sign, as engine.plan_base.PlanContext.tool_probe): "X-" = _TP[n,0] (travel −X, the
probe's +X face), "X+" = _TP[n,1], "Y-" = [2], "Y+" = [3], "Z-" = [4]: the coordinate of the
tool edge at switching (jog-measuring §7.2 table). ``F`` = tool reference point (spindle nose) at the
latch; the tool tip is ``F − L1·p̂`` (design.md §4). Radius measuring uses the tool centre
line ``X_c`` (= F in the plane).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from engine import alarms
from engine.plan_base import ToolPoint, ToolProbePoint
from engine.planes import Plane, axis_index
from engine.types import MeasuringError

__all__ = [
    "SpindleFeeds", "calibrate_tool_probe", "calibrate_tool_probe_point", "compensation_table_value",
    "evaluate_tool_task", "latch_delay_correction", "probe_centre", "spindle_speed_feeds", "tool_length", "tool_offset_update", "tool_point_value",
    "tool_radius",
]


# --- tool probe calibration (measuring-math §14.5, jog-measuring §7.2) -----------------------------------------

def calibrate_tool_probe(switch: dict[str, float], cal_length: float, cal_radius: float, plane: Plane,
                         old: dict[str, float] | None = None) -> tuple[dict[str, float], dict[str, Any]]:
    """_TP values from the calibration tool's exact L_c, R_c (measuring-math §14.5 [M], jog-measuring §7.2).

    ``switch[key]``: the reference coordinate on the key's axis at the latch — for the −infeed
    key ("Z-" in G17) the spindle nose F_p, for plane keys the tool centre line X_c / Y_c (MCS):

        travel −a: _TP = X_c − R_c      travel +a: _TP = X_c + R_c      travel −p: _TP = F_p − L_c

    Returns (new record: ``old`` updated with the measured keys; display numbers: the record,
    the differences new − old per measured key, the probe centre where both sides are known).
    """
    p_key = f"{plane.infeed}-"
    record = dict(old or {})
    measured: dict[str, float] = {}
    for key, value in switch.items():
        if len(key) != 2 or key[0] not in "XYZ" or key[1] not in "+-":
            raise ValueError(f"bad tool probe key {key!r}")
        if key == p_key:
            if cal_length <= 0.0:
                raise MeasuringError(alarms.TOOL_SIZE_ZERO, "Tool length or radius is 0 (calibration tool length)")
            measured[key] = float(value) - cal_length                       # measuring-math §14.5 F_z − L_c
        elif key[0] == plane.infeed:
            raise ValueError(f"the tool axis is only probed in minus direction, got {key!r}")
        else:
            if cal_radius <= 0.0:
                raise MeasuringError(alarms.TOOL_SIZE_ZERO, "Tool length or radius is 0 (calibration tool radius)")
            # measuring-math §14.5: travel −X: X_c − R_c; travel +X: X_c + R_c
            measured[key] = float(value) - cal_radius if key[1] == "-" else float(value) + cal_radius
    record.update(measured)
    values = {"tool_probe": dict(record),
              "difference": {k: (None if old is None or k not in old else v - float(old[k]))
                             for k, v in measured.items()},
              "center": probe_centre(record)}
    return record, values


def calibrate_tool_probe_point(point: ToolProbePoint, plane: Plane, old: dict[str, float] | None = None
                               ) -> tuple[dict[str, float], dict[str, Any]]:
    """``calibrate_tool_probe`` from engine.plan's stored point (touch ``rec`` = tool tip, MCS).

    The −p value uses the last −p touch (at the found centre, measuring-math §14.5 automatic order); F_p =
    tip_p + L1 with L1 = ``point.tool_length`` (the calibration tool's exact length is active).
    """
    p_key = f"{plane.infeed}-"
    switch: dict[str, float] = {}
    for touch in point.touches:                       # later touches of a key win
        rec = np.asarray(touch.rec, dtype=float)
        j = axis_index(touch.key[0])
        switch[touch.key] = float(rec[j]) + (point.tool_length if touch.key == p_key else 0.0)
    return calibrate_tool_probe(switch, point.tool_length, point.tool_radius, plane, old)


def probe_centre(record: dict[str, float]) -> dict[str, float]:
    """Probe centre per plane axis with both directions known: (_TP[a−] + _TP[a+])/2 (measuring-math §14.5)."""
    out = {}
    for axis in "XYZ":
        if f"{axis}-" in record and f"{axis}+" in record:
            out[axis] = 0.5 * (float(record[f"{axis}-"]) + float(record[f"{axis}+"]))
    return out


# --- measuring (measuring-math §14.4, jog-measuring §7.3 [I]) ------------------------------------------------

def tool_length(f_infeed: float, record: dict[str, float], plane: Plane) -> float:
    """L1 = F_p − _TP[n,4] (measuring-math §14.4; jog-measuring §7.3). Offset V and the rotating-spindle lateral
    offset (R − V, jog-measuring §11 Q12) only move the contact in the plane: the formula is the same."""
    key = f"{plane.infeed}-"
    if key not in record:
        raise MeasuringError(alarms.NOT_CALIBRATED_IN_PLANE, f"Tool probe not calibrated ({key})")
    return float(f_infeed) - float(record[key])


def tool_radius(centre_a: float, key: str, record: dict[str, float]) -> float:
    """R from the side touch (measuring-math §14.4): travel −a: R = X_c − _TP[a−]; +a: R = _TP[a+] − X_c."""
    if key not in record:
        raise MeasuringError(alarms.NOT_CALIBRATED_IN_PLANE, f"Tool probe not calibrated ({key})")
    if key.endswith("-"):
        return float(centre_a) - float(record[key])
    return float(record[key]) - float(centre_a)


def tool_point_value(point: ToolPoint, record: dict[str, float], plane: Plane) -> float:
    """Measured L1 (``kind`` "length") or R ("radius") from engine.plan's stored point
    (touch ``rec`` = tool tip, MCS, with the NC's L1 = ``point.tool_length``)."""
    rec = np.asarray(point.touch.rec, dtype=float)
    if point.kind == "length":
        if point.tool_length <= 0.0:
            raise MeasuringError(alarms.TOOL_SIZE_ZERO, "Tool length or radius is 0")
        f_p = float(rec[axis_index(plane.infeed)]) + point.tool_length    # F = tip + L1
        return tool_length(f_p, record, plane)
    if point.tool_radius <= 0.0:
        raise MeasuringError(alarms.TOOL_SIZE_ZERO, "Tool length or radius is 0")
    return tool_radius(float(rec[axis_index(point.touch.key[0])]), point.touch.key, record)


def tool_offset_update(measured: float, geometry: float, wear: float, mode: str,
                       zero_limit: float = 0.0) -> dict[str, Any]:
    """Offset bookkeeping (jog-measuring §7.3 _JM_B[0], jog-measuring §11 Q13; measuring-math §14.4 _CHBIT[3]).

    Δ = measured − (geometry + wear). |Δ| < ``zero_limit`` (_TZL, 0 in JOG): unchanged.
    ``mode`` "geometry" (_JM_B[0]=0): geometry := measured, wear := 0.
    ``mode`` "wear" (_JM_B[0]=1): wear := measured − geometry (= wear + Δ), geometry kept.
    """
    delta = float(measured) - (float(geometry) + float(wear))
    if mode not in ("geometry", "wear"):
        raise ValueError(f"mode must be 'geometry' or 'wear', got {mode!r}")
    if abs(delta) < zero_limit:
        new_geometry, new_wear = float(geometry), float(wear)
    elif mode == "geometry":
        new_geometry, new_wear = float(measured), 0.0
    else:
        new_geometry, new_wear = float(geometry), float(measured) - float(geometry)
    return {"measured": float(measured), "delta": delta, "changed": abs(delta) >= zero_limit,
            "geometry": new_geometry, "wear": new_wear,
            "geometry_old": float(geometry), "wear_old": float(wear)}


# --- rotating spindle (measuring-math §14.2, jog-measuring §7.3 [I]) --------------------------------------------

@dataclass(frozen=True)
class SpindleFeeds:
    speed: float                 # rpm
    final_feed: float            # mm/min, F = n·Δ
    feeds: tuple[float, ...]     # feeds of the probing stages, last = final


def spindle_speed_feeds(radius: float, max_surface_speed: float = 100.0, max_speed: float = 1000.0,
                        accuracy: float = 0.01, min_feed: float = 1.0, max_feed: float = 20.0,
                        factor1: float = 10.0, factor2: float = 0.0) -> SpindleFeeds:
    """n = min(E_MESS_MAX_S, E_MESS_MAX_V/(2π·r·0.001)), F = n·E_MESS_MIN_D (measuring-math §14.2);
    1st probing min(E_MESS_MAX_F, max(E_MESS_MIN_F, E_MESS_F_FAK1·F)); E_MESS_F_FAK2 > 0: a
    2nd probing at FAK2·F; last at F (jog-measuring §7.3 [I]). Radius 0 -> 61351."""
    if radius <= 0.0:
        raise MeasuringError(alarms.TOOL_SIZE_ZERO, "Tool length or radius is 0")
    speed = min(max_speed, max_surface_speed / (2.0 * math.pi * radius * 0.001))   # measuring-math §14.2
    final = speed * accuracy                                                        # measuring-math §14.2 F = n·Δ
    feeds = [min(max_feed, max(min_feed, factor1 * final))]
    if factor2 > 0.0:
        feeds.append(factor2 * final)
    feeds.append(final)
    return SpindleFeeds(speed=float(speed), final_feed=float(final), feeds=tuple(feeds))


def compensation_table_value(table: Sequence[Sequence[float]], radius: float, surface_speed: float
                             ) -> float:
    """_MT_EC_R/_MT_EC_L lookup (measuring-math §14.3): row 0 = [0, R1..R4], column 0 of rows 1.. = v1..;
    take the next table radius and speed (smallest >= actual, clamped to the last); the value is
    subtracted from the measured radius/length by the caller."""
    t = np.asarray(table, dtype=float)
    radii, speeds = t[0, 1:], t[1:, 0]
    col = int(np.searchsorted(radii, radius, side="left"))
    row = int(np.searchsorted(speeds, surface_speed, side="left"))
    col, row = min(col, len(radii) - 1), min(row, len(speeds) - 1)
    return float(t[row + 1, col + 1])


def evaluate_tool_task(task: str, params: dict[str, Any], point: object, plane: Plane, tool_probe: dict[str, float] | None,
                       tool: dict[str, Any] | None = None) -> tuple[dict[str, Any], dict[str, Any]]:
    """``toolprobe.calibrate`` / ``tool.length`` / ``tool.diameter`` (design.md §4).

    toolprobe.calibrate -> (new _TP record, values {"tool_probe", "difference", "center"}).
    tool.* -> (new tool data {"length", "radius", "wear": {"length", "radius"}, ...}, values
    {"length" or "radius" (+ "diameter"), "tool", "offset"}); ``params["compensation"]`` is
    "geometry" (_JM_B[0]=0) or "wear" (1).
    """
    if task == "toolprobe.calibrate":
        if not isinstance(point, ToolProbePoint):
            raise ValueError(f"{task} needs a ToolProbePoint, got {type(point).__name__}")
        return calibrate_tool_probe_point(point, plane, tool_probe)
    if task not in ("tool.length", "tool.diameter"):
        raise ValueError(f"not a tool task: {task!r}")
    if not isinstance(point, ToolPoint):
        raise ValueError(f"{task} needs a ToolPoint, got {type(point).__name__}")
    measured = tool_point_value(point, tool_probe or {}, plane)
    tool = dict(tool or {})
    wear = dict(tool.get("wear") or {})
    name = "length" if point.kind == "length" else "radius"
    update = tool_offset_update(measured, float(tool.get(name, 0.0)), float(wear.get(name, 0.0)),
                                str(params.get("compensation", "geometry")))
    tool[name] = update["geometry"]
    wear[name] = update["wear"]
    tool["wear"] = {"length": float(wear.get("length", 0.0)), "radius": float(wear.get("radius", 0.0))}
    values = {name: measured, "tool": tool, "offset": update}
    if name == "radius":
        values["diameter"] = 2.0 * measured
    return tool, values


def latch_delay_correction(stage_tips: Sequence[npt.ArrayLike | None], key: str, feeds: Sequence[float], override: float,
                           cal_feed: float, cal_override: float, min_feed_spread: float = 1.0
                           ) -> tuple[float | None, float]:
    """Signal delay t [s] of a flying tool measurement and the correction (v_meas − v_cal)·t.

    design.md §5, measuring-math §1.5 e_lat = v·t: calibration runs at E_MESS_MT_FM, rotating
    measuring at F = n·E_MESS_MIN_D, so a delay t leaves (v_meas − v_cal)·t in the result. [I] The
    stages of the final probing touch the same point at ``feeds`` (mm/min, last = measuring
    feed); their latched tool tips ``stage_tips`` (MCS, None = no latch) give s_i = S + v_i·t
    along the travel ``key`` ("Z-", "X+", least squares, a delay is never negative). Referring
    measurement and calibration (``cal_feed`` at ``cal_override`` %) to feed 0 adds
    (v_meas − v_cal)·t, v = feed·override. t is None (correction 0) when the stages cannot tell:
    fewer than two, one without a latch, or feeds less than ``min_feed_spread`` mm/min apart.
    """
    v = np.asarray(feeds, dtype=float) * override / 100.0 / 60.0          # mm/s
    if (len(v) < 2 or len(stage_tips) != len(v) or any(tip is None for tip in stage_tips)
            or np.ptp(v) * 60.0 < min_feed_spread):
        return None, 0.0
    d = np.zeros(3)
    d[axis_index(key[0])] = 1.0 if key[1] == "+" else -1.0
    s = np.array([float(np.asarray(tip, dtype=float) @ d) for tip in stage_tips])
    vc = v - v.mean()
    t = max(0.0, float(vc @ (s - s.mean()) / (vc @ vc)))
    v_cal = cal_feed * cal_override / 100.0 / 60.0
    return t, float((v[-1] - v_cal) * t)

"""Finishers of tool measuring in JOG: ``toolprobe.calibrate``, ``tool.length``, ``tool.diameter``.

Spec: spec/jog-measuring.md §7.2/jog-measuring §7.3 (+ jog-measuring §8.3 E_MESS_MT_*), measuring-math §14; the math is
engine.toolmeasure. The points come from engine.plan_tool (tool tip in MCS at the latch).

- Calibration writes the tool-probe record ``_TP[n]`` (``app.records.ToolProbeData``):
  trigger values per travel direction (tool edge at switching, MCS), how it was calibrated
  (tool, feed, override, time) and the E_MESS_MT_* data it was calibrated with.
- Length / diameter write the active tool's offset (jog-measuring §7.3, _JM_B[0]): ``geometry`` ->
  geometry := measured, the wear of that component := 0; ``wear`` -> wear := measured − geometry.
  The API parameter ``compensation`` overrides the setting ``tool_offset_mode`` (_JM_B[0]).

Latch delay (design.md §5 flying measurement): the stages of the final probing give the signal
delay and measurement and calibration are referred to feed 0; the math is
``engine.toolmeasure.latch_delay_correction``, the finisher hands it the stages' latches.
"""

from __future__ import annotations

from datetime import UTC, datetime

from pydantic import ValidationError

from app.records import ToolData, ToolProbeData
from app.workflow.context import MeasuringContext
from app.workflow.planning import active_tool, tool_probe_widths
from app.workflow.session import MeasureSession
from engine import alarms
from engine.plan_base import ToolPoint, ToolProbePoint
from engine.toolmeasure import (
    calibrate_tool_probe_point,
    latch_delay_correction,
    tool_offset_update,
    tool_point_value,
)
from engine.types import MeasuringError

TOOL_KEYS = ("t", "name", "type", "length", "radius", "wear")


def _now() -> str:
    return datetime.now(UTC).isoformat(timespec="seconds")


def _point(session: MeasureSession, points: list, kind: type):
    point = points[0] if points else None
    if not isinstance(point, kind):
        raise MeasuringError(alarms.PROBE_NOT_SWITCHED, f"{session.task}: no measured point stored")
    return point


def _tool_probe_number(ctx: MeasuringContext) -> int:
    return int(ctx.extra.get("tool_probe_number") or ctx.settings.tool_probe_number)


def _validated_tool_probe(record: dict) -> dict:
    return ToolProbeData.model_validate(record).model_dump(mode="json")


def _validated_tool(row: dict) -> dict:
    try:
        return ToolData.model_validate(row).model_dump()
    except ValidationError as exc:
        first = exc.errors()[0]
        where = ".".join(str(p) for p in first["loc"])
        raise MeasuringError(alarms.SAFE_AREA, f"Measured tool data out of range ({where}: {first['msg']}): "
                                    "check the tool probe calibration and the tool") from None


# --- tool probe calibration (jog-measuring §7.2, measuring-math §14.5) --------------------------------------------

def finish_toolprobe_calibrate(session: MeasureSession, ctx: MeasuringContext, points: list
                               ) -> tuple[dict, dict]:
    tool = active_tool(ctx)
    point = _point(session, points, ToolProbePoint)
    n = _tool_probe_number(ctx)
    stored = dict(ctx.extra.get("tool_probe") or {})
    old_trigger = {k: float(v) for k, v in (stored.get("trigger") or {}).items()}
    trigger, values = calibrate_tool_probe_point(point, ctx.plane, old_trigger)
    s = ctx.settings
    diameter_mode = point.mode == "length_diameter"
    a, o = ctx.plane.first, ctx.plane.second
    measured_keys = {touch.key for touch in point.touches}
    width = {axis: trigger[f"{axis}-"] - trigger[f"{axis}+"] for axis in (a, o)
             if f"{axis}-" in measured_keys and f"{axis}+" in measured_keys}
    disc = float(stored.get("disc_diameter") or 0.0)
    if disc <= 0.0 and width:                  # not entered: the measured probe width (1st axis)
        disc = float(width.get(a, next(iter(width.values()))))
    feeds = [t.feed for t in point.touches if t.feed > 0.0]
    record = {
        **{k: v for k, v in stored.items() if k != "number"},
        "number": n,
        "trigger": trigger,
        "disc_diameter": disc,
        "axes": int(s.mt_ax),
        "type": int(s.mt_type),
        "dz": float(s.mt_dz),
        "calibrated_length": True,
        "calibrated_diameter": bool(stored.get("calibrated_diameter")) or diameter_mode,
        "calibration_tool": int(tool["t"]),
        "calibration_feed": float(feeds[-1]) if feeds else float(s.mt_fm),
        "calibration_override": float(ctx.feed_override),
        "calibrated_at": _now(),
    }
    record = _validated_tool_probe(record)
    result = {"tool_probe": record, "mode": point.mode, "difference": values["difference"],
              "center": values["center"], "width": width,
              "calibration_tool": {"t": int(tool["t"]), "length": float(point.tool_length),
                                   "radius": float(point.tool_radius)}}
    answer = {"result": result,
              "correction": {"target": f"TP{n}", "before": old_trigger or None, "after": record["trigger"]},
              "activated": False, "setup_support": None}
    return answer, {"offset": None, "tool_probe_update": (n, record)}


# --- latch delay (math in engine.toolmeasure.latch_delay_correction) -----------------------------

def latch_correction(session: MeasureSession, point: ToolPoint, record: dict, ctx: MeasuringContext) -> dict:
    """value* = value + (v_meas − v_cal)·t from the final probing's stages (module docstring)."""
    override = float(ctx.feed_override)
    stages = session.slots[0].raw[-len(point.feeds):]
    tips = [r.get("rec") if r.get("triggered") else None for r in stages]
    cal_feed = float(record.get("calibration_feed") or ctx.settings.mt_fm)
    cal_override = record.get("calibration_override")
    t, correction = latch_delay_correction(tips, point.touch.key, point.feeds, override, cal_feed,
                                           override if cal_override is None else float(cal_override))
    return {"delay_s": t, "feed": float(point.feeds[-1]), "calibration_feed": cal_feed,
            "correction": correction}


# --- tool length / radius (jog-measuring §7.3, measuring-math §14.4) -----------------------------------------------

def finish_tool_measure(session: MeasureSession, ctx: MeasuringContext, points: list) -> tuple[dict, dict]:
    tool = active_tool(ctx)
    point = _point(session, points, ToolPoint)
    record = dict(ctx.extra.get("tool_probe") or {})
    trigger = {k: float(v) for k, v in (record.get("trigger") or {}).items()}
    name = "length" if point.kind == "length" else "radius"
    latch = latch_correction(session, point, record, ctx)
    measured = tool_point_value(point, trigger, ctx.plane) + latch["correction"]
    if measured <= 0.0:
        raise MeasuringError(alarms.SAFE_AREA, f"Measured {name} {measured:.4f} mm is not positive: check the tool "
                                    "probe calibration and the start position")
    mode = session.params.get("compensation") or ctx.settings.tool_offset_mode
    wear = dict(tool.get("wear") or {})
    update = tool_offset_update(measured, float(tool.get(name, 0.0)), float(wear.get(name, 0.0)), mode)
    row = {k: v for k, v in tool.items() if k in TOOL_KEYS}
    wear_before = {"length": float(wear.get("length", 0.0)), "radius": float(wear.get("radius", 0.0))}
    before = {"length": float(tool.get("length", 0.0)), "radius": float(tool.get("radius", 0.0)),
              "wear": wear_before}
    row["wear"] = dict(wear_before)
    row[name] = update["geometry"]
    row["wear"][name] = update["wear"]
    row = _validated_tool(row)
    t = int(row["t"])
    after = {"length": row["length"], "radius": row["radius"], "wear": dict(row["wear"])}
    dl, _dr = tool_probe_widths(ctx.settings, record)
    result = {name: measured, "tool": {"t": t, **after}, "mode": mode, "delta": update["delta"],
              "spindle": {"rotating": bool(point.rotating), "speed": float(point.speed),
                          "feeds": [float(f) for f in point.feeds]},
              "offset_v": float(point.offset_v), "lateral_offset": float(point.lateral_offset),
              "probe_width_length": dl, "latch": latch}
    if name == "radius":
        result["diameter"] = 2.0 * measured
    answer = {"result": result, "correction": {"target": f"T{t}", "before": before, "after": after},
              "activated": False, "setup_support": None}
    return answer, {"offset": None, "tool_update": (t, row)}

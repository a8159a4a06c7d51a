"""Workpiece measuring with automatic tool offset (manual §1.9–§1.11, §2.3; design.md §9.3).

The measured feature's size (bore, shaft, rectangle, slot/web width) or position (set edge)
goes through the tolerance and mean-value strategy (``engine.strategy``, measuring-math §3.5)
and, where it decides so, into the wear or geometry of tool T (``engine.tool_offset``,
measuring-math §2.3). Decision and write are made inside the write transaction, from the
tool data and the EV/MV memories as stored then (``ToolOffsetChange``), like a zero offset.
"""

from __future__ import annotations

from collections.abc import Callable

from app.gud import GudSettings
from app.workflow.context import MeasuringContext, ToolOffsetChange, ToolOffsetOutcome
from app.workflow.session import MeasureSession
from engine import alarms
from engine.evaluate import line_unit
from engine.planes import Plane
from engine.strategy import Decision, Tolerance, decide_tool_offset, repeat_measurement
from engine.tasks import evaluate
from engine.tool_offset import tool_offset_update
from engine.types import EdgePoint, MeasuringError

TOOL_TARGET_KEYS = ("tool", "edge", "correct", "mode")


def tolerance_defaults(settings: GudSettings, setpoint: float = 0.0) -> Tolerance:
    """The settings' tolerance parameters (design.md §9.3: missing keys come from the settings)."""
    return Tolerance(setpoint=setpoint, upper=settings.tol_upper, lower=settings.tol_lower,
                     zero_range=settings.tol_zero_range, mean_range=settings.tol_mean_range,
                     dim_difference=settings.tol_dim_difference, safe_area=settings.tol_safe_area,
                     k=settings.tol_k, evnum=settings.tol_evnum, keep_mean=settings.tol_keep_mean)


def tool_target(value: dict) -> dict:
    """design.md §9.3 ``target`` object, normalised; ValueError naming the key."""
    unknown = sorted(set(value) - set(TOOL_TARGET_KEYS))
    if unknown:
        raise ValueError(f"target.{unknown[0]}: unknown key (use {', '.join(TOOL_TARGET_KEYS)})")
    t = value.get("tool")
    if isinstance(t, bool) or not isinstance(t, int) or not 1 <= t <= 9999:
        raise ValueError("target.tool: a tool number 1..9999 is required")
    edge = value.get("edge", 1)
    if isinstance(edge, bool) or edge != 1:
        raise ValueError("target.edge: the tool table holds one cutting edge per tool (D1)")
    correct = value.get("correct", "radius")
    if correct not in ("radius", "length"):
        raise ValueError("target.correct: must be radius or length")
    mode = value.get("mode", "wear")
    if mode not in ("wear", "geometry"):
        raise ValueError("target.mode: must be wear or geometry")
    return {"tool": t, "edge": 1, "correct": correct, "mode": mode}


def target_label(target: dict) -> str:
    """The log's short target column: "T20 D1 radius"."""
    return f"T{target['tool']} D{target['edge']} {target['correct']}"


# --- what each task measures (measuring-math §8.3, measuring-math §9.1) ---------------------------------------

def _feature(task: str, params: dict, values: dict, points: list, plane: Plane
             ) -> tuple[str, float, float | None, int | None]:
    """(feature kind, actual value, default setpoint, probing direction ±1 or None)."""
    if task in ("hole.1", "spigot.1"):
        return ("bore" if task == "hole.1" else "shaft"), float(values["diameter"]), params.get("diameter"), None
    if task in ("pocket.rect", "spigot.rect"):
        if params.get("length") is None or params.get("width") is None:
            raise ValueError("length and width are the setpoints of a tool offset: enter both")
        mean_difference = ((values["length"] - params["length"]) + (values["width"] - params["width"])) / 2.0
        return ("inner_rectangle" if task == "pocket.rect" else "outer_rectangle"), mean_difference, 0.0, None
    if task == "edge.distance":
        unit = _axis_unit(params["axis"]) if params.get("line_angle") is None else \
            line_unit(plane, float(params["line_angle"]))          # CYCLE979 slot/web (measuring-math §10.2)
        e1, e2 = (float(p.touch.surface @ unit) for p in points if isinstance(p, EdgePoint))
        d1 = 1 if params["direction"] == "+" else -1
        inner = d1 * (e1 - e2) > 0.0          # the wall reached travelling + lies on the + side: a slot
        return ("slot" if inner else "web"), abs(e2 - e1), None, None
    if task == "edge.set":
        axis = params["axis"]
        return "surface", float(values["position"][axis]), float(params["setpoint"][axis]), \
            (1 if params["direction"] == "+" else -1)
    raise ValueError(f"{task} does not correct tools")


def _axis_unit(axis: str):
    import numpy as np

    unit = np.zeros(3)
    unit["XYZ".index(axis)] = 1.0
    return unit


def finish_tool_offset(session: MeasureSession, ctx: MeasuringContext, points: list) -> tuple[dict, dict]:
    result = evaluate(session.task, session.params, points, ctx.plane, ctx.probe)
    target = session.target
    assert isinstance(target, dict), "a WO target is finished by finish.finish_workpiece"
    try:
        feature, actual, default_setpoint, direction = _feature(session.task, session.params, result.values, points, ctx.plane)
        tolerance = Tolerance.from_params(session.params.get("tolerance"),
                                          tolerance_defaults(ctx.settings, default_setpoint or 0.0))
    except ValueError as exc:
        raise MeasuringError(alarms.WRONG_VARIANT, str(exc)) from None
    if "setpoint" not in (session.params.get("tolerance") or {}) and default_setpoint is None:
        raise MeasuringError(alarms.WRONG_VARIANT, f"{feature}: tolerance.setpoint (the nominal width) is required")
    settings: GudSettings = ctx.settings
    repetitions = int(session.repetitions)

    def compute(tool_row: dict, memory: Callable[[str, int], float]) -> ToolOffsetOutcome:
        memories = tolerance.memories
        ev = memory("EV", memories.ev) if memories.ev else 0.0
        mv_old = memory("MV", memories.mv) if memories.mv and tolerance.keep_mean else 0.0
        decision = decide_tool_offset(actual, tolerance, ev=ev, mv_old=mv_old, ev_add=settings.ev_add)
        action = repeat_measurement(decision.violation, repetitions, repeat=settings.repeat_on_violation)
        alarm = action.alarm if decision.violation else decision.alarm
        measured = {**result.values, "deviation": decision.deviation, "mean_value": decision.mean_value,
                    "decision": decision.decision, "actual": decision.actual, "setpoint": decision.setpoint,
                    "upper": decision.upper, "lower": decision.lower, "feature": feature}
        if action.abort:        # 61303 / 61306: the cycle aborts, nothing is written (measuring-math §3.5, measuring-math §3.6)
            assert action.alarm is not None, "an aborting repeat action carries its alarm"
            # the refusal keeps what was measured (design.md §10.2): the 409 and the log carry it
            raise MeasuringError(action.alarm, f"{_words(decision)}: no correction",
                                 result={**measured, "alarm": {"code": action.alarm.number, "text": action.alarm.text}})
        update = tool_offset_update(tool_row, decision, feature, correct=target["correct"], mode=target["mode"],
                                    direction=direction)
        writes = {}
        if decision.mv_memory is not None and memories.mv:
            writes[("MV", memories.mv)] = decision.mv_memory
        keys = {"deviation": decision.deviation, "mean_value": decision.mean_value, "decision": decision.decision,
                "compensation": update.compensation,
                "alarm": None if alarm is None else {"code": alarm.number, "text": alarm.text},
                "actual": decision.actual, "setpoint": decision.setpoint, "upper": decision.upper,
                "lower": decision.lower, "empirical_value": decision.empirical_value,
                "mv_old": decision.mv_old, "feature": feature, "repeat": action.repeat}
        correction = {"target": target_label(target), "tool": target, "before": update.before, "after": update.after}
        return ToolOffsetOutcome(tool=target["tool"], after=update.after if update.written else None,
                                 memories=writes, result=keys, correction=correction, repeat=action.repeat)

    answer = {"result": result.values, "activated": False, "setup_support": None}
    return answer, {"offset": None, "tool_offset": ToolOffsetChange(target["tool"], compute)}


def _words(decision: Decision) -> str:
    return {"safe_area": f"Deviation {decision.deviation:.4f} mm beyond the safe area",
            "dimension_difference": f"Deviation {decision.deviation:.4f} mm beyond the dimension difference"
            }.get(decision.decision, decision.decision)

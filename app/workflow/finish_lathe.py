"""The lathe tasks through the workflow (turning.md §10.2): context, finishers, the commit.

The engine's task layer is ``engine.turning_plan`` (params -> cycle call -> point program ->
evaluation); this module joins it to the app:

- ``lathe_context``: the ``engine.turning.LatheContext`` of a measuring context: the tool in the
  turret (the tool table row: type, SL, L1, L2, radius, wear), the tool probe records ``_TP``
  (``trigger``) and ``_TPW`` (``workpiece_trigger``), the probe records ``_WP`` (``trigger``,
  ``effective_diameter``, ``position_deviation``), the reference grooves ``_KB``, DIAMON, Y,
  SPOS capability, and the channel bits the settings give (_CHBIT[5] ev_add, [15] attempts,
  [16] rapid_return, [17] two_stage; _SPEED[1]/[2] position_feed, [3] fast_feed).
- ``lathe_finisher(finish_toolprobe | finish_tool | finish_probe | finish_workpiece)``: the
  finisher of a lathe task, named by its entry in app.workflow.tasks: (answer, commit) as the
  milling finishers. Tool probe calibration writes ``_TP[k]``/``_TPW[k]`` (``tool_probe_update``);
  tool measuring decides inside the write transaction from the tool data and the EV memory as
  stored then (``ToolOffsetChange``); probe calibration writes ``_WP[k]`` (``probe_update``);
  a 1-point ZO (``lathe.point`` with a WO target) goes through ``engine.correction.correct``
  (``OffsetChange``) into the frame as stored then; a 1-/2-point tool offset decides with the
  mean-value strategy (``engine.strategy.decide_tool_offset``, the milling one) inside the
  transaction and writes the turning.md §0.11 compensation (``ToolOffsetChange``).

Units (turning.md §10.2): results on X with DIAMON are diameters where the cycle reports them
so (``actual``, ``diameter``, ``deviation``, ``mean_value``, the 974/994 bands and their EV/MV
memories); ``compensation``, tool, probe, groove and tool-probe data are radius values.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from datetime import UTC, datetime
from typing import Any

import numpy as np
from pydantic import ValidationError

from app.records import ProbeData, ToolProbeData
from app.workflow.context import (
    MEASURE_ONLY,
    MeasuringContext,
    OffsetChange,
    OffsetOutcome,
    ToolOffsetChange,
    ToolOffsetOutcome,
)
from app.workflow.finish import _activation
from app.workflow.session import MeasureSession
from engine import alarms
from engine.correction import correct
from engine.frames import Frame, parent2bcs_of
from engine.planes import plane as plane_by_name
from engine.strategy import Tolerance, decide_tool_offset
from engine.turning import LatheContext, LatheProbe, LatheTool, ev_mv_numbers, measuring_feed
from engine.turning_plan import LathePrep, evaluate_lathe, finish_lathe, prepare
from engine.turning_probe import ProbeCalibrationResult
from engine.turning_tools import Cycle982, ToolProbeResult, ToolResult
from engine.turning_workpiece import WorkpieceCall
from engine.types import FeatureFix, MeasuringError

G18 = plane_by_name("G18")
WARNINGS = {"oversize", "undersize", "dimension_difference"}


def _now() -> str:
    return datetime.now(UTC).isoformat(timespec="seconds")


# --- the context ---------------------------------------------------------------------------------

def lathe_extra(ctx: MeasuringContext) -> dict:
    extra = (ctx.extra or {}).get("lathe")
    if extra is None:
        raise MeasuringError(alarms.WRONG_VARIANT, "the lathe tasks run on a lathe (machine.kind \"lathe\")")
    return extra


def lathe_tool(row: Mapping | None) -> LatheTool | None:
    """The engine's tool data of a tool table row (one cutting edge D1 per tool)."""
    if not row:
        return None
    wear = dict(row.get("wear") or {})
    return LatheTool(t=int(row["t"]), d=1, type=int(row.get("type", 500)), sl=int(row.get("sl") or 0),
                     l1=float(row.get("l1") or 0.0), l2=float(row.get("l2") or 0.0),
                     radius=float(row.get("radius") or 0.0), wear_l1=float(wear.get("l1") or 0.0),
                     wear_l2=float(wear.get("l2") or 0.0), wear_radius=float(wear.get("radius") or 0.0))


def _by_number(records: list[dict]) -> list[dict]:
    out: list[dict] = []
    for record in sorted(records, key=lambda r: int(r.get("number", 0))):
        n = int(record.get("number", 0))
        while len(out) < n - 1:
            out.append({})
        if n >= 1:
            out.append(record)
    return out


def kb_tuple(values: Mapping) -> tuple[float, ...]:
    """The 7 values _KB[k,0..6] of a groove record as entered (0 = not entered, turning.md §0.6)."""
    g = dict(values or {})
    return (g.get("x_plus", 0.0), g.get("x_minus", 0.0), g.get("bottom_z", 0.0), g.get("z_plus", 0.0),
            g.get("z_minus", 0.0), g.get("top_x", 0.0), g.get("bottom_x", 0.0))


def probe_record(data: Mapping) -> LatheProbe:
    return LatheProbe(number=int(data.get("number", 1)),
                      effective_diameter=float(data.get("effective_diameter") or 0.0),
                      trigger={k: float(v) for k, v in (data.get("trigger") or {}).items()},
                      skew={k: float(v) for k, v in (data.get("position_deviation") or {}).items()})


def lathe_context(ctx: MeasuringContext) -> LatheContext:
    """The LatheContext of a measuring context (module docstring)."""
    lx = lathe_extra(ctx)
    s = ctx.settings
    chbit = {5: int(bool(s.ev_add)), 15: int(int(s.attempts) == 1), 16: int(bool(s.rapid_return)),
             17: int(bool(s.two_stage))}
    tool_probes = _by_number(lx.get("tool_probes") or [])
    rotation = ctx.chain().wcs2bcs.rotation
    return LatheContext(
        chbit=chbit, speed=(50.0, float(s.position_feed), float(s.position_feed), float(s.fast_feed)),
        diamon=bool(lx["diamon"]), has_y=bool(lx["has_y"]), spos=bool(lx["spos"]),
        rotation_active=bool(np.max(np.abs(np.asarray(rotation) - np.eye(3))) > 1e-12),
        tool=lathe_tool(ctx.tool),
        tp=tuple({k: float(v) for k, v in (r.get("trigger") or {}).items()} for r in tool_probes),
        tpw=tuple({k: float(v) for k, v in (r.get("workpiece_trigger") or {}).items()} for r in tool_probes),
        wp=tuple(probe_record(r) for r in _by_number(lx.get("probes") or [])),
        kb=tuple(kb_tuple(g) for g in (lx.get("grooves") or [])),
    )


def lathe_prep(session: MeasureSession, ctx: MeasuringContext) -> LathePrep:
    return prepare(session.task, session.params, lathe_context(ctx))


def memory_value(ctx: MeasuringContext, kind: str, n: int) -> float:
    """An EV/MV memory as it was at NC Start (0 = never written)."""
    memories = (lathe_extra(ctx).get("memories") or {}).get(kind) or {}
    return float(memories.get(n, memories.get(str(n), 0.0)))


# --- tool data rows <-> the engine's tool dicts ------------------------------------------------------

def _row_after(row: Mapping, engine_after: Mapping) -> dict:
    """The tool table row with the engine's lengths/radius and their wear written in."""
    out = {k: v for k, v in dict(row).items() if k in ("t", "name", "type", "length", "radius", "wear", "sl", "l1",
                                                          "l2")}
    wear = dict(out.get("wear") or {})
    out["l1"], out["l2"], out["radius"] = (float(engine_after["l1"]), float(engine_after["l2"]),
                                           float(engine_after["radius"]))
    w = engine_after.get("wear") or {}
    wear.update(l1=float(w.get("l1", 0.0)), l2=float(w.get("l2", 0.0)), radius=float(w.get("radius", 0.0)))
    out["wear"] = {"length": float(wear.get("length", 0.0)), **wear}
    out["sl"] = int(row.get("sl") or engine_after.get("sl") or 0)
    return out


def _lathe_view(row: Mapping) -> dict:
    """What a correction shows of a tool: L1, L2, R and their wear (radius values)."""
    wear = dict(row.get("wear") or {})
    return {"l1": float(row.get("l1") or 0.0), "l2": float(row.get("l2") or 0.0), "radius": float(row.get("radius")
                                                                                                     or 0.0),
            "wear": {"l1": float(wear.get("l1") or 0.0), "l2": float(wear.get("l2") or 0.0),
                     "radius": float(wear.get("radius") or 0.0)}, "sl": int(row.get("sl") or 0)}


def target_label(target) -> str:
    if isinstance(target, dict):
        return f"T{target['tool']} D{target.get('edge', 1)} {target.get('correct', 'length')}"
    return str(target)


# --- the finisher --------------------------------------------------------------------------------

LatheEvaluator = Callable[[MeasureSession, LathePrep, Any, MeasuringContext], tuple[dict, dict]]


def lathe_finisher(evaluate: LatheEvaluator) -> Callable[[MeasureSession, MeasuringContext, list],
                                                         tuple[dict, dict]]:
    """The finisher of a lathe task (its entry in app.workflow.tasks names its ``evaluate``)."""
    def finish(session: MeasureSession, ctx: MeasuringContext, points: list) -> tuple[dict, dict]:
        point = points[0] if points else None
        if point is None:
            raise MeasuringError(alarms.PROBE_NOT_SWITCHED, f"{session.task}: no measured point stored")
        return evaluate(session, lathe_prep(session, ctx), point, ctx)

    return finish


def _answer(result: dict, correction: dict | None = None) -> dict:
    return {"result": result, "correction": correction, "activated": False, "setup_support": None}


def finish_toolprobe(session: MeasureSession, prep: LathePrep, point, ctx: MeasuringContext) -> tuple[dict, dict]:
    ev = evaluate_lathe(prep, point)
    r = ev.result
    assert isinstance(r, ToolProbeResult), "a CYCLE982 calibration evaluates to a ToolProbeResult"
    n = int(ev.values["tool_probe"]["number"])
    workpiece = ev.values["tool_probe"]["reference"] == "workpiece"
    stored = next((dict(x) for x in lathe_extra(ctx).get("tool_probes") or [] if int(x.get("number", 0)) == n), {})
    field = "workpiece_trigger" if workpiece else "trigger"
    before = dict(stored.get(field) or {})
    tool_t = (ctx.tool or {}).get("t")
    record = {**{k: v for k, v in stored.items() if k != "number"}, "number": n, field: dict(r.record),
              "calibrated_length": True, "calibration_tool": int(tool_t) if tool_t else None,
              "calibration_feed": measuring_feed(prep.call.vms, prep.call.fa),
              "calibrated_at": _now()}
    record = ToolProbeData.model_validate(record).model_dump(mode="json")
    result = {**ev.values, "ovr": list(r.ovr), "ovi": list(r.ovi), "product_extension": True}
    target = f"{'TPW' if workpiece else 'TP'}{n}"
    return _answer(result, {"target": target, "before": before or None, "after": record[field], "lathe": True,
                            "record": True}), \
        {"offset": None, "tool_probe_update": (n, record)}


def finish_tool(session: MeasureSession, prep: LathePrep, point, ctx: MeasuringContext) -> tuple[dict, dict]:
    call = prep.call
    assert isinstance(call, Cycle982), "the lathe tool tasks run CYCLE982"
    tool = ctx.tool or {}
    t = int(tool.get("t", 0))
    if not t:
        raise MeasuringError(alarms.NO_D_NUMBER, "no tool active")
    ev_no = ev_mv_numbers(call.evnum)[0] if call.evnum else 0

    def compute(row: dict, memory: Callable[[str, int], float]) -> ToolOffsetOutcome:
        ev_value = memory("EV", ev_no) if ev_no else 0.0
        evaluation = evaluate_lathe(prep, point, ev=ev_value)
        r = evaluation.result
        assert isinstance(r, ToolResult), "a CYCLE982 tool measurement evaluates to a ToolResult"
        after = _row_after(row, r.after) if r.written else None
        result = {**evaluation.values, "ovr": list(r.ovr), "ovi": list(r.ovi),
                  "empirical_value": ev_value, "product_extension": True}
        if r.alarm is not None:
            result["alarm"] = {"code": r.alarm.number, "text": r.alarm.text}
        correction = {"target": f"T{t} D1", "before": _lathe_view(row), "after": _lathe_view(after or row),
                      "written": list(r.written), "lathe": True, "record": True}
        return ToolOffsetOutcome(tool=t, after=after, memories={}, result=result, correction=correction)

    return _answer({}), {"offset": None, "tool_offset": ToolOffsetChange(t, compute)}


def finish_probe(session: MeasureSession, prep: LathePrep, point, ctx: MeasuringContext) -> tuple[dict, dict]:
    ev = evaluate_lathe(prep, point)
    r = ev.result
    assert isinstance(r, ProbeCalibrationResult), "a CYCLE973 calibration evaluates to a ProbeCalibrationResult"
    record: LatheProbe = r.record
    n = int(record.number) or 1
    stored = next((dict(x) for x in lathe_extra(ctx).get("probes") or [] if int(x.get("number", 0)) == n), {})
    tool = ctx.tool or {}
    ball = 2.0 * float(tool.get("radius") or 0.0) or float(stored.get("ball_diameter") or 6.0)
    data = {**{k: v for k, v in stored.items() if k != "number"}, "number": n, "ball_diameter": ball,
            "trigger": {k: float(v) for k, v in record.trigger.items() if float(v) != 0.0},
            "effective_diameter": float(record.effective_diameter),
            "position_deviation": {a: float(record.skew.get(a, 0.0)) for a in ("Z", "X")},
            "tool": int(tool["t"]) if tool.get("t") else stored.get("tool"), "calibrated_plane": "G18",
            # the directions calibrated so far: the lathe tasks use their trigger values (probe_trust)
            "calibrated_directions": sorted(set(stored.get("calibrated_directions") or ()) | set(r.trigger)),
            "calibrated_at": _now()}
    try:
        data = ProbeData.model_validate(data).model_dump(mode="json")
    except ValidationError as exc:
        first = exc.errors()[0]
        raise MeasuringError(alarms.SAFE_AREA, f"Probe record out of range ({'.'.join(map(str, first['loc']))}: "
                                               f"{first['msg']}): check the groove data and the probe") from None
    before = {"trigger": dict(stored.get("trigger") or {}), "effective_diameter": stored.get("effective_diameter"),
              "position_deviation": stored.get("position_deviation")}
    after = {"trigger": data["trigger"], "effective_diameter": data["effective_diameter"],
             "position_deviation": data["position_deviation"]}
    result = {**ev.values, "ovr": list(r.ovr), "ovi": list(r.ovi), "product_extension": True}
    return _answer(result, {"target": f"WP{n}", "before": before, "after": after, "lathe": True, "record": True}), \
        {"offset": None, "probe_update": (n, data)}


def _tolerance(prep: LathePrep) -> Tolerance:
    """The call's bands as the strategy's Tolerance (display units of the measuring axis)."""
    c = prep.call
    assert isinstance(c, WorkpieceCall), "only the workpiece tasks (974/994) have tolerance bands"
    k = float(c.k)
    if k != int(k) or k < 1:
        raise MeasuringError(alarms.WEIGHTING_FACTOR, f"_K = {k:g}: the weighting factor is a whole number >= 1")
    return Tolerance(setpoint=c.setval, upper=c.tul, lower=c.tll, zero_range=c.tzl, mean_range=c.tmv,
                     dim_difference=c.tdif, safe_area=c.tsa, k=int(k), evnum=int(c.evnum),
                     keep_mean=prep.ctx.bit(4))


def finish_workpiece(session: MeasureSession, prep: LathePrep, point, ctx: MeasuringContext) -> tuple[dict, dict]:
    call = prep.call
    assert isinstance(call, WorkpieceCall), "lathe.point / lathe.two_point run CYCLE974/994"
    ev_no, mv_no = ev_mv_numbers(call.evnum) if call.evnum else (0, 0)
    if prep.zero_offset:
        return _zero_offset(session, prep, point, ctx, memory_value(ctx, "EV", ev_no) if ev_no else 0.0)
    target = session.target
    if not isinstance(target, dict):                    # measure only: the decision is shown, nothing written
        ev_value = memory_value(ctx, "EV", ev_no) if ev_no else 0.0
        mv_old = memory_value(ctx, "MV", mv_no) if mv_no and prep.ctx.bit(4) else 0.0
        evaluation = evaluate_lathe(prep, point, ev=ev_value)
        assert evaluation.measurement is not None, "974/994 without a ZO target leave the decision to the strategy"
        decision = decide_tool_offset(evaluation.measurement.actual, _tolerance(prep), ev=ev_value, mv_old=mv_old,
                                      ev_add=prep.ctx.bit(5))
        result = {**evaluation.values, "decision": decision.decision, "mean_value": decision.mean_value,
                  "compensation": 0.0, "empirical_value": ev_value, "product_extension": True}
        return _answer(result, {"target": MEASURE_ONLY, "before": None, "after": None}), {"offset": None}
    t = int(target["tool"])

    def compute(row: dict, memory: Callable[[str, int], float]) -> ToolOffsetOutcome:
        ev_value = memory("EV", ev_no) if ev_no else 0.0
        mv_old = memory("MV", mv_no) if mv_no and prep.ctx.bit(4) else 0.0
        evaluation = evaluate_lathe(prep, point, ev=ev_value)
        m = evaluation.measurement
        assert m is not None, "974/994 without a ZO target leave the decision to the strategy"
        decision = decide_tool_offset(m.actual, _tolerance(prep), ev=ev_value, mv_old=mv_old, ev_add=prep.ctx.bit(5))
        if decision.decision == "safe_area":
            raise MeasuringError(alarms.SAFE_AREA, f"Deviation {decision.deviation:+.4f} beyond the safe area "
                                                   f"_TSA {call.tsa:g}: no correction")
        warning = decision.alarm if decision.decision in WARNINGS else None
        tool = lathe_tool(row)
        if tool is None or row.get("l1") is None:
            raise MeasuringError(alarms.TOOL_NUMBER, f"T{t} is not a lathe tool (no L1/L2 in the tool table)")
        r = finish_lathe(prep, evaluation, decision=decision.decision, amount=decision.corrected,
                         mean_value=decision.mean_value, warning=warning, tool=tool)
        after = _row_after(row, r.tool_after) if r.tool_after is not None else None
        writes = {}
        if decision.mv_memory is not None and mv_no:
            writes[("MV", mv_no)] = decision.mv_memory
        result = {**r.values, "mean_value": decision.mean_value, "empirical_value": ev_value,
                  "mv_old": decision.mv_old, "setpoint_eff": decision.setpoint, "upper": decision.upper,
                  "lower": decision.lower, "ovr": list(r.ovr), "ovi": list(r.ovi), "product_extension": True,
                  "alarm": None if warning is None else {"code": warning.number, "text": warning.text}}
        result.pop("tool", None)
        correction = {"target": target_label(target), "tool": target, "before": _lathe_view(row),
                      "after": _lathe_view(after or row), "quantity": r.quantity, "lathe": True}
        return ToolOffsetOutcome(tool=t, after=after, memories=writes, result=result, correction=correction)

    return _answer({}), {"offset": None, "tool_offset": ToolOffsetChange(t, compute)}


def _zero_offset(session: MeasureSession, prep: LathePrep, point, ctx: MeasuringContext, ev_value: float
                 ) -> tuple[dict, dict]:
    """974 _MVAR=100: 100 % of D into the target's translation on the measuring axis (radius);
    written through engine.correction.correct, so that any target of the chain is right."""
    evaluation = evaluate_lathe(prep, point, ev=ev_value)
    values = dict(evaluation.values)
    result = {**values, "ovr": list(evaluation.ovr or []), "ovi": list(evaluation.ovi or []),
              "empirical_value": ev_value, "product_extension": True}
    target = prep.zero_offset
    assert target is not None, "called for a lathe.point with a zero offset target only"
    axis = values["frame_axis"]
    setpoint_r = float(values["setpoint_radius"])
    position = setpoint_r + float(values["compensation"])          # the measured point in radius
    fix = FeatureFix(position={axis: position})

    def compute(frames_now: Mapping[str, Frame]) -> OffsetOutcome:
        correction = correct(fix, setpoints={axis: setpoint_r}, setpoint_angle=None, target=target,
                             target_frame=frames_now[target], chain=ctx.chain(),
                             target_parent2bcs=parent2bcs_of(frames_now, target), plane=G18,
                             angle_correction="rotation")
        return OffsetOutcome(correction.before.to_api(), correction.after.to_api(),
                             {"task": session.task, "setpoints": {axis: setpoint_r}},
                             _activation(correction, target, ctx))

    return _answer(result), {"offset": OffsetChange(target, compute)}

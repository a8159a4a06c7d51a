"""Finishers: evaluate stored points and decide what to write (spec/jog-measuring.md §2-§4, §6.2).

A finisher returns ``(answer, commit)``: the calculate answer of design.md §4 and the keyword
arguments of ``WorkflowEnv.commit_measurement`` (offset, probe/tool records).
"""

from __future__ import annotations

from app.workflow.service import MEASURE_ONLY, MeasureSession, MeasuringContext, points_of
from engine.correction import correct
from engine.evaluate import evaluate


def setpoints_of(session: MeasureSession, plane_axes: tuple[str, ...]) -> dict[str, float]:
    """Setpoints keyed by axis name; a bare number belongs to the task's measuring axis."""
    params = session.params
    raw = params.get("setpoint", 0.0)
    if isinstance(raw, dict):
        return {str(k): float(v) for k, v in raw.items()}
    axis = params.get("axis")
    if axis:
        return {axis: float(raw)}
    return {a: float(raw) for a in plane_axes[:2]}


def finish_workpiece(session: MeasureSession, ctx: MeasuringContext) -> tuple[dict, dict]:
    result = evaluate(session.task, session.params, points_of(session), ctx.plane, ctx.probe)
    answer: dict = {"result": result.values, "activated": False, "setup_support": None}
    target = session.target
    if target == MEASURE_ONLY:
        answer["correction"] = {"target": MEASURE_ONLY, "before": None, "after": None}
        return answer, {"offset": None}

    before = ctx.offsets[target]
    angle_correction = session.params.get("angle_correction") or "rotation"
    correction = correct(
        result.fix,
        setpoints=setpoints_of(session, ctx.plane.axes),
        setpoint_angle=float(session.params.get("setpoint_angle", 0.0) or 0.0),
        target=target,
        target_frame=before,
        chain=ctx.chain(),
        target_parent2bcs=ctx.parent2bcs_of(target),
        plane=ctx.plane,
        angle_correction=angle_correction,
    )
    before_api, after_api = correction.before.to_api(), correction.after.to_api()
    answer["correction"] = {"target": target, "before": before_api, "after": after_api}
    if correction.rotary_axis:
        answer["correction"]["rotary_axis"] = correction.rotary_axis
        answer["correction"]["rotary_move"] = correction.rotary_move

    in_chain = ctx.in_chain(target)
    reasons = []
    if not in_chain and target != ctx.active_offset:
        reasons.append({"code": "inactive_wo", "text": "You are compensating in an inactive WO!",
                        "toggle": "Activate compensated WO"})
    if correction.tilts_infeed(ctx.plane):
        reasons.append({"code": "realign", "text": "The new WCS needs a new alignment!",
                        "toggle": "Re-align probe"})
    if correction.rotary_axis:
        reasons.append({"code": "rotary", "text": "Rotary axis must be positioned!",
                        "toggle": f"Position rotary axis {correction.rotary_axis}",
                        "axis": correction.rotary_axis, "move": correction.rotary_move})
    if reasons:
        answer["setup_support"] = {"target": target, "reasons": reasons,
                                   "message": "Press NC Start to activate!"}
    elif in_chain:
        answer["activated"] = True          # basic frames are always part of the active chain
        answer["_refresh_frames"] = True
    else:
        answer["activated"] = True          # target = WO active while measuring (spec §4.4)
        answer["_activate"] = target
    detail = {"task": session.task, "setpoints": setpoints_of(session, ctx.plane.axes)}
    return answer, {"offset": (target, before_api, after_api, detail)}


FINISHERS = {"workpiece": finish_workpiece}

"""Finishers: evaluate stored points and decide what to write (spec/jog-measuring.md §2-jog-measuring §4, jog-measuring §6.2).

A finisher gets the session, the measuring context and the stored points (all in that
context's WCS) and returns ``(answer, commit)``: the calculate answer of design.md §4 and the
keyword arguments of ``WorkflowEnv.commit_measurement`` (offset change, probe/tool records).
"""

from __future__ import annotations

from collections.abc import Mapping

from app.errors import WorkflowError
from app.workflow.context import MEASURE_ONLY, MeasuringContext, OffsetChange, OffsetOutcome
from app.workflow.session import MeasureSession
from engine.correction import correct
from engine.frames import Frame, is_basic, parent2bcs_of
from engine.tasks import evaluate


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


class FormErrorRefusal(WorkflowError):
    """409 ``form_error`` that keeps what was measured (design.md §10.2): ``extra.result``."""

    def __init__(self, values: dict, message: str, field: str):
        super().__init__(409, "form_error", message, field)
        self.extra["result"] = dict(values)


def check_form_error(params: dict, values: dict) -> None:
    """``params.max_form_error`` refuses the write above it (design.md §9.8); nothing is written."""
    limit = params.get("max_form_error")
    form_error = values.get("form_error")
    if limit is not None and form_error is not None and form_error > limit:
        raise FormErrorRefusal(values, f"Form error {form_error:.4f} mm of the fitted points is above "
                            f"the limit {limit:g} mm: nothing written. Check the points (a chip, a burr?) "
                            "and measure again", "max_form_error")


def finish_workpiece(session: MeasureSession, ctx: MeasuringContext, points: list) -> tuple[dict, dict]:
    """Evaluate now; the correction is computed inside the write transaction (``OffsetChange``)
    from the target as stored then, so a concurrent change of another component is kept."""
    result = evaluate(session.task, session.params, points, ctx.plane, ctx.probe)
    check_form_error(session.params, result.values)
    answer: dict = {"result": result.values, "activated": False, "setup_support": None}
    target = session.target
    assert isinstance(target, str), "a tool offset target is finished by finish_tool_offset"
    if target == MEASURE_ONLY:
        answer["correction"] = {"target": MEASURE_ONLY, "before": None, "after": None}
        return answer, {"offset": None}
    setpoints = setpoints_of(session, ctx.plane.axes)

    def compute(frames_now: Mapping[str, Frame]) -> OffsetOutcome:
        correction = correct(
            result.fix,
            setpoints=setpoints,
            setpoint_angle=float(session.params.get("setpoint_angle", 0.0) or 0.0),
            target=target,
            target_frame=frames_now[target],
            chain=ctx.chain(),                              # the chain the points were measured in
            target_parent2bcs=parent2bcs_of(frames_now, target),   # the target's parents as stored now
            plane=ctx.plane,
            angle_correction=session.params.get("angle_correction") or "rotation",
        )
        return OffsetOutcome(correction.before.to_api(), correction.after.to_api(),
                             {"task": session.task, "setpoints": setpoints},
                             _activation(correction, target, ctx))

    return answer, {"offset": OffsetChange(target, compute)}


def _activation(correction, target: str, ctx: MeasuringContext) -> dict:
    """The answer's correction, set-up support reasons and activation (jog-measuring §4.4, jog-measuring §6.2)."""
    out: dict = {"correction": {"target": target, "before": correction.before.to_api(),
                                "after": correction.after.to_api()},
                 "activated": False, "setup_support": None}
    if correction.rotary_axis:
        out["correction"]["rotary_axis"] = correction.rotary_axis
        out["correction"]["rotary_move"] = correction.rotary_move
    in_chain = is_basic(target)
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
        out["setup_support"] = {"target": target, "reasons": reasons, "message": "Press NC Start to activate!"}
    elif in_chain:
        out["activated"] = True          # basic frames are always part of the active chain
        out["_refresh_frames"] = True
    else:
        out["activated"] = True          # target = WO active while measuring (jog-measuring §4.4)
        out["_activate"] = target
    return out

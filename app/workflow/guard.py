"""The start guard in the workflow (issue 24 §1, design.md §10.1): before the first motion of a
point, its whole program is checked (``engine.guard``) against the machine's protection model;
a refused path answers 409 ``guard`` naming the alarm and the segment, and nothing moves.

The model comes from the machine (``protection_model()``: the simulator's is its work space); a
controller without one gives the verdict ``unknown`` for every positioning move, shown in the
plan and the session's warnings (never a silent pass). Tool measuring (the cutter, MCS
coordinates) and the lathe tasks are not checked: their plan says ``unknown``.
"""

from __future__ import annotations

import numpy as np

from app.errors import ConflictError
from app.machine.protocol import ProtectedSpace
from app.workflow.executor import StepExecutor
from engine import alarms
from engine.guard import GuardReport, Placement, Segment, check_program, segments_to_api
from engine.guard_model import model_from_data
from engine.plan import ideal_path
from engine.plan_workpiece import ball_offset
from engine.types import MoveStep, ProbeStep

UNKNOWN_WARNING = ("Start guard: the control has no model of the work space: the path is not "
                   "checked for collisions; watch the probe")


class GuardRefused(ConflictError):
    code = "guard"


def protection_data(machine) -> dict | None:
    """The control's model of its work space; None: it has none (the path is not checked)."""
    return machine.protection_model() if isinstance(machine, ProtectedSpace) else None


def guarded(spec) -> bool:
    """Workpiece-probe tasks in the WCS are checked; tool measuring and the lathe are not."""
    return bool(spec.needs_probe) and not getattr(spec, "lathe", False) and bool(getattr(spec, "guarded", True))


def check_point(machine, spec, params: dict, n: int, ctx) -> tuple[GuardReport, str]:
    """The guard's report of point ``n`` from where the probe stands now, and the coordinates."""
    plan_ctx = spec.plan_context(ctx, params)
    executor = StepExecutor(machine, ctx.chain().wcs2bcs, ctx.tool_length, ctx.plane.infeed_unit,
                            tip=spec.tool_tip(ctx))
    coords = spec.coords_for(params, plan_ctx)
    start = executor.current(coords)
    program = spec.program(params, n, start, plan_ctx)
    if not guarded(spec) or coords != "WCS":
        return _unknown(ideal_path(program, start)), coords
    wcs2bcs = ctx.chain().wcs2bcs
    tip = executor.tip_conversion
    placement = Placement(rotation=np.asarray(wcs2bcs.rotation, dtype=float),
                          ball_shift=np.asarray(wcs2bcs.child2parent(ball_offset(plan_ctx)), dtype=float),
                          axes_shift=np.asarray(tip.axes_for_tip(np.zeros(3), "WCS"), dtype=float),
                          ball_radius=float(plan_ctx.probe.ball_diameter) / 2.0)
    return check_program(program, start, model_from_data(protection_data(machine)), placement), coords


def _unknown(steps) -> GuardReport:
    segments: list[Segment] = []
    directions = []
    pos = None
    for step in steps:
        if isinstance(step, ProbeStep):
            directions.append(np.asarray(step.direction, dtype=float))
        if isinstance(step, MoveStep):
            target = np.asarray(step.target, dtype=float)
            segments.append(Segment(len(segments) + 1, step.label, "move", target if pos is None else pos,
                                    target, "unknown"))
            pos = target
        elif isinstance(step, ProbeStep) and pos is not None:
            end = pos + float(step.distance) * np.asarray(step.direction, dtype=float)
            segments.append(Segment(len(segments) + 1, step.label, "probe", pos, end, "unknown"))
            travel = step.expected if step.expected is not None else step.distance / 2.0
            pos = pos + float(travel) * np.asarray(step.direction, dtype=float)
    return GuardReport(tuple(segments), True, tuple(directions))


def ideal_directions(report: GuardReport) -> list[np.ndarray] | None:
    """The probing directions of the point's program driven with ideal latches
    (``probe_trust.probing_directions``), read from the guard's run of the same program when that
    run answered every probing move with a contact or its expected travel and ended: the
    program took the same branches. None: the guard's run cannot tell (run it with ideal latches)."""
    if not report.complete or any(s.kind == "probe" and s.verdict not in ("contact", "unknown")
                                  for s in report.segments):
        return None
    return list(report.probe_directions)


def refusal_error(report: GuardReport, n: int, axes: tuple[str, ...], params: dict) -> GuardRefused | None:
    seg = report.refusal
    if seg is None:
        return None
    label = seg.label or f"step {seg.index}"
    if seg.verdict == "limit":
        alarm = alarms.START_GUARD_LIMIT
        what = f"{label} would leave the travel range of axis {seg.axis}"
    else:
        alarm = alarms.START_GUARD_COLLISION
        at = seg.where if seg.where is not None else seg.end
        where = " ".join(f"{a}{float(v):.3f}" for a, v in zip(axes, at, strict=True))
        what = f"{label} would run into the {seg.body or 'material'} at {where} (WCS)"
        if "DZ" in label and params.get("infeed") is not None:
            what += f": infeed {float(params['infeed']):g} mm reaches below the {seg.body or 'feature'}"
    message = f"{alarm.number} {alarm.text}: {what}. Nothing moved."
    (segment,) = segments_to_api([seg], axes, point=n)
    return GuardRefused(message, code="guard", extra={
        "alarm": {"code": alarm.number, "text": alarm.text, "remedy": alarm.remedy},
        "segment": segment})


def plan_to_api(report: GuardReport, n: int, coords: str, axes: tuple[str, ...]) -> dict:
    refusal = report.refusal
    return {"point": n, "coords": coords, "segments": segments_to_api(report.segments, axes, point=n),
            "verdict": "refused" if refusal is not None else ("unknown" if report.unknown else "clear"),
            "refused_step": refusal.index if refusal is not None else None}

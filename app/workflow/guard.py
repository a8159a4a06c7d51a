"""The start guard in the workflow (issue 24 §1, design.md §10.1): before the first motion of a
point, its whole program is checked (``engine.guard``) against the machine's protection model;
a refused path answers 409 ``guard`` naming the alarm and the segment, and nothing moves.

The model comes from the machine (``protection_model()``: the simulator's is its work space); a
controller without one gives the verdict ``unknown`` for every positioning move, shown in the
plan and the session's warnings (never a silent pass). The lathe's workpiece-probe tasks are
checked against the lathe's model (the ball centre is the NC's P = F − (L1, 0, L2)). Tool
measuring (the cutter around the tool probe) and ``kinematics.measure`` are not checked for
collisions: their plan says ``unknown`` and NC Start warns (``NOT_MODELLED``).

Every task's probing moves are checked against the probe's own reach (measuring-math §1.3) when
the machine knows its braking (``ProbeReach``): braking behind the switch beyond the permissible
deflection is refused with 65302 before anything moves.
"""

from __future__ import annotations

import numpy as np

from app.errors import ConflictError
from app.i18n import N_
from app.machine.protocol import Machine, ProbeReach, ProtectedSpace
from app.workflow.executor import StepExecutor
from engine import alarms
from engine.guard import (
    Braking,
    GuardReport,
    Placement,
    ProtectionModel,
    Segment,
    check_program,
    probe_reach,
    segments_to_api,
)
from engine.guard_model import braking_from_data, model_from_data
from engine.plan import ideal_path
from engine.plan_workpiece import ball_offset
from engine.types import MoveStep, ProbeStep

UNKNOWN_WARNING = N_("Start guard: the control has no model of the work space: the path is not "
                     "checked for collisions; watch the probe")
NOT_MODELLED = {      # why a task's path is not checked for collisions (issue 24 §1: say so)
    "tool": N_("Start guard: tool measuring is not checked for collisions (the HMI has no model of the "
               "cutter around the tool probe); watch the tool"),
    "kinematics": N_("Start guard: the kinematics measurement is not checked for collisions (the guard "
                     "does not model the swivel moves); watch the probe"),
}


class GuardRefused(ConflictError):
    code = "guard"


def protection_data(machine) -> dict | None:
    """The control's model of its work space; None: it has none (the path is not checked)."""
    return machine.protection_model() if isinstance(machine, ProtectedSpace) else None


def not_modelled_warning(spec) -> str:
    """The note NC Start gives for a task the guard does not check for collisions."""
    if spec.probe_used == "tool" or (not spec.needs_probe and not getattr(spec, "lathe", False)):
        return NOT_MODELLED["tool"]
    return NOT_MODELLED["kinematics"]


def braking_for(machine, spec) -> Braking | None:
    """The reach check's data for the probe ``spec`` switches with (None: not checked). The
    override is the one in effect, at least 100 % (it may be turned up during the measurement)."""
    if not isinstance(machine, ProbeReach):
        return None
    override = max(100.0, float(machine.status().feed_override or 100.0)) if isinstance(machine, Machine) else 100.0
    return braking_from_data(machine.probe_braking(), spec.probe_used, override)


def guarded(spec) -> bool:
    """Workpiece-probe tasks are checked (the lathe's too); tool measuring and
    ``kinematics.measure`` are not."""
    if getattr(spec, "lathe", False):
        return bool(getattr(spec, "uses_workpiece_probe", False))
    return bool(spec.needs_probe) and bool(getattr(spec, "guarded", True))


def check_point(machine, spec, params: dict, n: int, ctx) -> tuple[GuardReport, str]:
    """The guard's report of point ``n`` from where the probe stands now, and the coordinates."""
    plan_ctx = spec.plan_context(ctx, params)
    executor = StepExecutor(machine, ctx.chain().wcs2bcs, ctx.tool_length, ctx.plane.infeed_unit,
                            tip=spec.tool_tip(ctx))
    coords = spec.coords_for(params, plan_ctx)
    start = executor.current(coords)
    program = spec.program(params, n, start, plan_ctx)
    braking = braking_for(machine, spec)
    wcs2bcs = ctx.chain().wcs2bcs
    tip = executor.tip_conversion
    placement = None
    if guarded(spec) and getattr(spec, "lathe", False):
        placement = _lathe_placement(ctx, tip, coords, wcs2bcs)
    elif guarded(spec) and coords == "WCS":
        placement = Placement(rotation=np.asarray(wcs2bcs.rotation, dtype=float),
                              ball_shift=np.asarray(wcs2bcs.child2parent(ball_offset(plan_ctx)), dtype=float),
                              axes_shift=np.asarray(tip.axes_for_tip(np.zeros(3), "WCS"), dtype=float),
                              ball_radius=float(plan_ctx.probe.ball_diameter) / 2.0)
    if placement is None:
        return _unknown(ideal_path(program, start), start, braking), coords
    return check_program(program, start, _model_of(protection_data(machine)), placement, braking), coords


_model_cache: tuple[dict | None, ProtectionModel] | None = None


def _model_of(data: dict | None) -> ProtectionModel:
    """``model_from_data``, built again only when the data differ from the last (the work space
    changes with a scenario or a rotary table turn, not with every NC Start)."""
    global _model_cache
    cached = _model_cache
    if cached is not None and cached[0] == data:
        return cached[1]
    model = model_from_data(data)
    _model_cache = (data, model)
    return model


def _lathe_placement(ctx, tip, coords: str, wcs2bcs) -> Placement | None:
    """The lathe's probe (turning.md §0.4): its ball centre is the NC's reference point P (MCS =
    the WCS point through the frames), the turret's axes F = P + (L1, 0, L2); X is a radius
    everywhere here. None without the probe's ball (then the path is ``unknown``)."""
    diameter = ctx.probe.ball_diameter if ctx.probe is not None else (ctx.probe_data or {}).get("ball_diameter")
    if not diameter:
        return None
    if coords == "WCS":
        rotation = np.asarray(wcs2bcs.rotation, dtype=float)
        ball_shift = np.asarray(wcs2bcs.child2parent(np.zeros(3)), dtype=float)
    else:
        rotation, ball_shift = np.eye(3), np.zeros(3)
    return Placement(rotation=rotation, ball_shift=ball_shift,
                     axes_shift=np.asarray(tip.axes_for_tip(np.zeros(3), coords), dtype=float),
                     ball_radius=float(diameter) / 2.0)


def _unknown(steps, start, braking: Braking | None = None) -> GuardReport:
    """A path the guard has no model for: every segment ``unknown`` (from ``start``); the probing
    moves still checked against the probe's reach (at the nominal surface, else the stroke's start)."""
    segments: list[Segment] = []
    directions = []
    pos = np.asarray(start, dtype=float)
    for step in steps:
        if isinstance(step, ProbeStep):
            directions.append(np.asarray(step.direction, dtype=float))
        if isinstance(step, MoveStep):
            target = np.asarray(step.target, dtype=float)
            segments.append(Segment(len(segments) + 1, step.label, "move", pos, target, "unknown"))
            pos = target
        elif isinstance(step, ProbeStep):
            end = pos + float(step.distance) * np.asarray(step.direction, dtype=float)
            reach = probe_reach(step, None, braking)
            beyond = reach is not None and reach.beyond
            segments.append(Segment(len(segments) + 1, step.label, "probe", pos, end,
                                    "overtravel" if beyond else "unknown", feed=float(step.feed), reach=reach))
            if beyond:
                break
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


def refusal_error(report: GuardReport, n: int, axes: tuple[str, ...], params: dict, *,
                  x_radius: bool = False) -> GuardRefused | None:
    """The 409 of a refused path (None: clear). ``x_radius``: a lathe's X is a radius here."""
    seg = report.refusal
    if seg is None:
        return None
    label = seg.label or f"step {seg.index}"
    if seg.verdict == "limit":
        alarm = alarms.START_GUARD_LIMIT
        what = f"{label} would leave the travel range of axis {seg.axis}"
    elif seg.verdict == "overtravel":
        alarm = alarms.START_GUARD_OVERTRAVEL
        what = (f"{label} would push the probe {float(seg.deflection or 0.0):.3f} mm past the surface: braking at "
                f"the measuring feed {float(seg.feed or 0.0):g} mm/min takes {float(seg.braking or 0.0):.3f} mm "
                f", beyond its permissible deflection of "
                f"{float(seg.max_deflection or 0.0):g} mm")
    else:
        alarm = alarms.START_GUARD_COLLISION
        at = seg.where if seg.where is not None else seg.end
        where = " ".join(f"{a}{float(v):.3f}" for a, v in zip(axes, at, strict=True))
        what = f"{label} would run into the {seg.body or 'material'} at {where} (WCS{', X a radius' if x_radius else ''})"
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

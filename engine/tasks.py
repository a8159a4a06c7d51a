"""The engine's part of every measuring task: family, point count, validation, plan, evaluation.

One ``EngineTask`` per task id of design.md §4. ``engine.plan`` and ``engine.evaluate`` look
tasks up here instead of deciding by the name; the app's task registry
(``app/workflow/tasks.py``) adds what only the app knows (finisher, screen form, targets).
Adding a task = its functions + one entry here + one entry there.

A program is ``program(params, n, start, ctx, label)``: the generator of point n (1-based)
(see ``engine.plan.point_program``). ``evaluate`` is the workpiece evaluation
``(task, params, points, plane, probe) -> TaskResult``; calibration and tool tasks evaluate in
their finishers (``engine.calibration``, ``engine.toolmeasure``) and have none here.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from enum import StrEnum
from functools import partial
from typing import Any

from engine import evaluate as ev
from engine import params as pv
from engine.checks import ParamError
from engine.plan_base import PlanContext
from engine.plan_tool import tool_diameter_program, tool_length_program, toolprobe_program
from engine.plan_workpiece import (
    Program,
    corner_direction,
    edge_program,
    hole_program,
    rect_program,
    ring_program,
    sign_of,
    spigot_program,
)
from engine.planes import Plane
from engine.types import EdgePoint, FloatArray, ProbeRecord, StoredPoint, TaskResult, probe_record


class Family(StrEnum):
    EDGE = "edge"
    CORNER = "corner"
    POCKET = "pocket"
    HOLE = "hole"
    SPIGOT = "spigot"
    PLANE = "plane"
    PROBE = "probe"              # workpiece probe calibration
    TOOLPROBE = "toolprobe"      # tool probe calibration
    TOOL = "tool"                # tool measuring
    LATHE = "lathe"              # the turning cycles (turning.md §10.2): engine.turning_plan; tasks in the app

    @property
    def workpiece(self) -> bool:
        return self in WORKPIECE_FAMILIES

    @property
    def tool_measuring(self) -> bool:
        """Tool-probe calibration and tool measuring: the plan speaks MCS and the cutter's tip."""
        return self in (Family.TOOL, Family.TOOLPROBE)


WORKPIECE_FAMILIES = frozenset({Family.EDGE, Family.CORNER, Family.POCKET, Family.HOLE, Family.SPIGOT,
                                Family.PLANE})

Validator = Callable[[dict[str, Any], Plane], dict[str, Any]]
PointProgram = Callable[[dict[str, Any], int, FloatArray, PlanContext, str], Program[object]]
Evaluator = Callable[..., TaskResult]    # (task, params, points, plane, probe) -> TaskResult


@dataclass(frozen=True)
class EngineTask:
    name: str                       # task id (design.md §4), e.g. "hole.1"
    family: Family
    points: int                     # P1..Pn
    validate: Validator             # params -> normalised params, or ParamError
    program: PointProgram           # the probing program of one point
    evaluate: Evaluator | None = None  # workpiece tasks: stored points -> TaskResult

    @property
    def coords(self) -> str:
        """Where the plan and its stored points speak: the measuring WCS, or MCS for tool tasks."""
        return "MCS" if self.family.tool_measuring else "WCS"

    @property
    def variant(self) -> str:
        return self.name.partition(".")[2]


# --- edge-type programs: one touch along a direction (jog-measuring §2.5, jog-measuring §2.6, jog-measuring §2.9, jog-measuring §5.2) ---------------

def _one_touch(direction: Callable[[dict[str, Any], int, Plane], FloatArray], raw: bool = False) -> PointProgram:
    def program(params: dict[str, Any], n: int, start: FloatArray, ctx: PlanContext, label: str
                ) -> Program[EdgePoint]:
        return edge_program(direction(params, int(n), ctx.plane), start, ctx, label, raw=raw)
    return program


def _along_axis(params: dict[str, Any], n: int, plane: Plane) -> FloatArray:
    return sign_of(params["direction"]) * plane.unit(params["axis"])


def _distance_direction(params: dict[str, Any], n: int, plane: Plane) -> FloatArray:
    """± the axis, or ± the line at ``line_angle`` (measuring-math §10.2, as the evaluation reads it)."""
    sign = sign_of(params["direction" if n == 1 else "direction_p2"])
    if params.get("line_angle") is not None:
        return sign * ev.line_unit(plane, float(params["line_angle"]))
    return sign * plane.unit(params["axis"])


def _corner_direction(params: dict[str, Any], n: int, plane: Plane) -> FloatArray:
    return corner_direction(params["kind"], int(params["position"]), n, plane)


def _down(params: dict[str, Any], n: int, plane: Plane) -> FloatArray:
    return -plane.infeed_unit          # orient plane, probe length: −infeed (jog-measuring §2.9, jog-measuring §5.2)


def _feature(program_fn: Callable[..., Program[object]], **kwargs: Any) -> PointProgram:
    def program(params: dict[str, Any], n: int, start: FloatArray, ctx: PlanContext, label: str
                ) -> Program[object]:
        return program_fn(params, start, ctx, label, **kwargs)
    return program


def _validator(fn: pv.ParamsValidator, variant: str) -> Validator:
    def validate(params: dict[str, Any], plane: Plane) -> dict[str, Any]:
        return fn(variant, dict(params or {}), plane)
    return validate


def _task(name: str, points: int, validate: pv.ParamsValidator, program: PointProgram,
          evaluate: Evaluator | None = None) -> EngineTask:
    family = Family(name.partition(".")[0])
    return EngineTask(name, family, points, _validator(validate, name.partition(".")[2]), program, evaluate)


def _circles(family: str, spigot: bool) -> list[EngineTask]:
    program = _feature(spigot_program) if spigot else _feature(hole_program)
    kind = "spigot" if spigot else "hole"
    evaluators = {1: partial(ev.evaluate_circle1, kind=kind), 2: partial(ev.evaluate_circles2, kind=kind),
                  3: partial(ev.evaluate_circles34, kind=kind, n=3),
                  4: partial(ev.evaluate_circles34, kind=kind, n=4)}
    return [_task(f"{family}.{k}", k, pv.validate_circles(spigot), program, evaluators[k]) for k in range(1, 5)]


ENGINE_TASKS: dict[str, EngineTask] = {t.name: t for t in [
    _task("edge.set", 1, pv.validate_edge, _one_touch(_along_axis), ev.evaluate_edge_set),
    _task("edge.align", 2, pv.validate_edge, _one_touch(_along_axis), ev.evaluate_edge_align),
    _task("edge.distance", 2, pv.validate_edge, _one_touch(_distance_direction), ev.evaluate_edge_distance),
    _task("corner.right", 3, pv.validate_corner, _one_touch(_corner_direction), ev.evaluate_corner),
    _task("corner.any", 4, pv.validate_corner, _one_touch(_corner_direction), ev.evaluate_corner),
    _task("pocket.rect", 1, pv.validate_rect(False), _feature(rect_program, inner=True),
          partial(ev.evaluate_rect, kind="pocket")),
    *_circles("hole", spigot=False),
    _task("spigot.rect", 1, pv.validate_rect(True), _feature(rect_program, inner=False),
          partial(ev.evaluate_rect, kind="spigot")),
    *_circles("spigot", spigot=True),
    _task("plane.align", 3, pv.validate_plane, _one_touch(_down), ev.evaluate_plane_align),
    _task("probe.length", 1, pv.validate_probe_length, _one_touch(_down, raw=True)),
    _task("probe.radius", 1, pv.validate_probe_radius, _feature(ring_program)),
    _task("toolprobe.calibrate", 1, pv.validate_toolprobe, _feature(toolprobe_program)),
    _task("tool.length", 1, pv.validate_tool, _feature(tool_length_program)),
    _task("tool.diameter", 1, pv.validate_tool, _feature(tool_diameter_program)),
]}

WORKPIECE_TASKS = tuple(name for name, t in ENGINE_TASKS.items() if t.evaluate is not None)


def engine_task(task: str) -> EngineTask:
    """The task of id ``task``; ParamError on the ``task`` field for an unknown id."""
    try:
        return ENGINE_TASKS[task]
    except KeyError:
        raise ParamError("task", f"unknown measuring task {task!r}") from None


def evaluate(task: str, params: dict[str, Any], points: Sequence[StoredPoint], plane: Plane,
             probe: ProbeRecord | None) -> TaskResult:
    """Evaluate the stored points of a workpiece task (design.md §4 names) in the measuring WCS."""
    spec = ENGINE_TASKS.get(task)
    if spec is None or spec.evaluate is None:
        raise ValueError(f"unknown task {task!r}; known: {', '.join(WORKPIECE_TASKS)}")
    return spec.evaluate(task, dict(params or {}), list(points), plane, probe_record(probe, f"evaluating {task}"))

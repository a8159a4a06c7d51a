"""The task registry: one ``TaskSpec`` per measuring task, the only place that knows what a task is.

A spec joins the engine's part (``engine.tasks``: family, point count, validation, probing
program, evaluation) with what the app adds: the category the screens and the readiness
checks group by, whether it needs the 3D probe, what it may correct, its finisher and its
screen form. Every other module asks this registry (``task_spec(name)``) instead of looking
at the task's name. Adding a task = its functions + one ``EngineTask`` + one entry here.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from enum import StrEnum

from app.errors import WorkflowError
from app.workflow import (
    finish,
    finish_lathe,
    finish_probe,
    finish_tool,
    finish_tool_offset,
    forms,
    kinematics_task,
    planning,
)
from app.workflow.context import Finisher
from engine.checks import ParamError
from engine.coords import LatheToolTip
from engine.plan_base import PlanContext
from engine.planes import Plane
from engine.tasks import ENGINE_TASKS, EngineTask, Family
from engine.turning_plan import LATHE_TASKS, lathe_program, prepare, validate_lathe_params
from engine.types import ProbeStep


class Category(StrEnum):
    """How the screens, the readiness checks and the correction group the tasks."""

    WORKPIECE = "workpiece"                          # measure workpiece (jog-measuring §2)
    PROBE_CALIBRATION = "probe_calibration"          # calibrate the workpiece probe (jog-measuring §5)
    TOOL_PROBE_CALIBRATION = "tool_probe_calibration"  # calibrate the tool probe (jog-measuring §7.2)
    TOOL_MEASURING = "tool_measuring"                # measure a cutter (jog-measuring §7.3)


class Target(StrEnum):
    """What a task's result may be written into."""

    ZERO_OFFSET = "zero_offset"      # a settable WO, a basic frame, or measure only
    TOOL_OFFSET = "tool_offset"      # a tool's wear or geometry from the measured size (design.md §9.3)
    PROBE_RECORD = "probe_record"    # _WP[k] (+ the probe's L1)
    TOOL_PROBE_RECORD = "tool_probe_record"   # _TP[k]
    TOOL_DATA = "tool_data"          # the active cutter's geometry or wear


@dataclass(frozen=True)
class TaskSpec:
    engine: EngineTask
    category: Category
    targets: frozenset[Target]
    finish: Finisher
    form_builder: Callable[[str, forms.FormEnv], list[forms.FieldSpec]]
    validator: Callable[[dict, Plane], dict] | None = None   # None: the engine's
    planner: Callable | None = None                          # None: the engine's program
    max_points: int = 0          # > 0: ``params.points`` may add points up to this (a fitted line/plane)
    circle_points: bool = False  # ``params.points`` = touches on each fitted circle (engine.params.circle_touches)

    # --- what the engine knows -----------------------------------------------------------
    @property
    def name(self) -> str:
        return self.engine.name

    @property
    def family(self) -> Family:
        return self.engine.family

    @property
    def variant(self) -> str:
        return self.engine.variant

    @property
    def points(self) -> int:
        return self.engine.points

    @property
    def single_point(self) -> bool:
        return self.engine.points == 1

    def points_of(self, params: dict) -> int:
        """P1..Pn of a session: the task's own count, or ``params.points`` (design.md §9.8); a
        circle task keeps its P count (its points are the touches on each circle, §10.2)."""
        return self.points if self.circle_points else int(params.get("points", self.points))

    @property
    def coords(self) -> str:
        """"WCS" (measuring WCS) or "MCS" (tool tasks: the plan speaks the cutter's tip in MCS)."""
        return self.engine.coords

    # --- what the app adds -----------------------------------------------------------------
    @property
    def needs_probe(self) -> bool:
        """Measured with the 3D probe in the spindle (workpiece tasks and probe calibration)."""
        return self.category in (Category.WORKPIECE, Category.PROBE_CALIBRATION)

    @property
    def probe_used(self) -> str | None:
        """The probe that switches during the task: "workpiece", "tool" (the tool probe)."""
        if self.category in (Category.WORKPIECE, Category.PROBE_CALIBRATION):
            return "workpiece"
        return "tool" if self.category in (Category.TOOL_MEASURING, Category.TOOL_PROBE_CALIBRATION) else None

    @property
    def corrects_zero_offset(self) -> bool:
        return Target.ZERO_OFFSET in self.targets

    def validate(self, params: dict, plane: Plane) -> dict:
        """The task's own params (engine), plus those every task takes: ``measurements`` (_NMSP)
        and, for a tool offset, ``tolerance`` (design.md §9.3)."""
        params = dict(params or {})
        out = (self.validator or self.engine.validate)(params, plane)
        if "points" in params and not self.circle_points:      # circle tasks: the engine's validator
            out["points"] = self._points(params["points"])
        if "max_form_error" in params:
            limit = params["max_form_error"]
            if isinstance(limit, bool) or not isinstance(limit, int | float) or not 0.0 < limit <= 100.0:
                raise ParamError("max_form_error", "max_form_error must be a number of mm in (0, 100]")
            out["max_form_error"] = float(limit)
        if "verify" in params:
            out["verify"] = self._verify(params["verify"])
        if "measurements" in params:
            n = params["measurements"]
            if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= MAX_MEASUREMENTS:
                raise ParamError("measurements", f"measurements must be a whole number 1..{MAX_MEASUREMENTS}, "
                                 f"got {n!r}")
            out["measurements"] = n
        if "tolerance" in params:
            if not isinstance(params["tolerance"], dict) or Target.TOOL_OFFSET not in self.targets:
                raise ParamError("tolerance", "tolerance is an object, for the tasks that correct tools")
            out["tolerance"] = dict(params["tolerance"])
        return out

    def _points(self, n) -> int:
        """``points``: how many points a task with a variable count probes."""
        n = int(n) if isinstance(n, str) and n.strip().isdigit() else n      # typed on a screen
        if not self.max_points:
            raise ParamError("points", f"{self.name} has a fixed number of points ({self.points})")
        if isinstance(n, bool) or not isinstance(n, int) or not self.points <= n <= self.max_points:
            raise ParamError("points", f"points must be a whole number {self.points}..{self.max_points}, "
                             f"got {n!r}")
        return n

    def _verify(self, verify) -> bool:
        """``verify``: a single-point workpiece task probes again by itself."""
        if not isinstance(verify, bool):
            raise ParamError("verify", "verify must be true or false")
        if verify and (not self.single_point or self.category != Category.WORKPIECE):
            raise ParamError("verify", "verify: only single-point workpiece tasks probe again by themselves")
        return verify

    def program(self, params: dict, n: int, start, ctx: PlanContext):
        if not 1 <= int(n) <= self.points_of(params):
            raise ValueError(f"{self.name} has points 1..{self.points_of(params)}, got {n}")
        planner = self.planner or self.engine.program
        return planner(params, int(n), start, ctx, f"P{n}")

    def form(self, env: forms.FormEnv) -> list[forms.FieldSpec]:
        fields = self.form_builder(self.variant, env)
        return forms.with_tool_offset(fields, env) if Target.TOOL_OFFSET in self.targets else fields

    # --- how the workflow runs a point (the lathe tasks vary these) ----------------------------
    target_in_params = False    # the target is one of the task's params (lathe tasks, turning.md §10.2)
    lathe = False

    def plan_context(self, ctx, params: dict):
        """The context the point program reads (engine.plan_base.PlanContext)."""
        return planning.context_from(ctx, self, params)

    def coords_for(self, params: dict, plan_ctx) -> str:
        """The system of the start position and of every step."""
        return self.coords

    def tool_tip(self, ctx):
        """The tip <-> axes conversion of the executor; None: the milling one (engine.coords.ToolTip)."""
        return None

    def repeats(self, params: dict) -> int:
        """How often the whole point program runs and is averaged (_NMSP, measuring-math §1.4)."""
        return int(params.get("measurements", 1))

    guarded = True              # the start guard checks the plan before NC Start (design.md §10.1)

    def check_machine(self, params: dict, env) -> None:
        """Refusals of the params this machine decides (400 naming the field); most tasks have none."""


@dataclass(frozen=True)
class LatheTaskSpec(TaskSpec):
    """A lathe task (turning.md §10.2, engine.turning_plan): the product extension "measuring on
    the lathe" through the same workflow. The engine validates every param (``target`` and
    ``tolerance`` included), the context is an ``engine.turning.LatheContext``
    (app.workflow.finish_lathe), the tip is ``P = F − (L1·x̂ + L2·ẑ)``, _NMSP is the cycle's own."""

    target_in_params = True
    lathe = True

    @property
    def needs_probe(self) -> bool:
        return False            # the turning cycles check the 5xy probe themselves (61309, 61315)

    @property
    def uses_workpiece_probe(self) -> bool:
        return self.category in (Category.WORKPIECE, Category.PROBE_CALIBRATION)

    def validate(self, params: dict, plane: Plane) -> dict:
        out = self.engine.validate(dict(params or {}), plane)
        target = out.get("target")
        if isinstance(target, dict) and target["edge"] != 1:
            raise ParamError("target.edge", "target.edge: the tool table holds one cutting edge per tool (D1)")
        return out

    def plan_context(self, ctx, params: dict):
        return finish_lathe.lathe_context(ctx)

    def coords_for(self, params: dict, plan_ctx) -> str:
        return prepare(self.name, params, plan_ctx).coords

    def tool_tip(self, ctx):
        l1, l2 = finish_lathe.lathe_extra(ctx)["tool_lengths"]
        return LatheToolTip(ctx.chain().wcs2bcs, float(l1), float(l2))

    def repeats(self, params: dict) -> int:
        return 1                # _NMSP is the cycle's: each place probed n times, averaged (engine.turning)

    def form(self, env: forms.FormEnv) -> list[forms.FieldSpec]:
        return self.form_builder(self.variant, env)


# --- app-level variations of the engine's parts ----------------------------------------------

def _tool_validator(engine_task: EngineTask):
    """Tool length/diameter: ``compensation`` stays absent unless given, so the finisher falls
    back to the setting _JM_B[0] (``tool_offset_mode``, jog-measuring §7.3)."""
    def validate(params: dict, plane: Plane) -> dict:
        out = engine_task.validate(params, plane)
        if "compensation" not in (params or {}):
            out.pop("compensation", None)
        return out
    return validate


def _first_toolprobe_search_longer(engine_task: EngineTask):
    """[I] First tool-probe calibration: the cycle expects rough trigger values (measuring-math §14.5);
    without a stored infeed trigger value the first touch searches over
    max(2·E_MESS_MT_D, E_MESS_D_M), so the operator may start the tool that far above the probe."""
    def planner(params, n, start, ctx: PlanContext, label):
        program = engine_task.program(params, n, start, ctx, label)
        if f"{ctx.plane.infeed}-" in (ctx.tool_probe or {}):
            return program
        return _first_probe_longer(program, max(2.0 * ctx.mt_path, ctx.measuring_path))
    return planner


def _first_probe_longer(program, distance: float):
    reply, first = None, True
    try:
        while True:
            step = program.send(reply)
            if first and isinstance(step, ProbeStep):
                first = False
                step = dataclasses.replace(step, distance=max(float(step.distance), distance))
            reply = yield step
    except StopIteration as done:
        return done.value


# --- the registry -----------------------------------------------------------------------------

_ZO = frozenset({Target.ZERO_OFFSET})
_ZO_OR_TOOL = frozenset({Target.ZERO_OFFSET, Target.TOOL_OFFSET})
MAX_MEASUREMENTS = 99
MAX_FIT_POINTS = 12           # a fitted line or plane: up to P12 (the screens show up to P6)


def finish_workpiece_or_tool(session, ctx, points):
    """A WO (or measure only) by name, or a tool offset given as an object (design.md §9.3)."""
    if isinstance(session.target, dict):
        return finish_tool_offset.finish_tool_offset(session, ctx, points)
    return finish.finish_workpiece(session, ctx, points)


def _spec(name: str, category: Category, targets: frozenset[Target], finisher: Finisher, form,
          **variations) -> TaskSpec:
    engine_task = ENGINE_TASKS[name]
    made = {key: make(engine_task) for key, make in variations.items()}
    return TaskSpec(engine_task, category, targets, finisher, form, **made)


def _workpiece(name: str, form, targets: frozenset[Target] = _ZO, max_points: int = 0) -> TaskSpec:
    finisher = finish_workpiece_or_tool if Target.TOOL_OFFSET in targets else finish.finish_workpiece
    circles = name.startswith(("hole.", "spigot.")) and name != "spigot.rect"
    return dataclasses.replace(_spec(name, Category.WORKPIECE, targets, finisher, form), max_points=max_points,
                               circle_points=circles)


TASKS: dict[str, TaskSpec] = {spec.name: spec for spec in [
    _workpiece("edge.set", forms.edge_form, _ZO_OR_TOOL),
    _workpiece("edge.align", forms.edge_form, max_points=MAX_FIT_POINTS),
    _workpiece("edge.distance", forms.edge_form, _ZO_OR_TOOL),
    _workpiece("corner.right", forms.corner_form),
    _workpiece("corner.any", forms.corner_form),
    _workpiece("pocket.rect", forms.rect_form(spigot=False), _ZO_OR_TOOL),
    _workpiece("hole.1", forms.circles_form(spigot=False), _ZO_OR_TOOL),
    *(_workpiece(f"hole.{k}", forms.circles_form(spigot=False)) for k in range(2, 5)),
    _workpiece("spigot.rect", forms.rect_form(spigot=True), _ZO_OR_TOOL),
    _workpiece("spigot.1", forms.circles_form(spigot=True), _ZO_OR_TOOL),
    *(_workpiece(f"spigot.{k}", forms.circles_form(spigot=True)) for k in range(2, 5)),
    _workpiece("plane.align", forms.plane_form, max_points=MAX_FIT_POINTS),
    _spec("probe.length", Category.PROBE_CALIBRATION, frozenset({Target.PROBE_RECORD, Target.TOOL_DATA}),
          finish_probe.finish_probe_length, forms.probe_length_form),
    dataclasses.replace(_spec("probe.radius", Category.PROBE_CALIBRATION, frozenset({Target.PROBE_RECORD}),
                              finish_probe.finish_probe_radius, forms.probe_radius_form), circle_points=True),
    _spec("toolprobe.calibrate", Category.TOOL_PROBE_CALIBRATION, frozenset({Target.TOOL_PROBE_RECORD}),
          finish_tool.finish_toolprobe_calibrate, forms.toolprobe_form,
          planner=_first_toolprobe_search_longer),
    _spec("tool.length", Category.TOOL_MEASURING, frozenset({Target.TOOL_DATA}),
          finish_tool.finish_tool_measure, forms.tool_form, validator=_tool_validator),
    _spec("tool.diameter", Category.TOOL_MEASURING, frozenset({Target.TOOL_DATA}),
          finish_tool.finish_tool_measure, forms.tool_form, validator=_tool_validator),
]}


# --- the lathe tasks (turning.md §10.2): one entry each ------------------------------------------------

def _lathe_engine_task(name: str) -> EngineTask:
    def validate(params: dict, plane: Plane) -> dict:
        return validate_lathe_params(name, params)

    def program(params, n, start, ctx, label):
        return lathe_program(prepare(name, params, ctx), start)

    return EngineTask(name, Family.LATHE, 1, validate, program)


def _lathe(name: str, category: Category, targets: frozenset[Target],
           evaluate: finish_lathe.LatheEvaluator) -> LatheTaskSpec:
    return LatheTaskSpec(_lathe_engine_task(name), category, targets, finish_lathe.lathe_finisher(evaluate),
                         forms.lathe_form)


LATHE_SPECS: dict[str, TaskSpec] = {spec.name: spec for spec in [
    _lathe("lathe.toolprobe.calibrate", Category.TOOL_PROBE_CALIBRATION, frozenset({Target.TOOL_PROBE_RECORD}),
           finish_lathe.finish_toolprobe),
    _lathe("lathe.tool.measure", Category.TOOL_MEASURING, frozenset({Target.TOOL_DATA}), finish_lathe.finish_tool),
    _lathe("lathe.tool.auto", Category.TOOL_MEASURING, frozenset({Target.TOOL_DATA}), finish_lathe.finish_tool),
    _lathe("lathe.probe.groove", Category.PROBE_CALIBRATION, frozenset({Target.PROBE_RECORD}),
           finish_lathe.finish_probe),
    _lathe("lathe.probe.surface", Category.PROBE_CALIBRATION, frozenset({Target.PROBE_RECORD}),
           finish_lathe.finish_probe),
    _lathe("lathe.point", Category.WORKPIECE, frozenset({Target.ZERO_OFFSET, Target.TOOL_OFFSET}),
           finish_lathe.finish_workpiece),
    _lathe("lathe.two_point", Category.WORKPIECE, frozenset({Target.TOOL_OFFSET}), finish_lathe.finish_workpiece),
]}
assert tuple(LATHE_SPECS) == LATHE_TASKS
TASKS.update(LATHE_SPECS)


@dataclass(frozen=True)
class KinematicsTaskSpec(TaskSpec):
    """``kinematics.measure`` (design.md §10.6, app.workflow.kinematics_task): one point per position,
    planned in MCS of the NC's ball centre; the start guard does not model swivels (not guarded)."""

    guarded = False

    def points_of(self, params: dict) -> int:
        return len(params["positions"]) + (1 if "_reference" in params else 0)

    def coords_for(self, params: dict, plan_ctx) -> str:
        return "MCS"

    def plan_context(self, ctx, params: dict):
        return ctx                          # the program reads the measuring context itself

    def program(self, params: dict, n: int, start, ctx):
        if not 1 <= int(n) <= self.points_of(params):
            raise ValueError(f"{self.name} has points 1..{self.points_of(params)}, got {n}")
        return kinematics_task.program(params, int(n), start, ctx, f"P{n}")

    def repeats(self, params: dict) -> int:
        return 1

    def check_machine(self, params: dict, env) -> None:
        facts = env.measuring_context().extra.get("kinematics") or {}
        kinematics_task.check_machine(params, facts)
        if kinematics_task.partner_of(params, facts) is not None:
            params["_reference"] = True        # P(n+1): the sphere with every rotary axis at 0


KINEMATICS_SPEC = KinematicsTaskSpec(kinematics_task.ENGINE_TASK, Category.WORKPIECE, frozenset(),
                                     kinematics_task.finish_kinematics, kinematics_task.kinematics_form)
TASKS[KINEMATICS_SPEC.name] = KINEMATICS_SPEC
MILLING_TASKS = tuple(name for name in TASKS if name not in LATHE_SPECS)


def task_spec(name: str) -> TaskSpec:
    """The spec of task ``name``; an unknown name is a 400 naming the ``task`` field."""
    spec = TASKS.get(name) if isinstance(name, str) else None
    if spec is None:
        raise WorkflowError(400, "unknown_task", f"unknown measuring task {name!r}", "task")
    return spec

"""Planning: the probing program of every task (spec/jog-measuring.md §2, §5, §7).

The workflow only executes what is planned here. ``point_program`` is a generator: it yields
steps, receives ``None`` after Move/Spindle steps and a ``Latch`` after each ProbeStep, and
returns the stored point. Contracts and probing helpers: ``engine.plan_base``; geometry:
``engine.plan_workpiece``, ``engine.plan_tool``.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable, Generator

import numpy as np

from engine.plan_base import (
    TASK_POINTS,
    ParamError,
    PlanContext,
    RingCalibrationPoint,
    RingPass,
    ToolPoint,
    ToolProbePoint,
    ToolTouch,
    hit,
)
from engine.plan_tool import tool_diameter_program, tool_length_program, toolprobe_program
from engine.plan_workpiece import (
    corner_direction,
    edge_direction,
    edge_program,
    hole_program,
    rect_program,
    ring_program,
    spigot_program,
)
from engine.planes import Plane
from engine.types import Latch, MeasuringError, MoveStep, ProbeStep, Step

__all__ = [
    "TASK_POINTS", "ParamError", "PlanContext", "RingCalibrationPoint", "RingPass", "ToolPoint",
    "ToolProbePoint", "ToolTouch", "corner_direction", "hit", "planned_path", "point_program",
    "run_program", "validate_params",
]

ROTARY_AXES = ("A", "B", "C")   # design.md §3: optional rotary axes


# --- parameter validation (spec §2.3 [I] validation rules) ---------------------------------------

def _number(params: dict, name: str, default=None, *, required: bool = False) -> float | None:
    value = params.get(name, default)
    if value is None or value == "":
        if required:
            raise ParamError(name, f"{name} is required")
        return None
    if isinstance(value, bool):
        raise ParamError(name, f"{name} must be a number, got {value!r}")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ParamError(name, f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(number):
        raise ParamError(name, f"{name} must be a finite number, got {value!r}")
    return number


def _positive(params: dict, name: str, *, required: bool) -> float | None:
    value = _number(params, name, required=required)
    if value is not None and value <= 0.0:
        raise ParamError(name, f"{name} must be > 0, got {value:g}")
    return value


def _choice(params: dict, name: str, choices: tuple, default):
    value = params.get(name, default)
    if value not in choices:
        raise ParamError(name, f"{name} must be one of {', '.join(map(str, choices))}, got {value!r}")
    return value


def _axis(params: dict, name: str, default: str) -> str:
    value = params.get(name, default)
    value = value.upper() if isinstance(value, str) else value
    if value not in ("X", "Y", "Z"):
        raise ParamError(name, f"{name} must be X, Y or Z, got {params.get(name)!r}")
    return value


def _setpoint_axis(params: dict, axis: str) -> dict[str, float]:
    """Set edge / distance / probe length: {axis: value} (design.md §4); a bare number is accepted."""
    value = params.get("setpoint", 0.0)
    if isinstance(value, dict):
        extra = [k for k in value if k != axis]
        if extra:
            raise ParamError(f"setpoint.{extra[0]}", f"setpoint may only give the {axis} value")
        value = value.get(axis, 0.0)
    return {axis: _number({f"setpoint.{axis}": value}, f"setpoint.{axis}", 0.0) or 0.0}   # empty = 0


def _setpoint_point(params: dict, plane: Plane) -> dict[str, float]:
    """Plane setpoints keyed by the plane's axis names (design.md §4), default 0."""
    value = params.get("setpoint", {}) or {}
    if not isinstance(value, dict):
        raise ParamError("setpoint", "setpoint must be an object keyed by the plane's axis names")
    out = {}
    for axis in (plane.first, plane.second):
        out[axis] = _number({f"setpoint.{axis}": value.get(axis, 0.0)}, f"setpoint.{axis}", 0.0) or 0.0
    for key in value:
        if key not in out:
            raise ParamError(f"setpoint.{key}", f"setpoint axis {key!r} is not an axis of the plane {plane.name}")
    return out


def _angle_correction(params: dict, allowed_none: bool, default: str) -> str:
    value = params.get("angle_correction", default)
    choices = ("rotation", "none", *ROTARY_AXES) if allowed_none else ("rotation", *ROTARY_AXES)
    value = value.upper() if isinstance(value, str) and len(value) == 1 else value
    if value not in choices:
        raise ParamError("angle_correction",
                         f"angle_correction must be one of {', '.join(choices)}, got {params.get('angle_correction')!r}")
    return value


def _setpoint_angle(params: dict) -> float:
    value = _number(params, "setpoint_angle", 0.0) or 0.0     # empty field = 0 (spec §2.3)
    if not -360.0 < value < 360.0:      # spec §2.3 [I]: setpoint angle in (−360, 360)
        raise ParamError("setpoint_angle", f"setpoint_angle must lie in (-360, 360), got {value:g}")
    return value


def validate_params(task: str, params: dict, plane: Plane) -> dict:
    """Normalised params with defaults, or ParamError(field, message) (spec §2.3, design.md §4).

    ``target`` is passed through untouched (the app validates it); unknown keys are dropped.
    """
    if task not in TASK_POINTS:
        raise ParamError("task", f"unknown measuring task {task!r}")
    params = dict(params or {})
    out: dict = {}
    family, _, variant = task.partition(".")
    if family == "edge":
        out["axis"] = _axis(params, "axis", plane.second if variant == "align" else plane.first)
        out["direction"] = _choice(params, "direction", ("+", "-"), "+")
        if variant == "align":
            others = tuple(a for a in (plane.first, plane.second) if a != out["axis"])
            ref = _axis(params, "reference_axis", others[0])
            if ref == out["axis"] or ref not in (plane.first, plane.second):
                raise ParamError("reference_axis",
                                 f"reference_axis must be a plane axis ({plane.first}/{plane.second}) "
                                 f"other than the measuring axis {out['axis']}, got {ref}")
            out["reference_axis"] = ref
            out["angle_correction"] = _angle_correction(params, False, "rotation")
            out["setpoint_angle"] = _setpoint_angle(params)
        else:
            if variant == "distance":
                opposite = "-" if out["direction"] == "+" else "+"
                out["direction_p2"] = _choice(params, "direction_p2", ("+", "-"), opposite)
            out["setpoint"] = _setpoint_axis(params, out["axis"])
    elif family == "corner":
        out["kind"] = _choice(params, "kind", ("outside", "inside"), "outside")
        position = _number(params, "position", 1)
        if position not in (1.0, 2.0, 3.0, 4.0):
            raise ParamError("position", f"position must be 1, 2, 3 or 4, got {params.get('position')!r}")
        out["position"] = int(position)
        out["setpoint"] = _setpoint_point(params, plane)
    elif task in ("pocket.rect", "spigot.rect"):
        spigot = family == "spigot"
        out["length"] = _positive(params, "length", required=spigot)
        out["width"] = _positive(params, "width", required=spigot)
        if spigot:
            out["infeed"] = _positive(params, "infeed", required=True)
        out["setpoint"] = _setpoint_point(params, plane)
    elif family in ("hole", "spigot"):
        spigot = family == "spigot"
        out["diameter"] = _positive(params, "diameter", required=spigot)  # hole: may be empty (§2.3)
        if spigot:
            out["infeed"] = _positive(params, "infeed", required=True)
        out["probe_angle"] = _number(params, "probe_angle", 0.0) or 0.0
        if variant in ("2", "3", "4"):
            out["angle_correction"] = _angle_correction(params, variant != "2",
                                                        "rotation" if variant == "2" else "none")
            out["setpoint_angle"] = _setpoint_angle(params)
        if variant == "2":
            set_p1 = params.get("set_p1", False)
            if not isinstance(set_p1, bool):
                raise ParamError("set_p1", f"set_p1 must be true or false, got {set_p1!r}")
            out["set_p1"] = set_p1
        out["setpoint"] = _setpoint_point(params, plane)
    elif task == "probe.length":
        out["setpoint"] = _setpoint_axis(params, plane.infeed)
    elif task == "probe.radius":
        out["diameter"] = _positive(params, "diameter", required=True)
    elif task == "toolprobe.calibrate":
        out["mode"] = _choice(params, "mode", ("length", "length_diameter"), "length")
    elif family == "tool":
        value = _number(params, "offset_v", 0.0) or 0.0
        if value < 0.0:
            raise ParamError("offset_v", f"offset_v must be >= 0, got {value:g}")
        out["offset_v"] = value
        out["compensation"] = _choice(params, "compensation", ("geometry", "wear"), "geometry")
    if "target" in params:
        out["target"] = params["target"]
    return out


# --- point programs ---------------------------------------------------------------------------

def point_program(task: str, params: dict, n: int, start: np.ndarray, ctx: PlanContext
                  ) -> Generator[Step, Latch | None, object]:
    """The probing program of point n (1-based) of ``task``; returns the stored point.

    ``start``: NC reference position (ball centre, or tip with L1 to the tip; tool tip for tool
    tasks) in the measuring WCS (tool tasks: MCS). ``params``: as returned by validate_params.
    """
    if task not in TASK_POINTS:
        raise ParamError("task", f"unknown measuring task {task!r}")
    if not 1 <= int(n) <= TASK_POINTS[task]:
        raise ValueError(f"{task} has points 1..{TASK_POINTS[task]}, got {n}")
    start = np.asarray(start, dtype=float)
    label = f"P{n}"
    family = task.split(".")[0]
    if family in ("edge", "corner", "plane") or task == "probe.length":
        d = edge_direction(task, params, int(n), ctx.plane)
        return edge_program(d, start, ctx, label, raw=task == "probe.length")
    if task == "pocket.rect":
        return rect_program(params, start, ctx, label, inner=True)
    if task == "spigot.rect":
        return rect_program(params, start, ctx, label, inner=False)
    if family == "hole":
        return hole_program(params, start, ctx, label)
    if family == "spigot":
        return spigot_program(params, start, ctx, label)
    if task == "probe.radius":
        return ring_program(params, start, ctx, label)
    if task == "toolprobe.calibrate":
        return toolprobe_program(params, start, ctx, label)
    if task == "tool.length":
        return tool_length_program(params, start, ctx, label)
    return tool_diameter_program(params, start, ctx, label)


def run_program(program: Generator[Step, Latch | None, object],
                respond: Callable[[Step], Latch | None], steps: list[Step] | None = None) -> object:
    """Drive a point program: each step goes to ``respond``, whose answer (a Latch for a
    ProbeStep, None otherwise) is sent back; returns the stored point. ``steps`` collects the
    yielded steps (also those before an exception of the program)."""
    reply: Latch | None = None
    try:
        while True:
            step = program.send(reply)
            if steps is not None:
                steps.append(step)
            reply = respond(step)
    except StopIteration as done:
        return done.value


def planned_path(task: str, params: dict, n: int, start: np.ndarray, ctx: PlanContext) -> list[Step]:
    """The program driven with ideal latches, for the live preview (never raises on hits).

    Every ProbeStep switches at its ``expected`` travel (nominal geometry; halfway when
    unknown). A MeasuringError of the program (e.g. missing tool probe data) ends the list.
    """
    pos = np.asarray(start, dtype=float)

    def ideal(step: Step) -> Latch | None:
        nonlocal pos
        if isinstance(step, MoveStep):
            pos = np.asarray(step.target, dtype=float)
        elif isinstance(step, ProbeStep):
            travel = step.expected if step.expected is not None else step.distance / 2.0
            pos = pos + travel * np.asarray(step.direction, dtype=float)
            return Latch(triggered=True, rec=pos.copy())
        return None

    steps: list[Step] = []
    with contextlib.suppress(MeasuringError):
        run_program(point_program(task, params, n, start, ctx), ideal, steps)
    return steps

"""Planning: the probing program of every task (spec/jog-measuring.md §2, jog-measuring §5, jog-measuring §7).

The workflow only executes what is planned here. ``point_program`` is a generator: it yields
steps, receives ``None`` after Move/Spindle steps and a ``Latch`` after each ProbeStep, and
returns the stored point. Contracts and probing helpers: ``engine.plan_base``; geometry:
``engine.plan_workpiece``, ``engine.plan_tool``.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Generator
from typing import Any

import numpy as np

from engine.checks import ParamError
from engine.plan_base import (
    PlanContext,
    RingCalibrationPoint,
    RingPass,
    ToolPoint,
    ToolProbePoint,
    ToolTouch,
    hit,
)
from engine.plan_workpiece import corner_direction
from engine.planes import Plane
from engine.tasks import ENGINE_TASKS, engine_task
from engine.types import FloatArray, Latch, MeasuringError, MoveStep, ProbeStep, Step

__all__ = [
    "TASK_POINTS", "ParamError", "PlanContext", "RingCalibrationPoint", "RingPass", "ToolPoint",
    "ToolProbePoint", "ToolTouch", "corner_direction", "hit", "ideal_path", "planned_path", "point_program",
    "run_program", "validate_params",
]

TASK_POINTS: dict[str, int] = {name: task.points for name, task in ENGINE_TASKS.items()}


def validate_params(task: str, params: dict[str, Any], plane: Plane) -> dict[str, Any]:
    """Normalised params with defaults, or ParamError(field, message) (jog-measuring §2.3, design.md §4).

    The validator is the task's (``engine.tasks``, one per family in ``engine.params``).
    ``target`` is passed through untouched (the app validates it); unknown keys are dropped.
    """
    return engine_task(task).validate(params, plane)


# --- point programs ---------------------------------------------------------------------------

def point_program(task: str, params: dict[str, Any], n: int, start: FloatArray, ctx: PlanContext
                  ) -> Generator[Step, Latch | None, object]:
    """The probing program of point n (1-based) of ``task``; returns the stored point.

    ``start``: NC reference position (ball centre, or tip with L1 to the tip; tool tip for tool
    tasks) in the measuring WCS (tool tasks: MCS). ``params``: as returned by validate_params.
    """
    spec = engine_task(task)
    if not 1 <= int(n) <= spec.points:
        raise ValueError(f"{task} has points 1..{spec.points}, got {n}")
    return spec.program(params, int(n), np.asarray(start, dtype=float), ctx, f"P{n}")


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


def planned_path(task: str, params: dict[str, Any], n: int, start: FloatArray, ctx: PlanContext) -> list[Step]:
    """The program of point n of ``task`` driven with ideal latches (``ideal_path``)."""
    return ideal_path(point_program(task, params, n, start, ctx), start)


def ideal_path(program: Generator[Step, Latch | None, object], start: FloatArray) -> list[Step]:
    """A point program driven with ideal latches, for the live preview (never raises on hits).

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
        run_program(program, ideal, steps)
    return steps

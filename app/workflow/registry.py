"""Builds the workflow service with the finishers of every task family."""

from __future__ import annotations

from app.workflow import finish, planning
from app.workflow.service import WorkflowEnv, WorkflowService


def finishers() -> dict:
    table = dict(finish.FINISHERS)
    try:  # calibration and tool measuring plug in their own finishers
        from app.workflow import finish_probe
        table.update(finish_probe.FINISHERS)
    except ImportError:
        pass
    try:
        from app.workflow import finish_tool
        table.update(finish_tool.FINISHERS)
    except ImportError:
        pass
    return table


def build_workflow(env: WorkflowEnv) -> WorkflowService:
    return WorkflowService(env, finishers(), planning, planning.TASK_POINTS)

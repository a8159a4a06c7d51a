"""HTML screens (one module per screen) and the shared panel partials (header, position, MCP)."""

from fastapi import APIRouter, Depends

from app.access.deps import guard

from . import (
    docs,
    jog,
    kinematics,
    log,
    machine_view,
    measure,
    memories,
    nc,
    offsets,
    panel,
    parts,
    plant,
    plc,
    probes,
    settings,
    setup_support,
    signin,
    task_help,
    task_screens,
    tilted_setup,
    tool_probes,
    tools,
)

web_router = APIRouter(include_in_schema=False, dependencies=[Depends(guard)])   # app/access/deps.py
for module in (panel, jog, offsets, tools, machine_view, settings, tilted_setup, measure, tool_probes,
               task_screens, log, setup_support, probes, plc, signin, docs, nc, memories, task_help, parts,
               plant, kinematics):
    web_router.include_router(module.router)

__all__ = ["web_router"]

"""HTML screens (one module per screen) and the shared panel partials (header, position, MCP)."""

from fastapi import APIRouter

from . import (
    jog,
    log,
    machine_view,
    measure,
    offsets,
    panel,
    plc,
    probes,
    settings,
    setup_support,
    task_screens,
    tilted_setup,
    tool_probes,
    tools,
)

web_router = APIRouter(include_in_schema=False)
for module in (panel, jog, offsets, tools, machine_view, settings, tilted_setup, measure, tool_probes,
               task_screens, log, setup_support, probes, plc):
    web_router.include_router(module.router)

__all__ = ["web_router"]

"""HTML screens (one module per screen) and the shared panel partials (header, position, MCP)."""

from fastapi import APIRouter

from . import jog, log, machine_view, measure, offsets, panel, settings, task_screens, tool_probes, tools

web_router = APIRouter(include_in_schema=False)
for module in (panel, jog, offsets, tools, machine_view, settings, measure, tool_probes, task_screens, log):
    web_router.include_router(module.router)
web_router.include_router(__import__("app.web.setup_support", fromlist=["router"]).router)
web_router.include_router(__import__("app.web.probes", fromlist=["router"]).router)

__all__ = ["web_router"]

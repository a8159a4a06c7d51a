"""HTML screens (one module per screen) and the shared panel partials (header, position, MCP)."""

from fastapi import APIRouter

from . import jog, machine_view, measure, offsets, panel, settings, tools

web_router = APIRouter(include_in_schema=False)
for module in (panel, jog, offsets, tools, machine_view, settings, measure):
    web_router.include_router(module.router)

__all__ = ["web_router"]

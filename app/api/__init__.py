"""JSON API routers (design.md §4). Thin: parse, call a service, return its data."""

from fastapi import APIRouter

from . import data, machine, measure, plc, setup_support

api_router = APIRouter(prefix="/api")
for module in (machine, data, measure, setup_support, plc):
    api_router.include_router(module.router)

__all__ = ["api_router"]

"""JSON API routers (design.md §4). Thin: parse, call a service, return its data."""

from fastapi import APIRouter

from . import data, machine, measure

api_router = APIRouter(prefix="/api")
api_router.include_router(machine.router)
api_router.include_router(data.router)
api_router.include_router(measure.router)
api_router.include_router(__import__("app.api.setup_support", fromlist=["router"]).router)

__all__ = ["api_router"]

"""Rotary-axis kinematic data the control holds (design.md §10.6): read, write (``settings`` level)."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Body

from app.access.deps import needs
from app.deps import ServicesDep
from app.services.kinematics import KinematicsService

router = APIRouter(tags=["kinematics"])


@router.get("/kinematics", name="api_kinematics_get")
def get_kinematics(services: ServicesDep) -> dict:
    """``{axis: {"point", "direction", "unit"}}``: head axes ("head", relative to the tool reference
    point) and the rotary table ("table", MCS), lines at the zero position of every rotary axis."""
    return KinematicsService(services.db, services.machine).get()


@router.put("/kinematics", name="api_kinematics_put", dependencies=[needs("settings")])
def put_kinematics(body: Annotated[dict, Body()], services: ServicesDep) -> dict:
    """Replace the lines of the axes given (others keep theirs); audited (kind "kinematics"), undoable."""
    return KinematicsService(services.db, services.machine).put(body, source="api")

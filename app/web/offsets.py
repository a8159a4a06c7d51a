"""Zero-offset table screen: edit in place (one cell per request), activation, audit trail."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Form, Request

from app.deps import MachineDep, OffsetsDep
from app.errors import HmiError

from .templating import render_block, render_screen

router = APIRouter()


def columns(rotary_axes: tuple[str, ...]) -> list[tuple[str, str, str]]:
    """(field, group heading, axis heading) in display order."""
    cols = [(f"trans.{a}", "Offset", a) for a in ("X", "Y", "Z")]
    cols += [(f"trans.{a}", "Rotary", a) for a in rotary_axes]
    cols += [(f"fine.{a}", "Fine", a) for a in ("X", "Y", "Z")]
    cols += [(f"rot.{a}", "Rotation", a) for a in ("X", "Y", "Z")]
    return cols


def value_of(frame: dict, field: str) -> float:
    part, _, axis = field.partition(".")
    return float(frame.get(part, {}).get(axis, 0.0))


def cell(name: str, field: str, frame: dict, rotary: bool = False) -> dict:
    return {"name": name, "field": field, "value": value_of(frame, field), "text": None, "error": None,
            "rotary": rotary}


@router.get("/offsets")
def offsets_screen(request: Request, offsets: OffsetsDep, machine: MachineDep):
    frames = offsets.list()
    cols = columns(machine.rotary_axes)
    rows = [{"name": name, "cells": [cell(name, f, frame, f.split(".")[0] == "rot" or g == "Rotary")
                                     for f, g, _ in cols]}
            for name, frame in frames.items()]
    return render_screen(request, "offsets.html", {"screen": "offsets", "columns": cols, "rows": rows,
                                                   "active": machine.active_offset})


@router.get("/offsets/audit")
def audit_screen(request: Request, offsets: OffsetsDep):
    return render_screen(request, "audit.html", {"screen": "offsets", "entries": offsets.audit(50)})


@router.post("/offsets/{name}/activate")
def activate(request: Request, name: str, machine: MachineDep, offsets: OffsetsDep):
    machine.activate(name)
    return offsets_screen(request, offsets, machine)


@router.post("/offsets/{name}/{field}")
def edit_cell(request: Request, name: str, field: str, offsets: OffsetsDep,
              value: Annotated[str, Form()] = ""):
    """One cell: stored on success; on error the typed text stays with the message, nothing stored."""
    rotary = field.startswith("rot.") or field.split(".")[-1] not in ("X", "Y", "Z")
    try:
        frame = offsets.put_field(name, field, value, source="screen")
        data = cell(name, field, frame, rotary)
    except HmiError as exc:
        data = {"name": name, "field": field, "value": None, "text": value, "error": exc.message,
                "rotary": rotary}
    return render_block(request, "offsets.html", "offset_cell", {"cell": data})

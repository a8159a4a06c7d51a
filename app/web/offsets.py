"""Zero-offset table screen: edit in place (one cell per request), activation, audit trail, and the
History of one offset with Restore (undo of a change, design.md §9.2)."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Form, Request

from app.access.deps import needs
from app.deps import MachineDep, OffsetsDep
from app.errors import ConflictError, HmiError
from app.i18n import N_, gettext
from app.services.offsets import same_values

from . import units
from .audit_text import audit_rows, changes
from .templating import render_block, render_screen

router = APIRouter()


def columns(rotary_axes: tuple[str, ...]) -> list[tuple[str, str, str]]:
    """(field, group heading, axis heading) in display order."""
    cols = [(f"trans.{a}", N_("Offset"), a) for a in ("X", "Y", "Z")]
    cols += [(f"trans.{a}", N_("Rotary"), a) for a in rotary_axes]
    cols += [(f"fine.{a}", N_("Fine"), a) for a in ("X", "Y", "Z")]
    cols += [(f"rot.{a}", N_("Rotation"), a) for a in ("X", "Y", "Z")]
    return cols


def value_of(frame: dict, field: str) -> float:
    part, _, axis = field.partition(".")
    return float(frame.get(part, {}).get(axis, 0.0))


def cell(name: str, field: str, frame: dict, rotary: bool = False) -> dict:
    return {"name": name, "field": field, "value": value_of(frame, field), "text": None, "error": None,
            "rotary": rotary}


@router.get("/offsets", name="offsets_screen")
def offsets_screen(request: Request, offsets: OffsetsDep, machine: MachineDep):
    frames = offsets.list()
    cols = columns(machine.rotary_axes)
    rows = [{"name": name, "cells": [cell(name, f, frame, f.split(".")[0] == "rot" or g == "Rotary")
                                     for f, g, _ in cols]}
            for name, frame in frames.items()]
    return render_screen(request, "offsets.html", {"screen": "offsets", "columns": cols, "rows": rows,
                                                   "active": machine.active_offset})


def _gud(request: Request):
    return request.app.state.services.settings.get()


@router.get("/offsets/audit", name="offsets_audit_screen")
def audit_screen(request: Request, offsets: OffsetsDep):
    return render_screen(request, "audit.html", {"screen": "offsets",
                                                 "entries": audit_rows(offsets.audit(50), _gud(request))})


def _history(request: Request, offsets, name: str, message: str = "", level: str = "info", conflict=None,
             asking: dict | None = None):
    offsets.get(name)                      # 404 for an unknown offset
    return render_screen(request, "offset_history.html", {
        "screen": "offsets", "name": name, "entries": audit_rows(offsets.audit(100, name, "offset"), _gud(request)),
        "current": offsets.get(name), "form_message": message, "level": level, "conflict": conflict,
        "asking": asking})


@router.get("/offsets/{name}/history", name="offsets_history_screen")
def history_screen(request: Request, name: str, offsets: OffsetsDep):
    """Every change of one zero offset, newest first, each with Restore (the value before it)."""
    return _history(request, offsets, name)


def _question(request: Request, offsets, entry: dict) -> dict:
    """What Restore of ``entry`` would write (current value → value before the change) and whether
    the offset changed since (then Restore also undoes the later changes)."""
    current = offsets.get(entry["offset"])
    return {"id": entry["id"], "offset": entry["offset"],
            "writes": changes("offset", current, entry["before"], _gud(request)),
            "changed_since": not same_values(current, entry["after"])}


@router.post("/offsets/audit/{audit_id}/restore", name="offsets_restore", dependencies=[needs("offsets")])
def restore(request: Request, audit_id: int, offsets: OffsetsDep, force: Annotated[str, Form()] = "",
            confirm: Annotated[str, Form()] = ""):
    """Restore: first the question (what it writes, whether the offset changed since); confirmed,
    ``POST /api/audit/{id}/undo`` from the History view; a change made since needs "Restore anyway"."""
    entry = offsets.audit_entry(audit_id)
    if entry["kind"] != "offset":
        raise HmiError(f"change #{audit_id} is not a zero-offset change", code="not_undoable")
    if confirm != "1":
        return _history(request, offsets, entry["offset"], asking=_question(request, offsets, entry))
    try:
        done = offsets.restore(entry, force=force == "1")
    except ConflictError as exc:
        return _history(request, offsets, entry["offset"], exc.message, "error", conflict=audit_id)
    return _history(request, offsets, entry["offset"],
                    gettext("%(name)s restored to its value before change #%(id)s (change #%(new)s)",
                            name=entry["offset"], id=audit_id, new=done["audit_id"]))


@router.post("/offsets/{name}/activate", name="offsets_activate", dependencies=[needs("jog")])
def activate(request: Request, name: str, machine: MachineDep, offsets: OffsetsDep):
    machine.activate(name)
    return offsets_screen(request, offsets, machine)


@router.post("/offsets/{name}/{field}", name="offsets_edit_cell", dependencies=[needs("offsets")])
def edit_cell(request: Request, name: str, field: str, offsets: OffsetsDep,
              value: Annotated[str, Form()] = ""):
    """One cell: stored on success; on error the typed text stays with the message, nothing stored."""
    rotary = field.startswith("rot.") or field.split(".")[-1] not in ("X", "Y", "Z")
    typed = value
    if not rotary:                  # a length typed in the screen's unit; storage is mm
        try:
            stored = value_of(offsets.get(name), field)
        except (HmiError, ValueError, TypeError, AttributeError):
            stored = None
        typed = units.mm_text_of(value, request.app.state.services.settings.get(), stored)
    try:
        frame = offsets.put_field(name, field, typed, source="screen")
        data = cell(name, field, frame, rotary)
    except HmiError as exc:
        data = {"name": name, "field": field, "value": None, "text": value, "error": exc.message,
                "rotary": rotary}
    return render_block(request, "offsets.html", "offset_cell", {"cell": data})

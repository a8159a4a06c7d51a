"""Zero-offset table screen: edit in place (one cell per request), activation, audit trail, and the
History of one offset with Restore (undo of a change, design.md §9.2)."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Form, Request

from app.access.deps import needs
from app.deps import MachineDep, OffsetsDep
from app.errors import ConflictError, HmiError
from app.i18n import N_

from . import units
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


def changes(before, after, prefix: str = "") -> list[str]:
    """"trans.X: 0.000 → 12.500" for every value that differs (any kind of audited data)."""
    if isinstance(before, dict) or isinstance(after, dict):
        before, after = before if isinstance(before, dict) else {}, after if isinstance(after, dict) else {}
        out = []
        for key in list(dict.fromkeys([*before, *after])):
            out += changes(before.get(key), after.get(key), f"{prefix}{key}.")
        return out
    if before == after:
        return []
    return [f"{prefix.rstrip('.')}: {_text(before)} → {_text(after)}"]


def _text(value) -> str:
    if value is None:
        return "–"
    if isinstance(value, float):
        return f"{value:.4f}".rstrip("0").rstrip(".") if value != int(value) else f"{value:.3f}"
    return str(value)


def who_text(entry: dict) -> str:
    who = entry.get("who") or "–"
    return f"{who} (level {entry['level']})" if entry.get("level") is not None else who


def audit_rows(entries: list[dict]) -> list[dict]:
    return [{**e, "changes": changes(e.get("before"), e.get("after")) or ["(no change)"], "who_text": who_text(e)}
            for e in entries]


@router.get("/offsets/audit", name="offsets_audit_screen")
def audit_screen(request: Request, offsets: OffsetsDep):
    return render_screen(request, "audit.html", {"screen": "offsets", "entries": audit_rows(offsets.audit(50))})


def _history(request: Request, offsets, name: str, message: str = "", level: str = "info", conflict=None):
    offsets.get(name)                      # 404 for an unknown offset
    return render_screen(request, "offset_history.html", {
        "screen": "offsets", "name": name, "entries": audit_rows(offsets.audit(100, name, "offset")),
        "current": offsets.get(name), "form_message": message, "level": level, "conflict": conflict})


@router.get("/offsets/{name}/history", name="offsets_history_screen")
def history_screen(request: Request, name: str, offsets: OffsetsDep):
    """Every change of one zero offset, newest first, each with Restore (the value before it)."""
    return _history(request, offsets, name)


@router.post("/offsets/audit/{audit_id}/restore", name="offsets_restore", dependencies=[needs("offsets")])
def restore(request: Request, audit_id: int, offsets: OffsetsDep, force: Annotated[str, Form()] = ""):
    """Restore: ``POST /api/audit/{id}/undo`` from the History view; a change made since is named and
    needs "Restore anyway"."""
    entry = offsets.audit_entry(audit_id)
    if entry["kind"] != "offset":
        raise HmiError(f"change #{audit_id} is not a zero-offset change", code="not_undoable")
    try:
        done = offsets.restore(entry, force=force == "1")
    except ConflictError as exc:
        return _history(request, offsets, entry["offset"], exc.message, "error", conflict=audit_id)
    return _history(request, offsets, entry["offset"],
                    f"{entry['offset']} restored to its value before change #{audit_id} (change #{done['audit_id']})")


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

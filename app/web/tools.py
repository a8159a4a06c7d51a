"""Tool table screen: geometry and wear edited in place, the tool in the spindle marked, tool change."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Form, Request

from app.access.deps import needs
from app.deps import MachineDep, ToolsDep
from app.errors import HmiError
from app.i18n import N_, _

from . import units
from .templating import render_block, render_screen

router = APIRouter()

COLUMNS = [("name", N_("Name")), ("type", N_("Type")), ("length", N_("Length")), ("radius", N_("Radius")),
           ("wear.length", N_("Wear L")), ("wear.radius", N_("Wear R"))]
# a lathe (turning.md §0.4, turning §10.2): cutting-edge position, L1 in X, L2 in Z, their wear (radius values)
LATHE_COLUMNS = [("name", N_("Name")), ("type", N_("Type")), ("sl", N_("SL")), ("l1", N_("L1 (X)")), ("l2", N_("L2 (Z)")),
                 ("radius", N_("Radius")), ("wear.l1", N_("Wear L1")), ("wear.l2", N_("Wear L2")), ("wear.radius", N_("Wear R"))]


LENGTH_FIELDS = ("length", "radius", "wear.length", "wear.radius", "l1", "l2", "wear.l1", "wear.l2")


def value_of(tool: dict, field: str):
    part, _, sub = field.partition(".")
    return (tool.get(part) or {}).get(sub) if sub else tool.get(part)


def tool_cell(t: int, field: str, value, text=None, error=None) -> dict:
    return {"t": t, "field": field, "value": value, "text": text, "error": error}


def tool_rows(tools: list[dict], columns=COLUMNS) -> list[dict]:
    return [{"t": tool["t"], "tool": tool,
             "cells": [tool_cell(tool["t"], f, value_of(tool, f)) for f, _ in columns]} for tool in tools]


def _screen(request: Request, tools: ToolsDep, extra: dict | None = None):
    lathe = request.app.state.services.machine.is_lathe
    columns = LATHE_COLUMNS if lathe else COLUMNS
    return render_screen(request, "tools.html", {"screen": "tools", "columns": columns,
                                                 "rows": tool_rows(tools.list(), columns), **(extra or {})})


@router.get("/tools", name="tools_screen")
def tools_screen(request: Request, tools: ToolsDep):
    return _screen(request, tools)


@router.post("/tools/new", name="tools_new", dependencies=[needs("tools")])
def new_tool(request: Request, tools: ToolsDep, t: Annotated[str, Form()] = ""):
    try:
        number = int(t)
    except ValueError:
        return _screen(request, tools, {"new_error": _("T: enter a tool number"), "new_text": t})
    try:
        tools.get(number)
        return _screen(request, tools, {"new_error": _("T%(t)s exists already", t=number), "new_text": t})
    except HmiError:
        pass
    try:
        tools.put(number, {}, source="screen")
    except HmiError as exc:
        return _screen(request, tools, {"new_error": exc.message, "new_text": t})
    return _screen(request, tools)


@router.post("/tools/{t}/load", name="tools_load", dependencies=[needs("jog")])
def load_tool(request: Request, t: int, machine: MachineDep, tools: ToolsDep):
    """Tool change into the spindle (T 0 unloads)."""
    try:
        machine.change_tool(t)
    except HmiError as exc:
        return _screen(request, tools, {"message": exc.message})
    return _screen(request, tools)


@router.post("/tools/{t}/{field}", name="tools_edit_cell", dependencies=[needs("tools")])
def edit_cell(request: Request, t: int, field: str, tools: ToolsDep, value: Annotated[str, Form()] = ""):
    typed = value
    if field in LENGTH_FIELDS:          # typed in the screen's unit; storage is mm
        try:
            stored = value_of(tools.get(t), field)
        except (HmiError, ValueError, TypeError, AttributeError, KeyError):
            stored = None
        typed = units.mm_text_of(value, request.app.state.services.settings.get(),
                                 stored if isinstance(stored, int | float) else None)
    try:
        tool = tools.put_field(t, field, typed)
        data = tool_cell(t, field, value_of(tool, field))
    except HmiError as exc:
        data = tool_cell(t, field, None, value, exc.message)
    return render_block(request, "tools.html", "tool_cell", {"cell": data})



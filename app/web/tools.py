"""Tool table screen: geometry and wear edited in place, the tool in the spindle marked, tool change."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Form, Request

from app.deps import MachineDep, ToolsDep
from app.errors import HmiError

from .templating import render_block, render_screen

router = APIRouter()

COLUMNS = [("name", "Name"), ("type", "Type"), ("length", "Length"), ("radius", "Radius"),
           ("wear.length", "Wear L"), ("wear.radius", "Wear R")]


def value_of(tool: dict, field: str):
    part, _, sub = field.partition(".")
    return tool[part][sub] if sub else tool[part]


def tool_cell(t: int, field: str, value, text=None, error=None) -> dict:
    return {"t": t, "field": field, "value": value, "text": text, "error": error}


def tool_rows(tools: list[dict]) -> list[dict]:
    return [{"t": tool["t"], "tool": tool,
             "cells": [tool_cell(tool["t"], f, value_of(tool, f)) for f, _ in COLUMNS]} for tool in tools]


def _screen(request: Request, tools: ToolsDep, extra: dict | None = None):
    return render_screen(request, "tools.html", {"screen": "tools", "columns": COLUMNS,
                                                 "rows": tool_rows(tools.list()), **(extra or {})})


@router.get("/tools")
def tools_screen(request: Request, tools: ToolsDep):
    return _screen(request, tools)


@router.post("/tools/new")
def new_tool(request: Request, tools: ToolsDep, t: Annotated[str, Form()] = ""):
    try:
        number = int(t)
    except ValueError:
        return _screen(request, tools, {"new_error": f"T: {t!r} is not a tool number", "new_text": t})
    try:
        tools.get(number)
        return _screen(request, tools, {"new_error": f"T{number} exists already", "new_text": t})
    except HmiError:
        pass
    try:
        tools.put(number, {})
    except HmiError as exc:
        return _screen(request, tools, {"new_error": exc.message, "new_text": t})
    return _screen(request, tools)


@router.post("/tools/{t}/load")
def load_tool(request: Request, t: int, machine: MachineDep, tools: ToolsDep):
    """Tool change into the spindle (T 0 unloads)."""
    try:
        machine.change_tool(t)
    except HmiError as exc:
        return _screen(request, tools, {"message": exc.message})
    return _screen(request, tools)


@router.post("/tools/{t}/{field}")
def edit_cell(request: Request, t: int, field: str, tools: ToolsDep, value: Annotated[str, Form()] = ""):
    try:
        tool = tools.put_field(t, field, value)
        data = tool_cell(t, field, value_of(tool, field))
    except HmiError as exc:
        data = tool_cell(t, field, None, value, exc.message)
    return render_block(request, "tools.html", "tool_cell", {"cell": data})



"""EV / MV memories screen: the empirical and mean values of the tool-offset strategy
(measuring-math §3.3, manual §1.10), edited in place like the tool list."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Form, Request

from app.access.deps import needs
from app.deps import MachineDep, MemoriesDep
from app.errors import HmiError
from app.i18n import N_
from app.services.memories import WRITE_FUNCTION as MEMORY_WRITE

from .templating import render_block, render_screen

router = APIRouter()

KIND_LABELS = {"ev": N_("Empirical value _EV"), "mv": N_("Mean value _MV")}     # translated where shown


def memory_cell(kind: str, n: int, value, text=None, error=None) -> dict:
    return {"kind": kind, "n": n, "value": value, "text": text, "error": error}


def memory_rows(listing: dict) -> list[dict]:
    by_n: dict[int, dict] = {}
    for kind in KIND_LABELS:
        for item in listing[kind]:
            by_n.setdefault(item["n"], {"n": item["n"], "cells": []})["cells"].append(
                memory_cell(kind, item["n"], item["value"]))
    return [by_n[n] for n in sorted(by_n)]


@router.get("/memories", name="memories_screen")
def memories_screen(request: Request, memories: MemoriesDep):
    return render_screen(request, "memories.html", {"screen": "tools", "kinds": KIND_LABELS,
                                                    "rows": memory_rows(memories.list())})


@router.post("/memories/{kind}/{n}", name="memories_edit_cell", dependencies=[needs(MEMORY_WRITE)])
def edit_cell(request: Request, kind: str, n: int, memories: MemoriesDep, value: Annotated[str, Form()] = ""):
    text = value.strip()
    try:
        number = float(text.replace(",", "."))
    except ValueError:
        cell = memory_cell(kind, n, None, value, f"{text or 'empty'}: enter a number in mm")
    else:
        try:
            stored = memories.put(kind, n, number, source="screen")
            cell = memory_cell(kind, n, stored["value"])
        except HmiError as exc:
            cell = memory_cell(kind, n, None, value, exc.message.partition(": ")[2] or exc.message)
    return render_block(request, "memories.html", "memory_cell", {"cell": cell})


@router.post("/memories/next-part", name="memories_next_part", dependencies=[needs("scenario")])
def next_part(request: Request, memories: MemoriesDep, machine: MachineDep):
    """Simulator: the next part of the machined series is clamped (design.md §9.3)."""
    try:
        message = f"Part {machine.machine_part(0.0)['part']} clamped: measure it"
    except HmiError as exc:
        message = exc.message
    return render_screen(request, "memories.html", {"screen": "tools", "kinds": KIND_LABELS,
                                                    "rows": memory_rows(memories.list()), "message": message})

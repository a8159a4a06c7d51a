"""Workpiece probe data screen (_WP[k], spec/jog-measuring.md §5, §8.4): the records, and one
record's ball diameter, effective diameter, trigger values per travel direction, skew, length
convention and how it was calibrated (when, feed, override, gauge, tool). Editable with
validation (the same rules as ``PUT /api/probes/{n}``); the calibration itself is
``Measure workpiece > Calibrate probe``. The record marked active is the one the measuring
tasks use: the record bound to the tool in the spindle, else _JM_I[1]."""

from __future__ import annotations

from functools import partial

from fastapi import APIRouter, Request

from app.deps import MachineDep, ProbesDep, SettingsDep
from app.services.measuring import probe_number_for

from . import probe_records
from .probe_records import number
from .templating import render_screen

router = APIRouter()

# travel direction -> (_WP index, what the value is)
TRIGGERS = [("X-", 1, "travel −X (abscissa minus)"), ("X+", 2, "travel +X (abscissa plus)"),
            ("Y-", 3, "travel −Y (ordinate minus)"), ("Y+", 4, "travel +Y (ordinate plus)"),
            ("Z-", 5, "travel −Z (infeed minus)")]


def parse_form(form, stored: dict) -> tuple[dict, dict[str, str]]:
    """Form -> record (the stored record with the edited fields), {field: error}."""
    errors: dict[str, str] = {}
    old = stored.get("trigger") or {}
    edited = {key for key, _index, _text in TRIGGERS}
    trigger = {k: v for k, v in old.items() if k not in edited}
    for key, _index, _text in TRIGGERS:
        value = number(form.get(f"trigger.{key}", ""), f"trigger.{key}", errors, old.get(key))
        if value is not None:
            trigger[key] = value
    record = {**stored, "trigger": trigger}
    for name in ("ball_diameter", "effective_diameter"):
        value = number(form.get(name, ""), name, errors, stored.get(name))
        if name not in errors:
            if value is None and name == "ball_diameter":
                errors[name] = "required"
            record[name] = 0.0 if value is None else value
    skew = []
    for i, axis in enumerate("XY"):
        old = (stored.get("skew") or [0.0, 0.0])[i]
        value = number(form.get(f"skew.{axis}", ""), f"skew.{axis}", errors, old)
        skew.append(old if value is None else value)
    record["skew"] = skew
    tool_text = str(form.get("tool", "")).strip()
    if tool_text == "":
        record["tool"] = None
    else:
        try:
            record["tool"] = int(tool_text)
        except ValueError:
            errors["tool"] = f"{tool_text!r} is not a tool number"
    for axis in "XY":
        plus, minus = trigger.get(f"{axis}+"), trigger.get(f"{axis}-")
        if plus is not None and plus >= 0:
            errors[f"trigger.{axis}+"] = (f"must be negative: travel +{axis} switches with "
                                            "the ball centre before the wall")
        if minus is not None and minus <= 0:
            errors[f"trigger.{axis}-"] = (f"must be positive: travel −{axis} switches with "
                                            "the ball centre past the wall")
    return record, errors


def _screen(request: Request, probes, settings, machine, n: int | None = None, record: dict | None = None,
            errors: dict | None = None, message: str | None = None, level: str = "info",
            texts: dict | None = None):
    records = probes.list()
    spindle = machine.status().get("tool")
    active = probe_number_for(records, spindle, int(settings.get().probe_number))
    n = active if n is None else n
    if record is None:
        record = probe_records.stored_or_new(probes, n)
    return render_screen(request, "probes.html", {
        "screen": "probes", "n": n, "active": active, "spindle": spindle,
        "records": records, "record": record, "triggers": TRIGGERS, "errors": errors or {},
        "texts": texts or {}, "message": message, "level": level,
        "length_to_tip_gud": bool(settings.get().length_to_tip)})


@router.get("/probes")
def probes_screen(request: Request, probes: ProbesDep, settings: SettingsDep, machine: MachineDep):
    return probe_records.show(request, probes, partial(_screen, request, probes, settings, machine))


@router.post("/probes/{n}")
async def save_probe(request: Request, n: int, probes: ProbesDep, settings: SettingsDep, machine: MachineDep):
    return await probe_records.save(request, probes, n, parse_form,
                                    partial(_screen, request, probes, settings, machine))

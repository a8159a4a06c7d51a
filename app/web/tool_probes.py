"""Tool-probe data screen (_TP[n], spec/jog-measuring.md §7.2, §8.3): trigger values per travel
direction (MCS, tool edge at switching), disc diameter, type, axes code, DZ, and how the probe
was calibrated (when, with which tool, feed, override). Editable with validation; the
calibration itself is the ``Measure tool > Calibrate probe`` screen."""

from __future__ import annotations

from fastapi import APIRouter, Request
from pydantic import ValidationError

from app.deps import SettingsDep, ToolProbesDep
from app.errors import HmiError
from app.services.probes import MAX_PROBE, ToolProbeData
from app.services.settings import validation_errors

from .templating import render_screen

router = APIRouter()

# travel direction -> (_TP index, what the value is)
TRIGGERS = [("X-", 0, "travel −X: the probe's +X face"), ("X+", 1, "travel +X: the probe's −X face"),
            ("Y-", 2, "travel −Y: the probe's +Y face"), ("Y+", 3, "travel +Y: the probe's −Y face"),
            ("Z-", 4, "travel −Z: the probe's upper face")]
TYPES = [(0, "0 cube"), (101, "101 disc in XY"), (201, "201 disc in ZX"), (301, "301 disc in YZ")]
NUMBERS = ("disc_diameter", "dz")


def shown(value) -> str:
    """How the screen shows a stored mm value (the template's '%.4f')."""
    return "" if value is None else f"{float(value):.4f}"


def _number(text: str, name: str, errors: dict, stored=None) -> float | None:
    """Typed text -> mm; the untouched display text of ``stored`` keeps its full precision."""
    text = (text or "").strip().replace(",", ".")
    if text == "":
        return None
    if stored is not None and text == shown(stored):
        return float(stored)
    try:
        return float(text)
    except ValueError:
        errors[name] = f"{text!r} is not a number"
        return None


def check_axes(code: int) -> str | None:
    """E_MESS_MT_AX / _TP[k,7] digit code (spec §8.3): units X, tens Y, hundreds Z; 0..3 each."""
    digits = f"{code:03d}"
    if len(digits) != 3 or any(d not in "0123" for d in digits):
        return "each digit must be 0 (no), 1 (minus), 2 (plus) or 3 (both)"
    if digits[0] not in "13":
        return "the tool axis (hundreds digit) must allow the minus direction"
    return None


def parse_form(form, stored: dict) -> tuple[dict, dict[str, str]]:
    """Form -> record (stored record with the edited fields), {field: error}."""
    errors: dict[str, str] = {}
    trigger: dict[str, float] = {}
    for key, _index, _text in TRIGGERS:
        value = _number(form.get(f"trigger.{key}", ""), f"trigger.{key}", errors,
                        (stored.get("trigger") or {}).get(key))
        if value is not None:
            trigger[key] = value
    record = {**stored, "trigger": trigger}
    for name in NUMBERS:
        value = _number(form.get(name, ""), name, errors, stored.get(name))
        if name not in errors:
            record[name] = 0.0 if value is None and name == "disc_diameter" else value
            if record[name] is None:
                errors[name] = "required"
    for name in ("type", "axes"):
        text = str(form.get(name, "")).strip()
        try:
            record[name] = int(text)
        except ValueError:
            errors[name] = f"{text!r} is not a whole number"
    if "axes" not in errors and isinstance(record.get("axes"), int):
        problem = check_axes(record["axes"])
        if problem:
            errors["axes"] = problem
    for axis in "XY":
        lo, hi = trigger.get(f"{axis}+"), trigger.get(f"{axis}-")
        if lo is not None and hi is not None and hi <= lo:
            errors[f"trigger.{axis}-"] = (f"must be greater than {axis}+ ({lo:g}): travel −{axis} "
                                          f"switches at the probe's +{axis} face")
    return record, errors


def _view(record: dict) -> dict:
    trig = record.get("trigger") or {}
    centre = {a: (trig[f"{a}-"] + trig[f"{a}+"]) / 2.0 for a in "XY" if f"{a}-" in trig and f"{a}+" in trig}
    width = {a: trig[f"{a}-"] - trig[f"{a}+"] for a in centre}
    return {"centre": centre, "width": width}


def _screen(request: Request, tool_probes, settings, n: int | None = None, record: dict | None = None,
            errors: dict | None = None, message: str | None = None, level: str = "info",
            texts: dict | None = None):
    active = int(settings.get().tool_probe_number)
    n = active if n is None else n
    numbers = sorted({r["number"] for r in tool_probes.list()} | {active, n})
    if record is None:
        try:
            record = tool_probes.get(n)
        except HmiError:
            record = {**ToolProbeData(number=n).model_dump(mode="json")}
    return render_screen(request, "tool_probes.html", {
        "screen": "tool_probes", "n": n, "active": active, "numbers": numbers, "record": record,
        "triggers": TRIGGERS, "types": TYPES, "errors": errors or {}, "texts": texts or {},
        "message": message, "level": level, "view": _view(record)})


def _record_number(text) -> int | None:
    try:
        n = int(text)
    except (TypeError, ValueError):
        return None
    return n if 1 <= n <= MAX_PROBE else None


@router.get("/tool-probes")
def tool_probes_screen(request: Request, tool_probes: ToolProbesDep, settings: SettingsDep):
    n = _record_number(request.query_params.get("n")) if "n" in request.query_params else None
    if "n" in request.query_params and n is None:
        return _screen(request, tool_probes, settings, message=f"n: tool probe number must be 1..{MAX_PROBE}",
                       level="error")
    return _screen(request, tool_probes, settings, n)


@router.post("/tool-probes/{n}")
async def save_tool_probe(request: Request, n: int, tool_probes: ToolProbesDep, settings: SettingsDep):
    if _record_number(n) is None:
        return _screen(request, tool_probes, settings, message=f"n: tool probe number must be 1..{MAX_PROBE}",
                       level="error")
    form = await request.form()
    try:
        stored = tool_probes.get(n)
    except HmiError:
        stored = ToolProbeData(number=n).model_dump(mode="json")
    record, errors = parse_form(form, stored)
    if not errors:
        try:
            ToolProbeData.model_validate(record)
        except ValidationError as exc:
            errors = validation_errors(exc)
    texts = {k: str(v) for k, v in form.items()}
    if errors:
        return _screen(request, tool_probes, settings, n, record=record, errors=errors, texts=texts, level="error",
                       message=f"Not saved: {len(errors)} field(s) need correction")
    try:
        saved = tool_probes.put(n, record)
    except HmiError as exc:
        return _screen(request, tool_probes, settings, n, record=record, errors={exc.field or "form": exc.message},
                       texts=texts, message=exc.message, level="error")
    return _screen(request, tool_probes, settings, n, record=saved, message=f"Tool probe {n} saved")

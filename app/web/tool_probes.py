"""Tool-probe data screen (_TP[n], spec/jog-measuring.md §7.2, jog-measuring §8.3): trigger values per travel
direction (MCS, tool edge at switching), disc diameter, type, axes code, DZ, and how the probe
was calibrated (when, with which tool, feed, override). Editable with validation; the
calibration itself is the ``Measure tool > Calibrate probe`` screen."""

from __future__ import annotations

from functools import partial

from fastapi import APIRouter, Request

from app.access.deps import needs
from app.deps import SettingsDep, ToolProbesDep
from app.i18n import N_
from engine.toolmeasure import probe_centre

from . import probe_records
from .probe_records import number
from .templating import render_screen

router = APIRouter()

# travel direction -> (_TP index, what the value is)
TRIGGERS = [("X-", 0, "travel −X: the probe's +X face"), ("X+", 1, "travel +X: the probe's −X face"),
            ("Y-", 2, "travel −Y: the probe's +Y face"), ("Y+", 3, "travel +Y: the probe's −Y face"),
            ("Z-", 4, "travel −Z: the probe's upper face")]
# a lathe's _TP[k] / _TPW[k] (turning.md §0.7): the faces by the travel direction that touches them
LATHE_TRIGGERS = [("Z-", 0, "travel −Z: the right face"), ("Z+", 1, "travel +Z: the left face"),
                  ("X-", 2, "travel −X: the top face"), ("X+", 3, "travel +X: the bottom face")]
TYPES = [(0, N_("0 cube")), (101, N_("101 disc in XY")), (201, N_("201 disc in ZX")), (301, N_("301 disc in YZ"))]
NUMBERS = ("disc_diameter", "dz")


def check_axes(code: int) -> str | None:
    """E_MESS_MT_AX / _TP[k,7] digit code (jog-measuring §8.3): units X, tens Y, hundreds Z; 0..3 each."""
    digits = f"{code:03d}"
    if len(digits) != 3 or any(d not in "0123" for d in digits):
        return "each digit must be 0 (no), 1 (minus), 2 (plus) or 3 (both)"
    if digits[0] not in "13":
        return "the tool axis (hundreds digit) must allow the minus direction"
    return None


def parse_form(form, stored: dict, lathe: bool = False) -> tuple[dict, dict[str, str]]:
    """Form -> record (stored record with the edited fields), {field: error}."""
    errors: dict[str, str] = {}
    trigger: dict[str, float] = {}
    for key, _index, _text in (LATHE_TRIGGERS if lathe else TRIGGERS):
        value = number(form.get(f"trigger.{key}", ""), f"trigger.{key}", errors,
                       (stored.get("trigger") or {}).get(key))
        if value is not None:
            trigger[key] = value
    record = {**stored, "trigger": trigger}
    for name in NUMBERS:
        value = number(form.get(name, ""), name, errors, stored.get(name))
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
    for axis in ("ZX" if lathe else "XY"):
        lo, hi = trigger.get(f"{axis}+"), trigger.get(f"{axis}-")
        if lo is not None and hi is not None and hi <= lo:
            errors[f"trigger.{axis}-"] = (f"must be greater than {axis}+ ({lo:g}): travel −{axis} "
                                          f"switches at the probe's +{axis} face")
    return record, errors


def _view(record: dict) -> dict:
    """Probe centre (engine) and width per plane axis with both trigger values known."""
    trig = record.get("trigger") or {}
    centre = {a: c for a, c in probe_centre(trig).items() if a in "XY"}
    return {"centre": centre, "width": {a: trig[f"{a}-"] - trig[f"{a}+"] for a in centre}}


def _screen(request: Request, tool_probes, settings, n: int | None = None, record: dict | None = None,
            errors: dict | None = None, message: str | None = None, level: str = "info",
            texts: dict | None = None):
    active = int(settings.get().tool_probe_number)
    n = active if n is None else n
    numbers = sorted({r["number"] for r in tool_probes.list()} | {active, n})
    if record is None:
        record = probe_records.stored_or_new(tool_probes, n)
    lathe = request.app.state.services.machine.is_lathe
    return render_screen(request, "tool_probes.html", {
        "screen": "tool_probes", "n": n, "active": active, "numbers": numbers, "record": record,
        "triggers": LATHE_TRIGGERS if lathe else TRIGGERS, "types": TYPES, "errors": errors or {},
        "texts": texts or {}, "message": message, "level": level, "view": {} if lathe else _view(record)})


@router.get("/tool-probes", name="tool_probes_screen")
def tool_probes_screen(request: Request, tool_probes: ToolProbesDep, settings: SettingsDep):
    return probe_records.show(request, tool_probes, partial(_screen, request, tool_probes, settings))


@router.post("/tool-probes/{n}", name="tool_probes_save", dependencies=[needs("probe_data")])
async def save_tool_probe(request: Request, n: int, tool_probes: ToolProbesDep, settings: SettingsDep):
    lathe = request.app.state.services.machine.is_lathe
    return await probe_records.save(request, tool_probes, n, partial(parse_form, lathe=lathe),
                                    partial(_screen, request, tool_probes, settings))

"""Workpiece probe data screen (_WP[k], spec/jog-measuring.md §5, jog-measuring §8.4): the records, and one
record's ball diameter, effective diameter, trigger values per travel direction, skew, length
convention and how it was calibrated (when, feed, override, gauge, tool). Editable with
validation (the same rules as ``PUT /api/probes/{n}``); the calibration itself is
``Measure workpiece > Calibrate probe``. The record marked active is the one the measuring
tasks use: the record bound to the tool in the spindle, else _JM_I[1]."""

from __future__ import annotations

from functools import partial

from fastapi import APIRouter, Request

from app.access.deps import needs
from app.deps import MachineDep, ProbesDep, SettingsDep
from app.errors import HmiError
from app.i18n import N_
from app.services.lathe_data import GrooveService
from app.services.measuring import probe_number_for

from . import probe_records
from .probe_records import number
from .templating import render_screen

router = APIRouter()

# travel direction -> (_WP index, what the value is)
TRIGGERS = [("X-", 1, "travel −X (abscissa minus)"), ("X+", 2, "travel +X (abscissa plus)"),
            ("Y-", 3, "travel −Y (ordinate minus)"), ("Y+", 4, "travel +Y (ordinate plus)"),
            ("Z-", 5, "travel −Z (infeed minus)")]
# a lathe's _WP[k] (turning.md §0.7): trigger values per travel direction, radius values, G18
LATHE_TRIGGERS = [("Z-", 1, "travel −Z (abscissa minus)"), ("Z+", 2, "travel +Z (abscissa plus)"),
                  ("X-", 3, "travel −X (ordinate minus)"), ("X+", 4, "travel +X (ordinate plus)")]


# what made a calibration invalid (app.workflow.probe_trust.INVALID_REASONS), in the operator's words
REASON_TEXTS = {
    "not_calibrated": N_("not calibrated yet"),
    "collision": N_("a collision after the calibration"),
    "broken_probe": N_("the probe broke (overtravel) after the calibration"),
    "ball_changed": N_("the ball or stylus data changed after the calibration"),
    "other_probe": N_("another probe was loaded after the calibration"),
    "age": N_("the calibration is older than its time limit"),
}
CHART_W, CHART_H, CHART_PAD = 360, 120, 30      # the repeatability chart, px of its viewBox
HISTORY = 20                                     # checks shown in the chart


def repeatability_chart(checks: list[dict], limit: float) -> dict | None:
    """The last checks' 2σ (µm, oldest left) and the limit as an SVG chart (server-drawn, as the
    run chart of the results screens); None without a check."""
    values = [float(c["data"]["two_sigma"]) * 1000.0 for c in reversed(checks[:HISTORY])
              if isinstance((c.get("data") or {}).get("two_sigma"), int | float)]
    if not values:
        return None
    top = max(max(values), limit * 1000.0) * 1.2 or 1.0
    left, right, bottom = CHART_PAD + 10, CHART_W - 10, CHART_H - CHART_PAD

    def y(v: float) -> float:
        return round(bottom - (bottom - 10) * v / top, 1)

    step = (right - left) / max(len(values) - 1, 1)
    dots = [{"x": round(left + i * step, 1), "y": y(v), "value": round(v, 2), "over": v > limit * 1000.0}
            for i, v in enumerate(values)]
    return {"width": CHART_W, "height": CHART_H, "left": left, "right": right, "bottom": bottom,
            "limit_y": y(limit * 1000.0), "limit": round(limit * 1000.0, 2), "top": round(top, 2),
            "dots": dots, "path": " ".join(f"{d['x']},{d['y']}" for d in dots)}


def _health(request: Request, n: int, record: dict, settings) -> dict:
    """The record's health for the screen: validity, its reason, the events, the chart."""
    services = request.app.state.services
    events = services.probe_health.history("workpiece", n) if services.probe_health is not None else []
    checks = [e for e in events if e["event"] == "repeatability"]
    gud = settings.get()
    return {"health_record": record, "health_events": [e for e in events if e["event"] == "invalidated"][:10],
            "health_checks": checks[:5], "reason_texts": REASON_TEXTS,
            "chart": repeatability_chart(checks, float(gud.repeatability_limit)),
            "max_age_h": float(gud.calibration_max_age_h)}


def parse_form(form, stored: dict, lathe: bool = False) -> tuple[dict, dict[str, str]]:
    """Form -> record (the stored record with the edited fields), {field: error}."""
    errors: dict[str, str] = {}
    trigger = _triggers(form, stored.get("trigger") or {}, LATHE_TRIGGERS if lathe else TRIGGERS, errors)
    record = {**stored, "trigger": trigger}
    for name in ("ball_diameter", "effective_diameter"):
        value = number(form.get(name, ""), name, errors, stored.get(name))
        if name not in errors:
            if value is None and name == "ball_diameter":
                errors[name] = "required"
            record[name] = 0.0 if value is None else value
    if lathe:                                    # _WP[k,7]/[8]: position deviation Z, X
        record["position_deviation"] = _position_deviation(form, stored, errors)
    else:
        record["skew"] = _skew(form, stored, errors)
    tool_text = str(form.get("tool", "")).strip()
    if tool_text == "":
        record["tool"] = None
    else:
        try:
            record["tool"] = int(tool_text)
        except ValueError:
            errors["tool"] = f"{tool_text!r} is not a tool number"
    _trigger_signs(trigger, "ZX" if lathe else "XY", errors)
    if record.get("lobing") and any(record.get(k) != stored.get(k) for k in ("trigger", "effective_diameter", "skew")):
        record["lobing"] = None          # the calibrated trigger map no longer agrees with typed values
    return record, errors


def _triggers(form, old: dict, triggers, errors: dict[str, str]) -> dict:
    """The stored trigger values with the form's (those the form does not edit kept)."""
    edited = {key for key, _index, _text in triggers}
    trigger = {k: v for k, v in old.items() if k not in edited}
    for key, _index, _text in triggers:
        value = number(form.get(f"trigger.{key}", ""), f"trigger.{key}", errors, old.get(key))
        if value is not None:
            trigger[key] = value
    return trigger


def _position_deviation(form, stored: dict, errors: dict[str, str]) -> dict:
    deviation = dict(stored.get("position_deviation") or {})
    for axis in "ZX":
        value = number(form.get(f"position_deviation.{axis}", ""), f"position_deviation.{axis}", errors,
                       deviation.get(axis))
        deviation[axis] = deviation.get(axis, 0.0) if value is None else value
    return deviation


def _skew(form, stored: dict, errors: dict[str, str]) -> list:
    skew = []
    for i, axis in enumerate("XY"):
        old = (stored.get("skew") or [0.0, 0.0])[i]
        value = number(form.get(f"skew.{axis}", ""), f"skew.{axis}", errors, old)
        skew.append(old if value is None else value)
    return skew


def _trigger_signs(trigger: dict, axes: str, errors: dict[str, str]) -> None:
    """t(+) < 0 and t(−) > 0: the ball centre switches before (+) resp. past (−) the wall."""
    for axis in axes:
        plus, minus = trigger.get(f"{axis}+"), trigger.get(f"{axis}-")
        if plus is not None and plus >= 0:
            errors[f"trigger.{axis}+"] = (f"must be negative: travel +{axis} switches with "
                                            "the ball centre before the wall")
        if minus is not None and minus <= 0:
            errors[f"trigger.{axis}-"] = (f"must be positive: travel −{axis} switches with "
                                            "the ball centre past the wall")


def _screen(request: Request, probes, settings, machine, n: int | None = None, record: dict | None = None,
            errors: dict | None = None, message: str | None = None, level: str = "info",
            texts: dict | None = None):
    records = probes.list()
    spindle = machine.status().get("tool")
    active = probe_number_for(records, spindle, int(settings.get().probe_number))
    n = active if n is None else n
    if record is None:
        record = probe_records.stored_or_new(probes, n)
    lathe = machine.is_lathe
    extra = _lathe_context(request, record) if lathe else {}
    return render_screen(request, "probes.html", {
        "screen": "probes", "n": n, "active": active, "spindle": spindle,
        "records": records, "record": record, "triggers": LATHE_TRIGGERS if lathe else TRIGGERS,
        "errors": errors or {}, "texts": texts or {}, "message": message, "level": level,
        "length_to_tip_gud": bool(settings.get().length_to_tip), **extra,
        **_health(request, n, probes.get(n) if any(r["number"] == n for r in records) else record, settings)})


def _lathe_context(request: Request, record: dict) -> dict:
    """The lathe probe's tool data (L1, L2, SL, R) and the reference grooves _KB."""
    services = request.app.state.services
    tool = None
    if record.get("tool"):
        try:
            tool = services.tools.get(int(record["tool"]))
        except HmiError:
            tool = None
    return {"lathe_probe_tool": tool, "grooves": GrooveService(services.db).list(), "groove_keys": GROOVE_FIELDS}


GROOVE_FIELDS = [("x_minus", "SL 7: wall −X side", "_KB[k,1]"), ("x_plus", "SL 7: wall +X side", "_KB[k,0]"),
                 ("bottom_z", "SL 7: bottom Z", "_KB[k,2]"), ("z_minus", "SL 8: wall −Z side", "_KB[k,4]"),
                 ("z_plus", "SL 8: wall +Z side", "_KB[k,3]"), ("top_x", "SL 8: upper edge X", "_KB[k,5]"),
                 ("bottom_x", "SL 8: bottom X", "_KB[k,6]")]


@router.get("/probes", name="probes_screen")
def probes_screen(request: Request, probes: ProbesDep, settings: SettingsDep, machine: MachineDep):
    return probe_records.show(request, probes, partial(_screen, request, probes, settings, machine))


@router.post("/probes/{n}", name="probes_save", dependencies=[needs("probe_data")])
async def save_probe(request: Request, n: int, probes: ProbesDep, settings: SettingsDep, machine: MachineDep):
    return await probe_records.save(request, probes, n, partial(parse_form, lathe=machine.is_lathe),
                                    partial(_screen, request, probes, settings, machine))


@router.post("/probes/grooves/{k}", name="probes_groove_save", dependencies=[needs("probe_data")])
async def save_groove(request: Request, k: int, probes: ProbesDep, settings: SettingsDep, machine: MachineDep):
    """A reference groove record _KB[k−1] as entered (machine-related radius values, turning.md §0.6)."""
    form = await request.form()
    values: dict[str, float] = {}
    errors: dict[str, str] = {}
    for key, _label, _gud in GROOVE_FIELDS:
        value = number(form.get(f"groove.{key}", ""), f"groove.{key}", errors)
        if value is not None and value != 0.0:
            values[key] = value
    screen = partial(_screen, request, probes, settings, machine)
    if errors:
        return screen(level="error", message=f"Groove {k} not saved: " + "; ".join(errors.values()))
    try:
        GrooveService(request.app.state.services.db).put(k, values)
    except HmiError as exc:
        return screen(level="error", message=exc.message)
    return screen(message=f"Reference groove {k} saved")

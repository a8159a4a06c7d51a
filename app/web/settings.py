"""Settings screen: the GUD measuring settings as a form generated from ``app.gud.GudSettings``."""

from __future__ import annotations

import typing

from fastapi import APIRouter, Request
from pydantic.fields import FieldInfo

from app import checks
from app.access.deps import needs, require
from app.deps import SettingsDep
from app.errors import InvalidInput
from app.gud import GudSettings, field_groups
from app.i18n import N_, _
from app.web import units
from app.web.texts import translate_message

from .templating import render_screen

router = APIRouter()


def choices(annotation) -> list | None:
    if typing.get_origin(annotation) is typing.Literal:
        return list(typing.get_args(annotation))
    return None


# the texts of the choices an operator reads (the value stays the stored one)
CHOICE_TEXTS = {"auto": N_("automatic (the browser's language)"), "en": "English", "de": "Deutsch", "zh": "中文",
                "mm": "mm", "inch": "inch", "standard": N_("standard"), "extended": N_("extended"),
                "warn": N_("warn"), "refuse": N_("refuse"), "probe": N_("probe"), "machine": N_("machine"),
                "wear": N_("wear"), "geometry": N_("geometry")}
HIDDEN = {"inch_display"}           # the wave-1 name of ``units`` (app/gud.py): one field on the screen


def _length_unit(info) -> str:
    unit = (info.json_schema_extra or {}).get("unit", "")
    return unit if units.is_length_unit(unit) else ""


def form_fields(values: dict, errors: dict[str, str], gud=None,
                texts: dict | None = None) -> list[tuple[str, list[dict]]]:
    """The form's fields; lengths and feeds in the screen's unit (``gud``), ``texts`` the typed text."""
    groups = []
    texts = texts or {}
    for group, fields in field_groups():
        items = []
        for name, info in fields:
            if name in HIDDEN:
                continue
            assert isinstance(info, FieldInfo)          # field_groups() pairs a name with its FieldInfo
            extra = info.json_schema_extra if isinstance(info.json_schema_extra, dict) else {}   # ours: dicts
            options = choices(info.annotation)
            value = values.get(name)
            unit = str(extra.get("unit", ""))                 # a str where given (app/gud.py _f)
            if gud is not None and _length_unit(info) and isinstance(value, int | float) and not isinstance(value, bool):
                value = texts.get(name, units.field_text(float(value), gud))
                unit = units.unit(gud, unit)
            items.append({
                "name": name, "label": _(info.description or name), "gud": extra.get("gud", ""),
                "unit": unit, "choices": options,
                "choice_texts": {str(c): _(CHOICE_TEXTS[c]) for c in options or () if c in CHOICE_TEXTS},
                "is_bool": info.annotation is bool, "value": value,
                "error": translate_message(errors.get(name)) if errors.get(name) else None,
            })
        groups.append((group, items))
    return groups


def _typed_number(raw: str, name: str, real: bool):
    """Typed text -> the number (an int for whole-number fields); text that is none stays text and
    the model names the field."""
    try:
        number = checks.parse_number(raw, name)
    except InvalidInput:
        return raw
    return number if real or not number.is_integer() else int(number)


def parse_form(form, gud=None) -> dict:
    """Form strings -> typed values (checkbox present = True; Literal ints as int; lengths and feeds
    typed in the unit the form was shown in, ``gud``, stored as mm)."""
    values: dict = {}
    for name, info in GudSettings.model_fields.items():
        if info.annotation is bool:
            values[name] = form.get(name) in ("on", "true", "1")
            continue
        if name not in form:
            continue
        raw = str(form.get(name)).strip()
        if gud is not None and _length_unit(info) and raw != "":
            try:
                values[name] = units.parse_length(raw, gud, getattr(gud, name, None))
            except units.NumberError:
                values[name] = raw                  # the model names the field
            continue
        options = choices(info.annotation)
        if options and all(isinstance(o, int) for o in options) or info.annotation in (int, float):
            values[name] = _typed_number(raw, name, info.annotation is float)
        else:
            values[name] = raw
    return values


@router.get("/settings", name="settings_screen")
def settings_screen(request: Request, settings: SettingsDep):
    current = settings.get()
    return render_screen(request, "settings.html", {"screen": "settings",
                                                    "groups": form_fields(current.model_dump(), {}, current)})


@router.post("/settings", name="settings_save", dependencies=[needs("settings")])
async def save_settings(request: Request, settings: SettingsDep):
    form = await request.form()
    shown_in = settings.get()               # the unit the form was shown in
    values = parse_form(form, shown_in)
    if settings.changes_levels(values):
        require(request, "users")           # the access-level table
    checked, errors = settings.check(values)
    if checked is None:
        return render_screen(request, "settings.html", {
            "screen": "settings", "groups": form_fields({**shown_in.model_dump(), **values}, errors, shown_in,
                                                        {k: str(v) for k, v in form.items()}),
            "form_message": _("Not saved: %(n)s field(s) need correction", n=len(errors)), "level": "error"})
    saved = settings.put(checked.model_dump(), source="screen")
    return render_screen(request, "settings.html", {
        "screen": "settings", "groups": form_fields(saved.model_dump(), {}, saved), "form_message": _("Settings saved"),
        "level": "info"})

"""Settings screen: the GUD measuring settings as a form generated from ``app.gud.GudSettings``."""

from __future__ import annotations

import typing

from fastapi import APIRouter, Request

from app.deps import SettingsDep
from app.gud import GudSettings, field_groups

from .templating import render_screen

router = APIRouter()


def choices(annotation) -> list | None:
    if typing.get_origin(annotation) is typing.Literal:
        return list(typing.get_args(annotation))
    return None


def form_fields(values: dict, errors: dict[str, str]) -> list[tuple[str, list[dict]]]:
    groups = []
    for group, fields in field_groups():
        items = []
        for name, info in fields:
            extra = info.json_schema_extra or {}
            items.append({
                "name": name, "label": info.description, "gud": extra.get("gud", ""),
                "unit": extra.get("unit", ""), "choices": choices(info.annotation),
                "is_bool": info.annotation is bool, "value": values.get(name), "error": errors.get(name),
            })
        groups.append((group, items))
    return groups


def parse_form(form) -> dict:
    """Form strings -> typed values (checkbox present = True; Literal ints as int)."""
    values: dict = {}
    for name, info in GudSettings.model_fields.items():
        if info.annotation is bool:
            values[name] = form.get(name) in ("on", "true", "1")
            continue
        if name not in form:
            continue
        raw = str(form.get(name)).strip()
        options = choices(info.annotation)
        if options and all(isinstance(o, int) for o in options):
            try:
                values[name] = int(raw)
            except ValueError:
                values[name] = raw
        else:
            values[name] = raw
    return values


@router.get("/settings")
def settings_screen(request: Request, settings: SettingsDep):
    values = settings.get().model_dump()
    return render_screen(request, "settings.html", {"screen": "settings", "groups": form_fields(values, {})})


@router.post("/settings")
async def save_settings(request: Request, settings: SettingsDep):
    form = await request.form()
    values = parse_form(form)
    checked, errors = settings.check(values)
    if checked is None:
        return render_screen(request, "settings.html", {
            "screen": "settings", "groups": form_fields({**settings.get().model_dump(), **values}, errors),
            "form_message": f"Not saved: {len(errors)} field(s) need correction", "level": "error"})
    saved = settings.put(checked.model_dump())
    return render_screen(request, "settings.html", {
        "screen": "settings", "groups": form_fields(saved.model_dump(), {}), "form_message": "Settings saved",
        "level": "info"})

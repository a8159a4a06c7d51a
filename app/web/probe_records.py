"""What the two probe-record screens share (workpiece probes ``/probes``, tool probes
``/tool-probes``): the record number of the URL, typed text -> mm, and the save flow that marks
every bad field. The services (``app.services.probes``) give the model, the name and the checks.

``screen`` is the module's render function with the request and services bound:
``screen(n=None, *, record=None, errors=None, message=None, level="info", texts=None)``.
"""

from __future__ import annotations

from collections.abc import Callable

from fastapi import Request
from pydantic import ValidationError

from app.errors import HmiError
from app.i18n import _
from app.services.settings import validation_errors

from . import units
from .templating import fixed

DECIMALS = 4          # mm values of a record on the screen (the ``ui.record_field`` default)


def shown(value) -> str:
    """How the screen shows a stored mm value."""
    return "" if value is None else fixed(value, DECIMALS)


def number(text, name: str, errors: dict, stored=None) -> float | None:
    """Typed text -> mm (None when empty); the untouched display text of ``stored`` keeps its
    full precision, so saving without editing changes nothing."""
    gud = units.current()
    if gud is not None:                 # a screen form: typed in the screen's unit (app/web/units.py)
        if str(text or "").strip() == "":
            return None
        try:
            return units.parse_length(text, gud, stored)
        except units.NumberError:
            errors[name] = _("Enter a number")
            return None
    text = str(text or "").strip().replace(",", ".")
    if text == "":
        return None
    if stored is not None and text == shown(stored):
        return float(stored)
    try:
        return float(text)
    except ValueError:
        errors[name] = f"{text!r} is not a number"
        return None


def record_number(service, text) -> int:
    """The record number of a URL; the service's ``InvalidInput`` unless it is 1..MAX_PROBE."""
    try:
        n = int(text)
    except (TypeError, ValueError):
        n = None
    return service.check_number(n)


def stored_or_new(service, n: int) -> dict:
    """Record ``n`` as stored, else the model's defaults."""
    try:
        return service.get(n)
    except HmiError:
        return service.model(number=n).model_dump(mode="json")


def show(request: Request, service, screen: Callable):
    """GET: the record ``?n=`` (default: the active one); a bad number is the message line."""
    if "n" not in request.query_params:
        return screen()
    try:
        n = record_number(service, request.query_params["n"])
    except HmiError as exc:
        return screen(level="error", message=exc.message)
    return screen(n)


async def save(request: Request, service, n: int, parse_form: Callable, screen: Callable):
    """POST: form -> record; every bad field marked with the typed text kept, else stored."""
    try:
        service.check_number(n)
    except HmiError as exc:
        return screen(level="error", message=exc.message)
    form = await request.form()
    with units.typed_in(request.app.state.services.settings.get()):
        record, errors = parse_form(form, stored_or_new(service, n))
    if not errors:
        try:
            service.model.model_validate(record)
        except ValidationError as exc:
            errors = validation_errors(exc)
    texts = {k: str(v) for k, v in form.items()}
    if errors:
        return screen(n, record=record, errors=errors, texts=texts, level="error",
                      message=_("Not saved: %(n)s field(s) need correction", n=len(errors)))
    try:
        saved = service.put(n, record, source="screen")
    except HmiError as exc:
        return screen(n, record=record, errors={exc.field or "form": exc.message}, texts=texts,
                      level="error", message=exc.message)
    return screen(n, record=saved, message=_("%(what)s %(n)s saved", what=_(service.what).capitalize(), n=n))

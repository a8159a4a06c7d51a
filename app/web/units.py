"""Display units of the screens (design.md §3, §9.9): storage, engine and JSON API are mm; with the
setting ``units = "inch"`` every screen shows and reads inch (feeds inch/min). Angles stay degrees.

The one place of the conversion: the templates' filters (``length``, ``feed``, ``unit``) and every
form parser of the screens use it. Operate's convention: 3 decimals in mm, 4 in inch. Typed text
is converted in decimal arithmetic, so 1.0000 inch stores 25.4 mm exactly (and 0.1 inch 2.54 mm).
Input accepts the point and the language's decimal sign (a comma in German) alike.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from decimal import Decimal, InvalidOperation

from app.i18n import decimal_symbol, format_fixed, format_number, language

MM_PER_INCH = 25.4
_MM_PER_INCH = Decimal("25.4")
MAX_DECIMALS_IN_FIELD = 6          # an input field shows a stored value this precisely (trailing 0 cut)


def is_inch(gud) -> bool:
    return getattr(gud, "units", "mm") == "inch" or bool(getattr(gud, "inch_display", False))


def decimals(gud) -> int:
    """Display decimals of a length: 4 in inch, 3 in mm."""
    return 4 if is_inch(gud) else 3


def unit(gud, unit_mm: str = "mm") -> str:
    """The unit shown for a stored unit: mm -> inch, mm/min -> inch/min; others unchanged."""
    if not is_inch(gud):
        return unit_mm
    return {"mm": "inch", "mm/min": "inch/min"}.get(unit_mm, unit_mm)


def is_length_unit(unit_mm: str) -> bool:
    return unit_mm in ("mm", "mm/min")


def to_display(mm: float, gud) -> float:
    """A stored mm (or mm/min) value in the screen's unit."""
    return float(mm) / MM_PER_INCH if is_inch(gud) else float(mm)


def format_length(mm: float | None, gud, places: int | None = None) -> str:
    """A stored mm value as the screen shows it (unit of the setting, the language's decimal sign)."""
    if mm is None or (isinstance(mm, str) and mm == ""):
        return ""
    return format_fixed(to_display(mm, gud), decimals(gud) if places is None else places)


def format_feed(mm_per_min: float | None, gud) -> str:
    """A feed: mm/min as short as it is exact, inch/min with 2 decimals."""
    if mm_per_min is None:
        return ""
    if is_inch(gud):
        return format_fixed(to_display(mm_per_min, gud), 2)
    return format_number(float(mm_per_min))


def field_text(mm: float | None, gud) -> str:
    """A stored mm value as the text of an input field: exact enough to type back unchanged
    (``parse_length`` of it gives the stored value again when nothing was edited)."""
    if mm is None:
        return ""
    value = to_display(mm, gud)
    text = f"{value:.{MAX_DECIMALS_IN_FIELD}f}".rstrip("0").rstrip(".") if is_inch(gud) else f"{value:g}"
    if text in ("-0", ""):
        text = "0"
    sign = decimal_symbol(language())
    return text if sign == "." else text.replace(".", sign)


class NumberError(ValueError):
    """Typed text that is no number (the caller names the field)."""


def parse_decimal(text) -> Decimal:
    """Typed text -> Decimal; a point or the language's decimal sign (or a comma) as the decimal sign."""
    raw = str(text if text is not None else "").strip().replace(" ", "").replace("\u00a0", "")
    sign = decimal_symbol(language())
    if sign not in (".", ","):
        raw = raw.replace(sign, ".")
    raw = raw.replace(",", ".").replace("−", "-")
    if not raw.isascii():           # Decimal("１２") reads fullwidth digits; the NC does not (issue 25)
        raise NumberError(raw)
    try:
        value = Decimal(raw)
    except InvalidOperation:
        raise NumberError(raw) from None
    if not value.is_finite():
        raise NumberError(raw)
    return value


def parse_number(text) -> float:
    """Typed text of a plain number (degrees, factors) -> float."""
    value = float(parse_decimal(text))
    if not math.isfinite(value):
        raise NumberError(str(text))
    return value


def record_places(gud) -> int:
    """Decimals of a probe-data length (trigger values, ball): one more than a position."""
    return decimals(gud) + 1


def shown_texts(mm: float, gud) -> tuple[str, ...]:
    """Every text a screen shows a stored value as (field, display, probe data)."""
    return (field_text(mm, gud), format_length(mm, gud), format_length(mm, gud, record_places(gud)))


def parse_length(text, gud, stored_mm: float | None = None) -> float:
    """Typed text in the screen's unit -> mm. ``stored_mm``: the value the field showed; its
    unchanged text gives it back exactly (an untouched field changes nothing)."""
    if stored_mm is not None and str(text).strip() in shown_texts(stored_mm, gud):
        return float(stored_mm)
    value = parse_decimal(text)
    mm = value * _MM_PER_INCH if is_inch(gud) else value
    result = float(mm)
    if not math.isfinite(result):
        raise NumberError(str(text))
    return result


def mm_text_of(text, gud, stored_mm: float | None = None) -> str:
    """Typed text in the screen's unit -> the same value as mm text (for services that take text);
    text that is no number is passed on as it is (the service names the field)."""
    if str(text or "").strip() == "":
        return ""
    try:
        return repr(parse_length(text, gud, stored_mm))
    except NumberError:
        return str(text)


# --- the unit of the form being saved (the record screens parse deep inside their helpers) ---------

_screen_gud: ContextVar = ContextVar("screen_gud", default=None)


@contextmanager
def typed_in(gud) -> Iterator[None]:
    """``with typed_in(gud): ...``: the lengths a form helper parses are in ``gud``'s unit."""
    token = _screen_gud.set(gud)
    try:
        yield
    finally:
        _screen_gud.reset(token)


def current():
    """The settings of the form being saved (``typed_in``), or None (mm)."""
    return _screen_gud.get()

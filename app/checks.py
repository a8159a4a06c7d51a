"""The one place the app checks the numbers clients send (issue 25 item 3, issue 27 item 7).

A JSON number is a number: ``true`` is no 1, the text ``"12"`` or ``"1e3"`` is no number, NaN and
infinity are refused, and an integer too large for a float (a 400-digit ``1000…0``) is a 422 that
names the field, never a server error (``float(10**400)`` raises ``OverflowError``). Every refusal
is :class:`app.errors.InvalidInput` (422 ``validation``, ``field`` set), raised before anything is
stored, so a refused write leaves the stored data as it was.

Typed text from the screens goes through :func:`parse_number`: ASCII digits only (a fullwidth
``１２`` is refused as it is on the NC), a point or a comma as the decimal sign.

Pydantic models use the annotated types at the end (:data:`Number`, :data:`Integer`), which are
strict in the same way.
"""

from __future__ import annotations

import math
import re
from typing import Annotated, Any

from pydantic import AllowInfNan, Strict

from app.errors import InvalidInput

INT_LIMIT = 2**63 - 1                   # a database id or a 64-bit counter

# a number as typed: optional sign, ASCII digits with one decimal point, optional exponent
_NUMBER_TEXT = re.compile(r"[+-]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]{1,3})?")


def _range_text(lo: float | None, hi: float | None, unit: str) -> str:
    suffix = f" {unit}" if unit else ""
    if lo is not None and hi is not None:
        if lo == -hi:
            return f"within ±{hi:g}{suffix}"
        return f"within {lo:g}..{hi:g}{suffix}"
    if lo is not None:
        return f"at least {lo:g}{suffix}"
    if hi is not None:
        return f"at most {hi:g}{suffix}"
    return ""


def is_json_number(value: Any) -> bool:
    """An int or a float as JSON gives them (a bool is no number)."""
    return isinstance(value, int | float) and not isinstance(value, bool)


def number(value: Any, field: str, *, lo: float | None = None, hi: float | None = None,
           unit: str = "", lo_open: bool = False, hi_open: bool = False) -> float:
    """``value`` as a finite float within [lo, hi] (``lo_open``/``hi_open``: the bound itself
    excluded); InvalidInput naming ``field`` otherwise."""
    wanted = _range_text(lo, hi, unit)
    what = f"a finite number {wanted}".rstrip()
    if not is_json_number(value):
        raise InvalidInput(f"{field}: must be {what}, not {_kind(value)}", field=field)
    try:
        result = float(value)
    except OverflowError:           # an int beyond the float range
        raise InvalidInput(f"{field}: must be {what} (the number is too large)", field=field) from None
    if not math.isfinite(result):
        raise InvalidInput(f"{field}: must be {what}", field=field)
    if lo is not None and (result < lo or lo_open and result == lo) \
            or hi is not None and (result > hi or hi_open and result == hi):
        raise InvalidInput(f"{field}: must be {what}", field=field)
    return result


def optional_number(value: Any, field: str, **limits: Any) -> float | None:
    """None stays None; anything else as :func:`number`."""
    return None if value is None else number(value, field, **limits)


def integer(value: Any, field: str, *, lo: int | None = None, hi: int | None = None) -> int:
    """``value`` as an int within [lo, hi]; a float (even 3.0), a bool or a text is refused."""
    wanted = _range_text(lo, hi, "")
    what = f"a whole number {wanted}".rstrip()
    if isinstance(value, bool) or not isinstance(value, int):
        raise InvalidInput(f"{field}: must be {what}, not {_kind(value)}", field=field)
    if abs(value) > INT_LIMIT or lo is not None and value < lo or hi is not None and value > hi:
        raise InvalidInput(f"{field}: must be {what}", field=field)
    return value


def normalise_number_text(text: Any) -> str:
    """Typed text with blanks removed, a comma or a typographic minus as the point and the sign."""
    raw = str(text if text is not None else "").strip()
    return raw.replace(" ", "").replace("\u00a0", "").replace(",", ".").replace("\u2212", "-")


def parse_number(text: Any, field: str, **limits: Any) -> float:
    """Typed text (a screen field) -> a float within the limits of :func:`number`. Digits must be
    ASCII: Python's ``float("１２")`` would read a fullwidth 12, the NC does not."""
    raw = normalise_number_text(text)
    if not _NUMBER_TEXT.fullmatch(raw):
        raise InvalidInput(f"{field}: {str(text)[:40]!r} is not a number", field=field)
    return number(float(raw), field, **limits)


def json_numbers(document: Any, field: str = "") -> None:
    """Every number inside a JSON document (objects, lists) finite; for free-form documents stored
    as they come. InvalidInput names the first bad one's path."""
    if isinstance(document, dict):
        for key, item in document.items():
            json_numbers(item, f"{field}.{key}" if field else str(key))
    elif isinstance(document, list):
        for i, item in enumerate(document):
            json_numbers(item, f"{field}[{i}]")
    elif is_json_number(document):
        number(document, field or "value")


def _kind(value: Any) -> str:
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true/false"
    if isinstance(value, str):
        return "a text"
    if isinstance(value, dict):
        return "an object"
    if isinstance(value, list):
        return "a list"
    return type(value).__name__


# --- pydantic: the same rules in a model --------------------------------------------------------------
# strict: no bool, no text; a finite float (an int is taken as a float); pydantic refuses an int
# beyond the float range as "a valid number" (tests/hardening)
Number = Annotated[float, Strict(), AllowInfNan(False)]
Integer = Annotated[int, Strict()]

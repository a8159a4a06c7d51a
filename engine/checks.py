"""The engine's one module of scalar and vector checks (issue 27 item 7); pure, imports no engine module.

Two kinds of refusal:

* :class:`ValueError` for a value a caller passes in (a cycle parameter, a direction, sigma):
  ``real``, ``integer``, ``unit_sign``, ``choice``, ``vector``, ``unit_vector``;
* :class:`ParamError` (a ValueError naming the ``field``) for a task parameter a client sent
  (design.md §4): ``param_number``, ``param_positive``, ``param_int``, ``param_bool``,
  ``param_choice``. The app answers it with a 422 naming the field.

A JSON boolean is no number anywhere here (``True`` is not 1).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, Literal, TypeGuard, overload

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]


class ParamError(ValueError):
    """An invalid task parameter; ``field`` names it, the message names the problem."""

    def __init__(self, field: str, message: str):
        super().__init__(message)
        self.field = field
        self.message = message


# --- values passed in (ValueError) --------------------------------------------------------------

def is_number(value: object) -> TypeGuard[int | float | np.integer[Any] | np.floating[Any]]:
    """An int or a float (numpy's included); a bool is no number."""
    return isinstance(value, int | float | np.integer | np.floating) and not isinstance(value, bool)


def is_finite(value: float | None) -> bool:
    """``value`` is given and finite (None, NaN and ±inf are not)."""
    return value is not None and math.isfinite(value)


def real(name: str, value: object, *, minimum: float | None = None) -> float:
    """``value`` as a finite float (at least ``minimum`` when given); ValueError naming ``name``."""
    if not is_number(value):
        raise ValueError(f"{name} must be a number, got {value!r}")
    out = float(value)
    if not math.isfinite(out):
        raise ValueError(f"{name} must be finite, got {value!r}")
    if minimum is not None and out < minimum:
        raise ValueError(f"{name} must be a finite value >= {minimum:g}, got {value!r}")
    return out


def integer(name: str, value: object) -> int:
    """An integer (an integral float such as 3.0 is accepted, 2.5 and booleans are not)."""
    out = real(name, value)
    if out != int(out):
        raise ValueError(f"{name} must be an integer, got {value!r}")
    return int(out)


def unit_sign(name: str, value: object) -> int:
    """+1 or −1 (a bool is neither)."""
    if isinstance(value, bool) or value not in (1, -1):
        raise ValueError(f"{name} must be +1 or −1, got {value!r}")
    return 1 if value == 1 else -1


def choice(name: str, value: object, choices: tuple[str, ...]) -> str:
    """One of ``choices``; ValueError listing them otherwise."""
    if value not in choices:
        raise ValueError(f"{name} must be one of {', '.join(choices)}, got {value!r}")
    return str(value)


def vector(value: npt.ArrayLike, name: str, dim: int = 3) -> FloatArray:
    """A finite vector of ``dim`` components, as a new array (the caller may keep it)."""
    arr = np.array(value, dtype=float)
    if arr.shape != (dim,):
        raise ValueError(f"{name} must have shape ({dim},), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite, got {arr}")
    return arr


def unit_vector(value: npt.ArrayLike, name: str = "direction", dim: int | None = None) -> FloatArray:
    """``value`` scaled to length 1 (of ``dim`` components when given); a zero or non-finite
    vector is a ValueError."""
    u = np.asarray(value, dtype=float)
    if dim is not None and u.shape != (dim,):
        raise ValueError(f"{name} must have shape ({dim},), got {u.shape}")
    flat = u.ravel(order="K")
    norm = math.sqrt(flat.dot(flat))      # np.linalg.norm's own sum for real vectors, without its checks
    if not math.isfinite(norm) or norm == 0.0:
        raise ValueError(f"{name} must be a finite non-zero vector, got {u}")
    return u / norm


# --- task parameters a client sent (ParamError naming the field) ---------------------------------

@overload
def param_number(params: Mapping[str, Any], name: str, default: object = None, *, required: Literal[True],
                 field_name: str | None = None, bound: float | None = None) -> float: ...
@overload
def param_number(params: Mapping[str, Any], name: str, default: object = None, *, required: bool = False,
                 field_name: str | None = None, bound: float | None = None) -> float | None: ...
def param_number(params: Mapping[str, Any], name: str, default: object = None, *, required: bool = False,
                 field_name: str | None = None, bound: float | None = None) -> float | None:
    """``params[name]`` (else ``default``) as a finite float, within ±``bound`` when given; None
    (or "") when absent and not ``required``. ``field_name``: the field the error names."""
    f = field_name or name
    value = params.get(name, default)
    if value is None or value == "":
        if required:
            raise ParamError(f, f"{f} is required")
        return None
    if isinstance(value, bool):
        raise ParamError(f, f"{f} must be a number, got {value!r}")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ParamError(f, f"{f} must be a number, got {value!r}") from None
    if not math.isfinite(number):
        raise ParamError(f, f"{f} must be a finite number, got {value!r}")
    if bound is not None and abs(number) > bound:
        raise ParamError(f, f"{f} must lie within ±{bound:g}, got {value!r}")
    return number


def param_positive(params: Mapping[str, Any], name: str, *, required: bool,
                   bound: float | None = None) -> float | None:
    """:func:`param_number` above zero."""
    value = param_number(params, name, required=required, bound=bound)
    if value is not None and value <= 0.0:
        raise ParamError(name, f"{name} must be > 0, got {value:g}")
    return value


def param_int(params: Mapping[str, Any], name: str, default: int, minimum: int, field_name: str | None = None) -> int:
    """:func:`param_number` that is a whole number of at least ``minimum``."""
    f = field_name or name
    value = param_number(params, name, default, field_name=f)
    if value is None or value != int(value) or value < minimum:
        raise ParamError(f, f"{f} must be an integer >= {minimum}, got {params.get(name)!r}")
    return int(value)


def param_bool(params: Mapping[str, Any], name: str, default: bool) -> bool:
    """true or false (no 0/1, no text)."""
    value = params.get(name, default)
    if not isinstance(value, bool):
        raise ParamError(name, f"{name} must be true or false, got {value!r}")
    return value


def param_choice(params: Mapping[str, Any], name: str, choices: tuple[str, ...], default: str | None, *,
                 required: bool = False) -> str:
    """One of ``choices`` (a text matching an upper-case choice in lower case is taken as it)."""
    value = params.get(name, default)
    if value is None and required:
        raise ParamError(name, f"{name} is required ({', '.join(map(str, choices))})")
    if isinstance(value, str) and value.upper() in choices:
        value = value.upper()
    if value not in choices:
        raise ParamError(name, f"{name} must be one of {', '.join(map(str, choices))}, got {params.get(name)!r}")
    return str(value)


def param_real(field: str, value: object) -> float:
    """A value the client gave as a JSON number: finite, no text, no bool; ParamError naming ``field``."""
    if not is_number(value) or not math.isfinite(float(value)):
        raise ParamError(field, f"{field}: a finite number is needed, got {value!r}")
    return float(value)

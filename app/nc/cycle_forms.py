"""Cycle support of the program editor (design.md §10.2, manual §7.2–7.3): the measuring cycles
as input screens whose fields are the manual's parameters, the text the editor inserts (the
parameter assignments and the call, SW 6.3 style: parameters set before the call, manual §2.2),
and the way back from such a text to the form. ``read(render(c, p)) == (c, p)`` exactly:
integers stay integers, reals are written with Python's shortest round-trip representation.
The milling machine offers ``CYCLES``; a lathe offers ``LATHE_CYCLES`` (CYCLE982/973/974/994 with
the parameters app.nc.cycles.lathe reads), and neither offers the other's. The lathe forms check
``_MVAR`` digit by digit with the decoders the NC's cycles use (engine.turning_tools.decode_982,
engine.turning_probe.decode_973; CYCLE974 0/100/1000, CYCLE994 1/2 by its range): a variant the
cycle does not have is refused naming ``params._MVAR`` and the digits it may have.

    fields = CYCLES["CYCLE977"]                 # the form: parameter name, operator text, kind
    text = render("CYCLE977", {"_MVAR": 101, "_SETVAL": 20.0, "_KNUM": 1})
    read(text) == ("CYCLE977", {"_MVAR": 101, "_SETVAL": 20.0, "_KNUM": 1})
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from app.i18n import N_
from app.nc import nodes as n
from app.nc.errors import NcSyntaxError
from app.nc.parser import parse_program
from engine.turning_probe import decode_973
from engine.turning_tools import decode_982
from engine.types import MeasuringError


@dataclass(frozen=True)
class CycleField:
    name: str            # the manual's parameter name: _MVAR, _SETV[0], _CHBIT[4]
    text: str            # the operator text (catalogue msgid)
    kind: str            # "int" or "real"
    default: int | float = 0
    low: float = -1e9
    high: float = 1e9

    def to_api(self, translate) -> dict:
        return {"name": self.name, "text": translate(self.text), "kind": self.kind, "default": self.default,
                "min": self.low, "max": self.high}


def _int(name: str, text: str, default: int = 0, low: float = 0, high: float = 1e9) -> CycleField:
    return CycleField(name, text, "int", default, low, high)


def _real(name: str, text: str, default: float = 0.0, low: float = -1e5, high: float = 1e5) -> CycleField:
    return CycleField(name, text, "real", default, low, high)


# the auxiliary parameters every cycle reads (manual §2.3)
_COMMON = (
    _int("_PRNUM", N_("Probe number"), 1, 1, 3),
    _real("_VMS", N_("Measuring feed (0: default)"), 0.0, 0.0, 10000.0),
    _int("_NMSP", N_("Measurements at one place"), 1, 1, 99),
    _real("_FA", N_("Measuring path"), 2.0, 0.001, 1000.0),
    _real("_TSA", N_("Safe area"), 1.0, 0.0, 1e5),
)
_TOOL_OFFSET = (
    _int("_TNUM", N_("Tool number for the offset"), 0, 0, 32000),
    _real("_TUL", N_("Upper tolerance")), _real("_TLL", N_("Lower tolerance")),
    _real("_TZL", N_("Zero offset range"), 0.0, 0.0, 1e5), _real("_TMV", N_("Mean value range"), 0.0, 0.0, 1e5),
    _real("_TDIF", N_("Dimension difference"), 0.0, 0.0, 1e5),
    _int("_K", N_("Weighting factor for averaging"), 1, 1, 1000), _int("_EVNUM", N_("Empirical value memory"), 0),
)
_VARIANT = _int("_MVAR", N_("Measuring variant"), 0, 0, 999999)
_SETVAL = _real("_SETVAL", N_("Setpoint"))
_AXIS = _int("_MA", N_("Measuring axis"), 1, 1, 3)
_KNUM = _int("_KNUM", N_("Correction target (zero offset or tool offset)"), 0, 0, 9999999)
_INFEED = _real("_ID", N_("Infeed / offset"))
# touches on the circle (this HMI's extension, app.nc.cycles.workpiece.circle_points; 0: the manual's)
_NPTS = _int("_NPTS", N_("Number of points"), 0, 0, 36)

CYCLES: dict[str, tuple[CycleField, ...]] = {
    "CYCLE976": (_VARIANT, _SETVAL, _AXIS, _int("_MD", N_("Measuring direction (0 +, 1 −)"), 1, 0, 1),
                 _real("_STA1", N_("Starting angle")), *_COMMON, _real("_TZL", N_("Zero offset range"), 0.0, 0.0, 1e5)),
    "CYCLE977": (_VARIANT, _SETVAL, _real("_SETV[0]", N_("Setpoint length")), _real("_SETV[1]", N_("Setpoint width")),
                 _AXIS, _INFEED, _KNUM, _NPTS, *_COMMON, *_TOOL_OFFSET),
    "CYCLE978": (_VARIANT, _SETVAL, _AXIS, _KNUM, *_COMMON, *_TOOL_OFFSET),
    "CYCLE979": (_VARIANT, _SETVAL, _real("_CPA", N_("Centre point, abscissa")),
                 _real("_CPO", N_("Centre point, ordinate")), _real("_STA1", N_("Starting angle")),
                 _real("_INCA", N_("Indexing angle")), _INFEED, _KNUM, _NPTS, *_COMMON, *_TOOL_OFFSET),
    "CYCLE998": (_VARIANT, _SETVAL, _real("_SETV[0]", N_("Setpoint of the second angle")), _AXIS, _INFEED,
                 _real("_STA1", N_("Starting angle")), _real("_RA", N_("Rotary axis correction")), _KNUM, *_COMMON),
    "CYCLE961": (_VARIANT, _real("_SETV[0]", N_("Setpoint length")), _real("_SETV[1]", N_("Setpoint width")),
                 _real("_STA1", N_("Starting angle")), _real("_INCA", N_("Indexing angle")), _INFEED, _KNUM,
                 *_COMMON),
    "CYCLE997": (_VARIANT, _SETVAL, _KNUM, _real("_TNVL", N_("Limit of the distortion"), 0.0, 0.0, 1e5), *_COMMON),
    "CYCLE971": (_VARIANT, _AXIS, _INFEED, _int("_CHBIT[3]", N_("Correct the wear (1) or the geometry (0)"), 0, 0, 1),
                 *_COMMON, _real("_TZL", N_("Zero offset range"), 0.0, 0.0, 1e5),
                 _real("_TDIF", N_("Dimension difference"), 0.0, 0.0, 1e5)),
}


# --- the lathe's cycles (manual ch. 6): the parameters app.nc.cycles.lathe reads -------------------
_MD = _int("_MD", N_("Measuring direction (0 +, 1 −)"), 1, 0, 1)
_AXIS_ZX = _int("_MA", N_("Measuring axis (1 Z, 2 X)"), 1, 1, 2)
_AXIS_ZXY = _int("_MA", N_("Measuring axis (1 Z, 2 X, 3 Y)"), 2, 1, 3)
_GEOMETRY = _int("_CHBIT[6]", N_("Correct the geometry (1) or the wear (0)"), 0, 0, 1)
_KEEP_MEAN = _int("_CHBIT[4]", N_("Keep the mean value over the parts"), 0, 0, 1)

LATHE_CYCLES: dict[str, tuple[CycleField, ...]] = {
    "CYCLE982": (_VARIANT, _AXIS_ZX, _MD, _real("_STA1", N_("Starting angle")),
                 _real("_CORA", N_("Correction angle position (second edge, reversal)")),
                 _int("_CHBIT[3]", N_("Correct the wear (1) or the geometry (0)"), 0, 0, 1),
                 _int("_PRNUM", N_("Tool probe number"), 1, 1, 3), *_COMMON[1:],
                 _real("_TZL", N_("Zero offset range"), 0.0, 0.0, 1e5),
                 _real("_TDIF", N_("Dimension difference"), 0.0, 0.0, 1e5),
                 _int("_EVNUM", N_("Empirical value memory"), 0)),
    "CYCLE973": (_int("_MVAR", N_("Measuring variant"), 0, 0, 99999), _AXIS_ZXY, _MD, _SETVAL,
                 _int("_CALNUM", N_("Reference groove"), 1, 1, 3), *_COMMON,
                 _real("_TZL", N_("Zero offset range"), 0.0, 0.0, 1e5)),
    "CYCLE974": (_int("_MVAR", N_("Measuring variant"), 0, 0, 1000), _SETVAL, _AXIS_ZXY,
                 _real("_STA1", N_("Start angle of the reversal")), _KNUM, _GEOMETRY, _KEEP_MEAN,
                 *_COMMON, *_TOOL_OFFSET),
    "CYCLE994": (_int("_MVAR", N_("Measuring variant"), 2, 1, 2), _SETVAL, _AXIS_ZXY,
                 _real("_SZA", N_("Protection zone in Z (detour)")), _real("_SZO", N_("Protection zone in X")),
                 _KNUM, _GEOMETRY, _KEEP_MEAN,
                 _int("_CHBIT[7]", N_("Use the ball diameter (probe not calibrated)"), 0, 0, 1),
                 *_COMMON, *_TOOL_OFFSET),
}


def cycles_for(lathe: bool) -> dict[str, tuple[CycleField, ...]]:
    """The cycles the editor offers on this machine: the lathe's on a lathe, else the milling ones."""
    return LATHE_CYCLES if lathe else CYCLES


class CycleFormError(ValueError):
    """Bad input to the cycle support, naming the field (``cycle``, ``params.<name>``, ``text``).
    ``text``/``values``: the message as a catalogue msgid with its %-values, for the screen to
    translate (the API answers ``message``, the English)."""

    def __init__(self, field: str, message: str, text: str | None = None, values: dict | None = None):
        super().__init__(message)
        self.field = field
        self.message = message
        self.text = text
        self.values = values or {}

    def translated(self, translate) -> str:
        if self.text is None:
            return self.message
        return translate(self.text) % {k: translate(v) if isinstance(v, Reason) else v for k, v in self.values.items()}


class Reason(str):
    """A catalogue msgid given as a value of a message (translated with it)."""


def fields_of(cycle: str, lathe: bool = False) -> dict[str, CycleField]:
    offered = cycles_for(lathe)
    if cycle not in offered:
        other = CYCLES if lathe else LATHE_CYCLES
        why = (f" ({cycle} is a {'milling' if lathe else 'lathe'} cycle: this machine is a "
               f"{'lathe' if lathe else 'milling machine'})" if cycle in other else "")
        raise CycleFormError("cycle", f"{cycle!r} is not a measuring cycle of the editor's cycle support "
                             f"({', '.join(offered)}){why}")
    return {f.name: f for f in offered[cycle]}


def _value(field: CycleField, value: object) -> int | float:
    where = f"params.{field.name}"
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise CycleFormError(where, f"{field.name} must be a number, got {value!r}")
    if field.kind == "int":
        if float(value) != int(value):
            raise CycleFormError(where, f"{field.name} must be a whole number, got {value!r}")
        value = int(value)
    else:
        value = float(value)
    if not field.low <= value <= field.high:
        raise CycleFormError(where, f"{field.name} must lie in {field.low:g}..{field.high:g}, got {value!r}")
    return value


# --- the _MVAR digits of the lathe's cycles (the same decoders the NC's cycles use) -------------------
_DIGITS_982 = Reason(N_(
    "units 0 calibrate, 1 measure on _MA, 2 measure automatically; tens 0 tool probe _TP, "
    "1 workpiece-related _TPW; mills only: hundreds 1 with reversal, thousands 0 length, 1 radius, "
    "2 length and radius (automatic: 0), ten-thousands 1 radial position; hundred-thousands 1 "
    "incremental (not automatic, not with length and radius); calibration has no mill digits"))
_DIGITS_973 = Reason(N_(
    "0 on a surface, or xxx13 in the reference groove: hundreds 1 with the effective ball diameter, "
    "thousands 0 or 1 one direction, 2 both directions of _MA, ten-thousands 1 with the position deviation"))
_ONE_DIRECTION_973 = Reason(N_(
    "in one direction neither the effective ball diameter (hundreds digit) nor the position deviation "
    "(ten-thousands digit) can be determined: set the thousands digit to 2 (both directions)"))
_VARIANTS_974 = Reason(N_("0 tool offset or measure only, 100 zero offset, 1000 with reversal"))
_NOT_A_VARIANT = N_("_MVAR=%(mvar)s is not a %(cycle)s variant: %(reason)s")


def _variant_982(mvar: int) -> str | None:
    try:
        decode_982(mvar)
    except MeasuringError:
        return _DIGITS_982
    return None


def _variant_973(mvar: int) -> str | None:
    try:
        decode_973(mvar)
    except MeasuringError:
        d3, d4, d5 = (mvar // 100) % 10, (mvar // 1000) % 10, mvar // 10_000
        if mvar % 100 == 13 and d3 in (0, 1) and d4 in (0, 1) and d5 in (0, 1) and (d3 or d5):
            return _ONE_DIRECTION_973
        return _DIGITS_973
    return None


def _variant_974(mvar: int) -> str | None:
    return None if mvar in (0, 100, 1000) else _VARIANTS_974


# cycle -> the reason its _MVAR is not one of its variants (None: it is)
_VARIANTS = {"CYCLE982": _variant_982, "CYCLE973": _variant_973, "CYCLE974": _variant_974}


def _check_variant(cycle: str, values: dict[str, int | float]) -> None:
    check = _VARIANTS.get(cycle)
    mvar = values.get("_MVAR")
    if check is None or mvar is None:
        return
    reason = check(int(mvar))
    if reason is not None:
        details: dict[str, object] = {"mvar": int(mvar), "cycle": cycle, "reason": reason}
        raise CycleFormError("params._MVAR", _NOT_A_VARIANT % details, _NOT_A_VARIANT, details)


def _text_of(value: int | float) -> str:
    return str(value) if isinstance(value, int) else repr(float(value))


def render(cycle: str, params: dict, lathe: bool = False) -> str:
    """The assignments in the form's order and the call: ``_MVAR=101 _SETVAL=20.0\\nCYCLE977``
    (``lathe``: the machine is a lathe, its cycles are the ones offered)."""
    fields = fields_of(cycle, lathe)
    if not isinstance(params, dict):
        raise CycleFormError("params", "params must be an object of the cycle's parameters")
    unknown = [k for k in params if k not in fields]
    if unknown:
        raise CycleFormError(f"params.{unknown[0]}", f"{unknown[0]} is not a parameter of {cycle} "
                             f"({', '.join(fields)})")
    values = {name: _value(field, params[name]) for name, field in fields.items() if name in params}
    _check_variant(cycle, values)
    words = [f"{name}={_text_of(value)}" for name, value in values.items()]
    lines, line = [], ""
    for word in words:                  # blocks well below the NC's 512 characters
        if line and len(line) + 1 + len(word) > 72:
            lines.append(line)
            line = ""
        line = f"{line} {word}" if line else word
    if line:
        lines.append(line)
    return "\n".join([*lines, cycle])


_INDEX = re.compile(r"^\d+$")


def _constant(expr) -> int | float | None:
    if isinstance(expr, n.Num):
        return expr.value
    if isinstance(expr, n.Unary) and expr.op in "+-" and isinstance(expr.operand, n.Num):
        return -expr.operand.value if expr.op == "-" else expr.operand.value
    return None


def read(text: str, lathe: bool = False) -> tuple[str, dict]:
    """The last measuring-cycle call of ``text`` and the constant values its parameters were given
    before it (what the editor's form shows when the operator opens the call); ``lathe``: the
    lathe's cycles are the ones read."""
    offered = cycles_for(lathe)
    if not isinstance(text, str):
        raise CycleFormError("text", "text must be the program text")
    try:
        program = parse_program(text, "EDITOR")
    except NcSyntaxError as exc:
        raise CycleFormError("text", f"line {exc.line}: {exc.message}") from None
    seen: dict[str, int | float] = {}
    found: tuple[str, dict] | None = None
    for block in program.blocks:
        for word in block.words:
            if isinstance(word, n.Assign) and len(word.values) == 1:
                indices = [_constant(i) for i in word.target.indices]
                if any(i is None for i in indices):
                    continue
                name = word.target.name.upper() + ("" if not indices else
                                                   "[" + ",".join(str(int(i)) for i in indices if i is not None) + "]")
                value = _constant(word.values[0])
                if value is not None:
                    seen[name] = value
            elif isinstance(word, n.CycleCall) and word.name.upper() in offered:
                fields = fields_of(word.name.upper(), lathe)
                found = (word.name.upper(), {k: _value(fields[k], v) for k, v in seen.items() if k in fields})
    if found is None:
        raise CycleFormError("text", f"the text calls no measuring cycle of the cycle support ({', '.join(offered)})")
    return found

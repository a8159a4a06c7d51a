"""The variable store: R parameters, GUD (the measuring-cycle data), system variables, LUD.

Every variable has a ``VarDef``: type (REAL, INT, BOOL, STRING), shape (``()`` scalar, ``(20,)``,
``(3, 11)``; or indexed by axis name like ``$AA_MM[X]``), default, and whether programs may write
it. ``Variables`` holds the values; elements never written read as their default.

Persistent data (``_EV``/``_MV`` empirical and mean values, probe records ``_WP``/``_TP``...) can
live outside: ``Variables(backings={"_EV": store})`` or ``variables.bind("_EV", store)`` with any
object that has ``__getitem__``/``__setitem__`` (a dict, or ``CallbackBacking(read, write)`` over a
database). Keys are ``int`` for one-dimensional arrays (``_EV[9]`` -> ``9``), tuples for more
dimensions (``_WP[0,1]`` -> ``(0, 1)``), the axis name for axis-indexed ones (``"X"``) and ``()``
for scalars. A missing key (``KeyError``/``IndexError``, or ``None`` from ``CallbackBacking``)
reads as the default. Values handed to a backing are already checked and converted to the
variable's type.

Units: the store keeps numbers as programmed; the measuring cycles interpret them (measuring-math
measuring-math §4: "unit: act." parameters in the active unit system, ``_FA`` always mm).
"""

from __future__ import annotations

import dataclasses
import math
import threading
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any, Protocol

from lark.exceptions import LarkError

from engine import alarms
from engine.alarms import AlarmDef

from .errors import NcError
from .modal import AXIS_LETTERS

Value = int | float | bool | str
Key = int | tuple | str

TYPES = ("REAL", "INT", "BOOL", "STRING")
INT_RANGE = (-(2**31), 2**31 - 1)


class VariableError(Exception):
    """A variable access that cannot be done; ``alarm`` is the catalogue entry."""

    alarm: AlarmDef = alarms.NC_NAME_UNKNOWN

    def __init__(self, message: str):
        super().__init__(message)
        self.message = message


class UnknownVariable(VariableError):
    alarm = alarms.NC_NAME_UNKNOWN


class IndexOutOfRange(VariableError):
    alarm = alarms.NC_ARRAY_INDEX


class WriteProtected(VariableError):
    alarm = alarms.NC_WRITE_PROTECTED


class InvalidValue(VariableError):
    alarm = alarms.NC_VALUE_RANGE


class Backing(Protocol):
    """Storage of one variable's elements outside the store (a mapping-like object)."""

    def __getitem__(self, key: Key) -> Value: ...

    def __setitem__(self, key: Key, value: Value) -> None: ...


class CallbackBacking:
    """A backing from two functions: ``read(key) -> value | None`` (None = default), ``write(key, value)``."""

    def __init__(self, read: Callable[[Key], Value | None], write: Callable[[Key, Value], None] | None = None):
        self._read = read
        self._write = write

    def __getitem__(self, key: Key) -> Value:
        value = self._read(key)
        if value is None:
            raise KeyError(key)
        return value

    def __setitem__(self, key: Key, value: Value) -> None:
        if self._write is None:
            raise WriteProtected("this variable is read-only")
        self._write(key, value)


@dataclass(frozen=True)
class VarDef:
    """One variable. ``default``: a value for every element, or a tuple with one value per element
    of the last dimension (repeated for every record, e.g. one probe record of ``_WP``), or one per
    element of the whole array (row-major)."""

    name: str
    type: str = "REAL"
    shape: tuple[int, ...] = ()
    default: Value | tuple = 0
    writable: bool = True               # False: system data, only the NC writes it (set_system)
    axis_indexed: bool = False          # $AA_MM[X]
    first_index: int = 0                # $AC_MEA[1], [2]
    length: int | None = None           # STRING[n]
    scope: str = "GUD"                  # R, GUD, SYS, LUD
    description: str = ""

    def __post_init__(self) -> None:
        if self.type not in TYPES:
            raise ValueError(f"{self.name}: type must be one of {TYPES}")
        if any(int(d) < 1 for d in self.shape):
            raise ValueError(f"{self.name}: every dimension needs at least one element")
        if isinstance(self.default, tuple):
            size = math.prod(self.shape) if self.shape else 1
            last = self.shape[-1] if self.shape else 1
            if len(self.default) not in (size, last):
                raise ValueError(f"{self.name}: {len(self.default)} defaults for shape {self.shape}")

    @property
    def is_array(self) -> bool:
        return self.axis_indexed or bool(self.shape)

    @property
    def size(self) -> int:
        return math.prod(self.shape) if self.shape else 1

    def default_at(self, key: Key) -> Value:
        d = self.default
        if not isinstance(d, tuple):
            return self.coerce(d)
        if self.axis_indexed or not self.shape:
            return self.coerce(d[0])
        idx = (key,) if isinstance(key, int) else tuple(key)
        flat = 0
        for i, dim in zip(idx, self.shape, strict=True):
            flat = flat * dim + (i - self.first_index)
        if len(d) == self.size:
            return self.coerce(d[flat])
        return self.coerce(d[flat % self.shape[-1]])

    def key(self, index: tuple) -> Key:
        """The backing key of ``index`` (a tuple of ints, or of one axis name), range-checked."""
        index = tuple(index)
        if self.axis_indexed:
            return self._axis_key(index)
        if not self.shape:
            if index:
                raise IndexOutOfRange(f"{self.name} is not an array and takes no index")
            return ()
        if len(index) != len(self.shape):
            need = ", ".join("i" for _ in self.shape)
            raise IndexOutOfRange(f"{self.name} needs {len(self.shape)} "
                                  f"{'index' if len(self.shape) == 1 else 'indices'}: {self.name}[{need}]")
        out = [self._element(i, dim) for i, dim in zip(index, self.shape, strict=True)]
        return out[0] if len(out) == 1 else tuple(out)

    def _axis_key(self, index: tuple) -> str:
        if len(index) != 1 or not isinstance(index[0], str):
            raise IndexOutOfRange(f"{self.name} is indexed by an axis name, e.g. {self.name}[X]")
        axis = index[0].upper()
        if axis not in AXIS_LETTERS:
            raise IndexOutOfRange(f"{self.name}[{index[0]}]: {index[0]} is not an axis")
        return axis

    def _element(self, i, dim: int) -> int:
        """One index: a whole number within the dimension (from ``first_index``)."""
        if isinstance(i, str) or isinstance(i, bool):
            raise IndexOutOfRange(f"{self.name}: an index must be a number")
        if isinstance(i, float):
            if not math.isfinite(i) or i != int(i):
                raise IndexOutOfRange(f"{self.name}[{_fmt(i)}]: an index must be a whole number")
            i = int(i)
        lo, hi = self.first_index, self.first_index + dim - 1
        if not lo <= i <= hi:
            raise IndexOutOfRange(f"{self.name}[{i}]: the index must lie within {lo}..{hi}")
        return int(i)

    def coerce(self, value: Any) -> Value:
        """``value`` as this variable's type (INT rounds half away from zero, like the 840D)."""
        if self.type == "STRING":
            if not isinstance(value, str):
                raise InvalidValue(f"{self.name} holds a text; assign it in quotes, e.g. {self.name}=\"ABC\"")
            if self.length is not None and len(value) > self.length:
                raise InvalidValue(f"{self.name} holds at most {self.length} characters")
            return value
        if isinstance(value, str):
            raise InvalidValue(f"{self.name} holds a number, not the text \"{value}\"")
        try:
            number = float(value)
        except OverflowError:           # an integer beyond the REAL range (issue 25)
            raise InvalidValue(f"{self.name}: the value is too large for a REAL") from None
        if not math.isfinite(number):
            raise InvalidValue(f"{self.name}: the value is not a finite number")
        if self.type == "REAL":
            return number
        if self.type == "BOOL":
            return number != 0.0
        rounded = int(math.floor(abs(number) + 0.5)) * (1 if number >= 0 else -1)
        if not INT_RANGE[0] <= rounded <= INT_RANGE[1]:
            raise InvalidValue(f"{self.name}: {_fmt(number)} is too large for an INT")
        return rounded

    def keys(self, axes: Iterable[str] = AXIS_LETTERS) -> list[Key]:
        """Every element's key, row-major (axis-indexed: the given axes)."""
        if self.axis_indexed:
            return list(axes)
        if not self.shape:
            return [()]
        keys: list[tuple[int, ...]] = [()]
        for dim in self.shape:
            keys = [(*k, i) for k in keys for i in range(self.first_index, self.first_index + dim)]
        return [k[0] if len(k) == 1 else k for k in keys]


def _fmt(x: float) -> str:
    return f"{x:g}"


class Variables:
    """The NC's variables, thread-safe (the API may read while a program runs)."""

    def __init__(self, definitions: Iterable[VarDef] | None = None, *,
                 backings: Mapping[str, Backing] | None = None, axes: Iterable[str] = ("X", "Y", "Z")):
        self._lock = threading.RLock()
        self._defs: dict[str, VarDef] = {}
        self._values: dict[str, dict[Key, Value]] = {}
        self._backings: dict[str, Backing] = {}
        self._locals: set[str] = set()
        self.axes = tuple(axes)
        for d in (default_definitions() if definitions is None else definitions):
            self.define(d)
        for name, backing in (backings or {}).items():
            self.bind(name, backing)

    # --- definitions ---------------------------------------------------------------------------
    def define(self, definition: VarDef, *, replace: bool = False) -> None:
        name = definition.name.upper()
        if definition.name != name:
            definition = dataclasses.replace(definition, name=name)
        with self._lock:
            if name in self._defs and not replace:
                raise ValueError(f"variable {name} is already defined")
            self._defs[name] = definition
            self._values[name] = {}

    def bind(self, name: str, backing: Backing) -> None:
        """Keep the elements of ``name`` in ``backing`` (persistent GUD arrays, live system data)."""
        name = name.upper()
        with self._lock:
            if name not in self._defs:
                raise UnknownVariable(f"{name} is not defined")
            self._backings[name] = backing

    def define_locals(self, definitions: Iterable[VarDef]) -> None:
        """Local user data (DEF) of a program: replaces the previous program's locals."""
        with self._lock:
            self.clear_locals()
            for d in definitions:
                if d.name in self._defs:
                    raise ValueError(f"{d.name} is already defined")
                self.define(d)
                self._locals.add(d.name)

    def clear_locals(self) -> None:
        with self._lock:
            for name in self._locals:
                self._defs.pop(name, None)
                self._values.pop(name, None)
                self._backings.pop(name, None)
            self._locals.clear()

    def has(self, name: str) -> bool:
        return name.upper() in self._defs

    def definition(self, name: str) -> VarDef:
        try:
            return self._defs[name.upper()]
        except KeyError:
            raise UnknownVariable(f"{name} is not a known variable") from None

    def names(self, scope: str | None = None) -> list[str]:
        with self._lock:
            return sorted(n for n, d in self._defs.items() if scope is None or d.scope == scope)

    # --- element access ------------------------------------------------------------------------
    def get(self, name: str, index: tuple = ()) -> Value:
        d = self.definition(name)
        key = d.key(index)
        return self._get(d, key)

    def _get(self, d: VarDef, key: Key) -> Value:
        with self._lock:
            backing = self._backings.get(d.name)
            values = self._values[d.name]
            if backing is None:
                return values[key] if key in values else d.default_at(key)
        try:
            raw = backing[key]
        except (KeyError, IndexError, LookupError):
            return d.default_at(key)
        return d.coerce(raw)

    def set(self, name: str, value: Value, index: tuple = ()) -> None:
        """A program's write: refused for system data."""
        d = self.definition(name)
        if not d.writable:
            raise WriteProtected(f"{d.name} is written by the control only")
        self._set(d, d.key(index), value)

    def set_system(self, name: str, value: Value, index: tuple = ()) -> None:
        """The NC's own write (e.g. $AA_MM after a measuring move)."""
        d = self.definition(name)
        self._set(d, d.key(index), value)

    def _set(self, d: VarDef, key: Key, value: Value) -> None:
        value = d.coerce(value)
        with self._lock:
            backing = self._backings.get(d.name)
            if backing is None:
                self._values[d.name][key] = value
                return
        backing[key] = value

    def resolve(self, name: str, index: tuple) -> tuple[VarDef, Key]:
        """Definition and key of ``name[index]`` (checks name and range; no access)."""
        d = self.definition(name)
        return d, d.key(index)

    def reset(self, name: str) -> None:
        """Back to the defaults (in-memory values only; a backing keeps its data)."""
        d = self.definition(name)
        with self._lock:
            self._values[d.name] = {}

    # --- whole variables, by reference text (the API) -------------------------------------------
    def snapshot(self, name: str):
        """JSON-ready value: a scalar, a (nested) list for arrays, ``{axis: value}`` by axis."""
        d = self.definition(name)
        if d.axis_indexed:
            return {a: self._get(d, a) for a in self.axes}
        if not d.shape:
            return self._get(d, ())
        flat: list[object] = [self._get(d, k) for k in d.keys()]     # nested into rows below
        for dim in reversed(d.shape[1:]):
            flat = [flat[i:i + dim] for i in range(0, len(flat), dim)]
        return flat

    def read(self, reference: str):
        """``"R1"``, ``"R[5]"``, ``"_EV[9]"``, ``"$AA_MM[X]"`` -> the element; ``"_OVR"`` -> the whole."""
        name, index = self._parse_ref(reference)
        if index is None:
            return self.snapshot(name)
        return self.get(name, index)

    def write(self, reference: str, value: Value) -> None:
        """A write through the API (same rules as a program's write)."""
        name, index = self._parse_ref(reference)
        d = self.definition(name)
        if index is None:
            if d.is_array:
                raise IndexOutOfRange(f"{d.name} is an array: name the element, e.g. {d.name}[0]")
            index = ()
        self.set(name, value, index)

    def _parse_ref(self, reference: str) -> tuple[str, tuple | None]:
        from . import nodes as n
        from .parser import parse_reference

        try:
            var = parse_reference(reference)
        except (NcError, LarkError, ValueError):     # not NC text, or not one variable
            raise UnknownVariable(f"{reference!r} is not a variable reference") from None
        if not var.indices:
            return var.name, None
        index: list[int | float | str] = []
        for e in var.indices:
            if isinstance(e, n.Num):
                index.append(e.value)
            elif isinstance(e, n.Var) and not e.indices:
                index.append(e.name)
            elif isinstance(e, n.Unary) and e.op == "-" and isinstance(e.operand, n.Num):
                index.append(-e.operand.value)
            else:
                raise UnknownVariable(f"{reference!r}: an index must be a number or an axis name")
        return var.name, tuple(index)


# --- the definitions of the control ------------------------------------------------------------

def r_parameters(count: int = 100) -> VarDef:
    """R0 .. R{count-1} (840D default: 100, MD 28050)."""
    return VarDef("R", "REAL", (count,), 0.0, scope="R", description="R parameters")


GUD5, GUD6 = "GUD5", "GUD6"


def _gud_real(name, default=0.0, shape=(), text="", scope=GUD5) -> VarDef:
    return VarDef(name, "REAL", shape, default, scope=scope, description=text)


def _gud_int(name, default=0, shape=(), text="", scope=GUD5) -> VarDef:
    return VarDef(name, "INT", shape, default, scope=scope, description=text)


def _gud_bool(name, default=0, shape=(), text="", scope=GUD6) -> VarDef:
    return VarDef(name, "BOOL", shape, default, scope=scope, description=text)


def _gud_string(name, length, default="", shape=(), text="", scope=GUD5) -> VarDef:
    return VarDef(name, "STRING", shape, default, length=length, scope=scope, description=text)


def measuring_cycle_gud(*, ev_count: int = 20, mv_count: int = 20, probe_records: int = 3,
                        tool_probe_records: int = 3, calibration_records: int = 3) -> list[VarDef]:
    """GUD5/GUD6 of the measuring cycles SW 6.3 (measuring-math §3.2, measuring-math §4; manual §2.2, §9.2.1)."""
    return [*_gud_inputs(), *_gud_results(ev_count, mv_count),
            *_gud_records(ev_count, mv_count, probe_records, tool_probe_records, calibration_records),
            *_gud_logging()]


def _gud_inputs() -> list[VarDef]:
    return [
        # --- input parameters (measuring-math §4.1) --------------------------------------------------------
        _gud_int("_MVAR", text="measuring variant"),
        _gud_int("_MA", text="measuring axis (1 abscissa, 2 ordinate, 3 applicate)"),
        _gud_int("_MD", text="measuring direction (0 +, 1 -)"),
        _gud_real("_SETVAL", text="setpoint (active unit system)"),
        _gud_real("_SETV", shape=(9,), text="additional setpoints"),
        _gud_real("_ID", text="incremental infeed / offset"),
        _gud_real("_CPA", text="centre abscissa"),
        _gud_real("_CPO", text="centre ordinate"),
        _gud_real("_SZA", text="protection zone abscissa"),
        _gud_real("_SZO", text="protection zone ordinate"),
        _gud_real("_STA1", text="start / setpoint angle"),
        _gud_real("_INCA", text="incremental / second angle"),
        _gud_int("_RA", text="CYCLE998: 0 rotate the frame, > 0 rotary axis"),
        _gud_real("_RF", text="feed on circular intermediate paths"),
        _gud_int("_TNUM", text="tool number for automatic tool offset"),
        _gud_string("_TNAME", 32, text="tool name"),
        _gud_int("_KNUM", text="correction target (zero offset or tool offset)"),
        _gud_int("_DLNUM", text="DL number of setup/sum offset"),
        _gud_string("_TENV", 32, text="tool environment"),
        _gud_real("_VMS", text="variable measuring feed (0 = 150/300 mm/min)"),
        _gud_real("_CORA", text="correction angle for mono probes"),
        _gud_real("_TZL", 0.001, text="zero offset range"),
        _gud_real("_TMV", 0.7, text="mean value range"),
        _gud_real("_TNVL", 1.2, text="triangle distortion limit"),
        _gud_real("_TUL", 1.0, text="upper tolerance"),
        _gud_real("_TLL", -1.0, text="lower tolerance"),
        _gud_real("_TDIF", 1.2, text="dimensional difference check"),
        _gud_real("_TSA", 2.0, text="safe area"),
        _gud_real("_FA", 2.0, text="measuring path in mm"),
        _gud_int("_PRNUM", 1, text="probe number"),
        _gud_int("_EVNUM", 0, text="empirical / mean value memory"),
        _gud_int("_CALNUM", 0, text="calibration body number"),
        _gud_int("_NMSP", 1, text="measurements at the same point"),
        _gud_int("_K", 1, text="weighting factor of the mean value"),
        _gud_int("_NPTS", 0, text="touches on a circle, 3..36 (this HMI's extension; 0 = as the manual)"),
    ]


def _gud_results(ev_count: int, mv_count: int) -> list[VarDef]:
    return [
        # --- results (measuring-math §4.2) ------------------------------------------------------------------
        _gud_real("_OVR", shape=(32,), text="results, real"),
        _gud_int("_OVI", shape=(14,), text="results, integer"),
        # --- empirical and mean values (GUD5, persistent) ------------------------------------
        _gud_real("_EV", shape=(ev_count,), text="empirical values"),
        _gud_real("_MV", shape=(mv_count,), text="mean values"),
    ]


def _gud_records(ev_count: int, mv_count: int, probe_records: int, tool_probe_records: int,
                 calibration_records: int) -> list[VarDef]:
    cbit = [0] * 16
    cbit[3] = cbit[8] = 1
    chbit = [0] * 30
    chbit[1] = chbit[2] = chbit[24] = 1
    return [
        # --- GUD6: data records, bits, feeds ---------------------------------------------------
        _gud_int("_CVAL", (tool_probe_records, probe_records, calibration_records, tool_probe_records),
                (4,), "number of data records", scope=GUD6),
        _gud_real("_TP", (0, 0, 0, 0, 0, 0, 0, 133, 0, 2), (tool_probe_records, 10),
             "tool probe, machine-related", scope=GUD6),
        _gud_real("_TPW", (0, 0, 0, 0, 0, 0, 0, 133, 0, 2), (tool_probe_records, 10),
             "tool probe, workpiece-related", scope=GUD6),
        _gud_real("_WP", (6, 3, -3, 3, -3, 3, -3, 0, 0, 0, 0), (probe_records, 11), "workpiece probe", scope=GUD6),
        _gud_real("_KB", 0.0, (calibration_records, 7), "calibration bodies", scope=GUD6),
        _gud_real("_CM", (100, 1000, 1, 0.005, 20, 4, 10, 0), (8,), "tool measuring, rotating spindle", scope=GUD6),
        _gud_real("_MFS", 0.0, (6,), "speeds and feeds, rotating spindle", scope=GUD6),
        _gud_bool("_CBIT", tuple(cbit), (16,), "central bits"),
        _gud_bool("_CHBIT", tuple(chbit), (30,), "channel bits"),
        _gud_real("_SPEED", (50, 1000, 1000, 900), (4,), "traversing velocities", scope=GUD6),
        _gud_int("_EVMVNUM", (ev_count, mv_count), (2,), "number of EV / MV memories", scope=GUD6),
    ]


def _gud_logging() -> list[VarDef]:
    return [
        # --- logging (measuring-math §15) ---------------------------------------------------------------------
        _gud_string("_PROTNAME", 32, shape=(2,), text="log: program and file name", scope=GUD6),
        _gud_string("_HEADLINE", 80, shape=(10,), text="log: header lines", scope=GUD6),
        _gud_int("_PROTFORM", (60, 80, 1, 3, 1, 12), (6,), "log: format", scope=GUD6),
        _gud_string("_PROTSYM", 1, (";", "#"), (2,), "log: separators", scope=GUD6),
        _gud_string("_PROTVAL", 100, shape=(13,), text="log: header lines and values", scope=GUD6),
        _gud_int("_DIGIT", 3, text="log: decimal places", scope=GUD6),
        _gud_string("_TXT", 12, shape=(100,), text="log: formatted texts", scope=GUD6),
    ]


def system_variables() -> list[VarDef]:
    """System variables the programs read (only the control writes them)."""
    def sys(name, text, **kw):
        return VarDef(name, kw.pop("type", "REAL"), writable=False, scope="SYS", description=text, **kw)

    return [
        sys("$AA_MM", "measured value, machine coordinates (latched at the trigger)", axis_indexed=True),
        sys("$AA_MW", "measured value, workpiece coordinates (latched at the trigger)", axis_indexed=True),
        sys("$AC_MEA", "probe has switched in the last measuring move", type="BOOL", shape=(2,),
            first_index=1),
        sys("$AA_IM", "actual position, machine coordinates", axis_indexed=True),
        sys("$AA_IW", "actual position, workpiece coordinates", axis_indexed=True),
        sys("$P_TOOLNO", "tool in the spindle (0 = none)", type="INT"),
        sys("$P_TOOL", "active D number", type="INT"),
        sys("$PI", "the circle constant pi", default=math.pi),
    ]


def default_definitions(r_count: int = 100) -> list[VarDef]:
    return [r_parameters(r_count), *measuring_cycle_gud(), *system_variables()]

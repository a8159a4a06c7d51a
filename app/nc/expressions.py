"""Evaluation of expressions and assignments against the variable store.

Arithmetic as on the 840D: ``+ - * /`` (``/`` always real), ``DIV`` (integer quotient, truncated),
``MOD`` (remainder, sign of the dividend), comparisons ``== <> < > <= >=`` (the weakest operators:
``IF (R1==1) AND (R2==2)`` needs its parentheses), ``AND OR XOR NOT``; angles in degrees.
REAL equality compares with a relative tolerance of 1e-12 (0.1+0.2 == 0.3 is true).

An ``Evaluator`` collects the writes of one block in ``pending`` (read back by later words of the
same block) so that a block that fails leaves the store untouched; ``commit()`` writes them.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from engine import alarms
from engine.alarms import AlarmDef

from . import nodes as n
from .modal import AXIS_LETTERS
from .variables import Key, Value, VarDef, VariableError, Variables


class EvalError(Exception):
    """An expression that cannot be evaluated, located at ``pos``."""

    def __init__(self, message: str, pos: n.Pos | None, alarm: AlarmDef = alarms.NC_ARITHMETIC):
        super().__init__(message)
        self.message = message
        self.pos = pos
        self.alarm = alarm


def _round_half_away(x: float) -> float:
    return math.floor(abs(x) + 0.5) * (1.0 if x >= 0 else -1.0)


def _asin(x: float) -> float:
    if not -1.0 <= x <= 1.0:
        raise ValueError(f"ASIN({x:g}): the argument must lie within -1..1")
    return math.degrees(math.asin(x))


def _acos(x: float) -> float:
    if not -1.0 <= x <= 1.0:
        raise ValueError(f"ACOS({x:g}): the argument must lie within -1..1")
    return math.degrees(math.acos(x))


def _sqrt(x: float) -> float:
    if x < 0.0:
        raise ValueError(f"SQRT({x:g}): the square root of a negative number")
    return math.sqrt(x)


def _ln(x: float) -> float:
    if x <= 0.0:
        raise ValueError(f"LN({x:g}): the logarithm needs a number greater than 0")
    return math.log(x)


#: name -> (number of arguments, function); angles in degrees
FUNCTIONS: dict[str, tuple[int, Callable[..., float]]] = {
    "SIN": (1, lambda a: math.sin(math.radians(a))),
    "COS": (1, lambda a: math.cos(math.radians(a))),
    "TAN": (1, lambda a: math.tan(math.radians(a))),
    "ASIN": (1, _asin),
    "ACOS": (1, _acos),
    "ATAN2": (2, lambda y, x: math.degrees(math.atan2(y, x))),
    "SQRT": (1, _sqrt),
    "ABS": (1, abs),
    "POT": (1, lambda a: a * a),
    "TRUNC": (1, lambda a: float(math.trunc(a))),
    "ROUND": (1, _round_half_away),
    "LN": (1, _ln),
    "EXP": (1, math.exp),
    "MINVAL": (2, min),
    "MAXVAL": (2, max),
}


def as_text(value: Value) -> str:
    """A value as ``<<`` converts it: texts stay, whole numbers without decimals, reals in their
    shortest form (3.5, 0.001)."""
    if isinstance(value, str):
        return value
    if isinstance(value, bool):
        return "1" if value else "0"
    if isinstance(value, float) and value.is_integer():
        return str(int(value))
    return repr(value) if isinstance(value, float) else str(value)


def _num(value: Value, pos: n.Pos, what: str) -> float:
    if isinstance(value, str):
        raise EvalError(f"{what}: the text \"{value}\" is not a number", pos, alarms.NC_VALUE_RANGE)
    return float(value)


def _close(a: float, b: float) -> bool:
    return a == b or math.isclose(a, b, rel_tol=1e-12, abs_tol=1e-300)


#: the operators on two numbers: arithmetic (result checked for size, integers kept), the rest
#: (comparisons with the control's tolerance, logic, DIV) as they are; which divide by their right side
_ARITHMETIC: dict[str, Callable[[float, float], float]] = {
    "+": lambda x, y: x + y, "-": lambda x, y: x - y, "*": lambda x, y: x * y, "/": lambda x, y: x / y,
    "MOD": math.fmod,
}
_LOGIC: dict[str, Callable[[float, float], Value]] = {
    "DIV": lambda x, y: math.trunc(x / y),
    "==": _close, "<>": lambda x, y: not _close(x, y),
    "<": lambda x, y: x < y and not _close(x, y), ">": lambda x, y: x > y and not _close(x, y),
    "<=": lambda x, y: x < y or _close(x, y), ">=": lambda x, y: x > y or _close(x, y),
    "AND": lambda x, y: bool(x) and bool(y), "OR": lambda x, y: bool(x) or bool(y),
    "XOR": lambda x, y: bool(x) != bool(y),
}
_ZERO_DIVISION = {"/": "division by zero", "DIV": "division by zero (DIV)", "MOD": "division by zero (MOD)"}


def _on_texts(op: str, a: Value, b: Value, pos: n.Pos) -> Value:
    """``<<`` joins two values as texts; ``==``/``<>`` compare two texts (not a text with a number)."""
    if op == "<<":
        return as_text(a) + as_text(b)
    if not (isinstance(a, str) and isinstance(b, str)):
        raise EvalError(f"'{op}' compares a text with a number", pos, alarms.NC_VALUE_RANGE)
    return (a == b) if op == "==" else (a != b)


class Evaluator:
    """Evaluates the expressions of one block; writes go to ``pending`` until ``commit()``."""

    def __init__(self, variables: Variables):
        self.variables = variables
        self._pending: dict[tuple[str, Key], Value] = {}
        self._order: list[tuple[VarDef, Key, Value]] = []

    # --- values -------------------------------------------------------------------------------
    def eval(self, expr: n.Expr) -> Value:
        try:
            return self._eval(expr)
        except EvalError:
            raise
        except VariableError as e:
            raise EvalError(e.message, getattr(expr, "pos", None), e.alarm) from None

    def number(self, expr: n.Expr, what: str = "the value") -> float:
        return _num(self.eval(expr), expr.pos, what)

    def _eval(self, e: n.Expr) -> Value:
        if isinstance(e, n.Num):
            return e.value
        if isinstance(e, n.Str):
            return e.value
        if isinstance(e, n.Var):
            return self.read(e)
        if isinstance(e, n.Unary):
            v = self._eval(e.operand)
            if e.op == "<<":
                return as_text(v)
            if e.op == "NOT":
                return not _num(v, e.pos, "NOT")
            x = _num(v, e.pos, e.op)
            return -x if e.op == "-" else x
        if isinstance(e, n.Binary):
            return self._binary(e)
        if isinstance(e, n.Func):
            return self._function(e)
        raise EvalError(f"cannot evaluate {e!r}", getattr(e, "pos", None), alarms.NC_INTERNAL)

    def _binary(self, e: n.Binary) -> Value:
        a, b = self._eval(e.left), self._eval(e.right)
        op = e.op
        if op == "<<" or (op in ("==", "<>") and (isinstance(a, str) or isinstance(b, str))):
            return _on_texts(op, a, b, e.pos)
        x, y = _num(a, e.pos, op), _num(b, e.pos, op)
        if y == 0.0 and op in _ZERO_DIVISION:
            raise EvalError(_ZERO_DIVISION[op], e.pos)
        if op in _LOGIC:
            return _LOGIC[op](x, y)
        arithmetic = _ARITHMETIC.get(op)
        if arithmetic is None:
            raise EvalError(f"unknown operator {op}", e.pos, alarms.NC_INTERNAL)
        r = arithmetic(x, y)
        if not math.isfinite(r):
            raise EvalError(f"the result of '{op}' is too large", e.pos)
        if isinstance(a, int) and isinstance(b, int) and op in "+-*" and not isinstance(r, bool):
            return int(r) if abs(r) < 2**53 else r          # integers stay integers (INT variables, indices)
        return r

    def _function(self, e: n.Func) -> float:
        if e.name not in FUNCTIONS:
            raise EvalError(f"{e.name} is not a function of this control", e.pos, alarms.NC_NAME_UNKNOWN)
        arity, fn = FUNCTIONS[e.name]
        if len(e.args) != arity:
            raise EvalError(f"{e.name} takes {arity} argument{'s' if arity > 1 else ''}", e.pos, alarms.NC_SYNTAX)
        args = [_num(self._eval(a), a.pos, e.name) for a in e.args]
        try:
            r = fn(*args)
        except (ValueError, OverflowError) as err:
            raise EvalError(str(err) if str(err).startswith(e.name) else f"{e.name}: {err}", e.pos) from None
        if not math.isfinite(r):
            raise EvalError(f"{e.name}: the result is not a finite number", e.pos)
        return r

    # --- variables ------------------------------------------------------------------------------
    def index(self, var: n.Var, d: VarDef) -> tuple:
        """The index values of ``var`` (axis names for axis-indexed variables)."""
        if d.axis_indexed:
            if len(var.indices) != 1:
                raise EvalError(f"{d.name} takes one axis name as index, e.g. {d.name}[X]", var.pos,
                                alarms.NC_ARRAY_INDEX)
            (i,) = var.indices
            if isinstance(i, n.Var) and not i.indices and i.name in AXIS_LETTERS:
                return (i.name,)
            raise EvalError(f"{d.name} takes an axis name as index, e.g. {d.name}[X]", i.pos, alarms.NC_ARRAY_INDEX)
        out = []
        for i in var.indices:
            v = self._eval(i)
            if isinstance(v, str):
                raise EvalError(f"{d.name}: an index must be a number", i.pos, alarms.NC_ARRAY_INDEX)
            out.append(v)
        return tuple(out)

    def resolve(self, var: n.Var) -> tuple[VarDef, tuple, Key]:
        try:
            d = self.variables.definition(var.name)
            index = self.index(var, d)
            return d, index, d.key(index)
        except VariableError as err:
            raise EvalError(err.message, var.pos, err.alarm) from None

    def read(self, var: n.Var) -> Value:
        d, index, key = self.resolve(var)
        if d.is_array and not var.indices:
            raise EvalError(f"{d.name} is an array: name the element, e.g. {d.name}[0]", var.pos,
                            alarms.NC_ARRAY_INDEX)
        if (d.name, key) in self._pending:
            return self._pending[(d.name, key)]
        try:
            return self.variables.get(d.name, index)
        except VariableError as err:
            raise EvalError(err.message, var.pos, err.alarm) from None

    def assign(self, word: n.Assign) -> None:
        """``R1=...``, ``_SETV[0]=SET(1,2,3)`` (fills consecutive elements of the last dimension)."""
        target = word.target
        d, index, key = self.resolve(target)
        if not d.writable:
            raise EvalError(f"{d.name} is written by the control only", target.pos, alarms.NC_WRITE_PROTECTED)
        if d.is_array and not target.indices:
            raise EvalError(f"{d.name} is an array: name the element, e.g. {d.name}[0]", target.pos,
                            alarms.NC_ARRAY_INDEX)
        values = [self.eval(v) for v in word.values]
        if word.is_set and (d.axis_indexed or not d.shape):
            raise EvalError(f"SET fills an array; {d.name} is not one", target.pos, alarms.NC_SYNTAX)
        keys = [key]
        if word.is_set:
            all_keys = d.keys()
            start = all_keys.index(key)
            if start + len(values) > len(all_keys):
                raise EvalError(f"SET writes {len(values)} values from {d.name}{list(index)}: beyond the end of "
                                f"{d.name}", target.pos, alarms.NC_ARRAY_INDEX)
            keys = all_keys[start:start + len(values)]
        for k, (v, expr) in zip(keys, zip(values, word.values, strict=True), strict=True):
            try:
                coerced = d.coerce(v)
            except VariableError as err:
                raise EvalError(err.message, expr.pos, err.alarm) from None
            self._pending[(d.name, k)] = coerced
            self._order.append((d, k, coerced))

    def fill(self, name: str, value: Value, pos: n.Pos) -> None:
        """Every element of ``name`` := ``value`` (``DEF REAL A[3]=2``)."""
        try:
            d = self.variables.definition(name)
            coerced = d.coerce(value)
        except VariableError as err:
            raise EvalError(err.message, pos, err.alarm) from None
        for k in d.keys(self.variables.axes):
            self._pending[(d.name, k)] = coerced
            self._order.append((d, k, coerced))

    @property
    def pending(self) -> list[tuple[str, Key, Value]]:
        return [(d.name, k, v) for d, k, v in self._order]

    def commit(self) -> None:
        """Write the block's assignments to the store, in the order they were programmed."""
        for d, key, value in self._order:
            index = (key,) if isinstance(key, (int, str)) else tuple(key)
            self.variables.set(d.name, value, index)
        self._order.clear()
        self._pending.clear()

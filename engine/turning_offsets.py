"""Tool-data and zero-offset updates of the turning cycles (turning.md §0.11, turning §2.4; MM turning §2.1–turning §2.3).

Pure functions: tool data in (an ``engine.turning.LatheTool`` or the API's tool dict), the
``(before, after)`` tool dicts out. Lengths and radii are radius values (turning.md §0.3).

- ``tool_measure_update``: CYCLE972/982 — first measurement (geometry := measured, wear := 0),
  re-measurement (wear += Δ), incremental (as first measurement) [L16933–L16937, L20070–L20074].
- ``correction_value``: the sign of a 974/994 correction on a lathe (turning.md §0.11 [I]).
- ``decode_tool_knum`` / ``ToolTarget``: the _KNUM tool layout of MM turning §2.3 (7 digits).
- ``workpiece_tool_update``: MM turning §2.3 write rule (_CHBIT[6], _CHBIT[8], setup/sum offsets _DLNUM).
- ``zero_offset_update``: MM turning §2.1/turning §2.2 translation of an unrotated frame, fine or coarse.
"""

from __future__ import annotations

import copy
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from engine import alarms, checks
from engine.turning import LENGTH_OF_AXIS, LatheTool, index
from engine.types import MeasuringError

QUANTITIES = ("l1", "l2", "l3", "radius")


def tool_dict(tool: LatheTool | Mapping[str, Any]) -> dict[str, Any]:
    """The API's lathe tool dict (turning §10.2): geometry, "wear", "base" and optional "dl" records
    {n: {"setup": {...}, "sum": {...}}} (deep copy, all quantities present)."""
    if isinstance(tool, LatheTool):
        out = tool.to_dict()
    else:
        out = copy.deepcopy(dict(tool))
        base = LatheTool.from_dict(out).to_dict()
        for name in ("wear", "base"):
            base[name].update({k: float(v) for k, v in dict(out.get(name) or {}).items()})
        out.update({k: base[k] for k in ("l1", "l2", "l3", "radius", "wear", "base")})
        out.setdefault("sl", base["sl"])
        out.setdefault("type", base["type"])
    return out


# --- CYCLE972/982 (turning.md §2.4, turning §0.11) ----------------------------------------------------

def tool_measure_update(tool: LatheTool | Mapping[str, Any], quantity: str, measured: float, *, remeasure: bool,
                        incremental: bool = False) -> tuple[dict[str, Any], dict[str, Any]]:
    """Write a measured effective length/radius (turning.md §2.4 [L16933–L16937]).

    First measurement (_CHBIT[3]=0) and incremental measuring (independent of _CHBIT[3]
    [L20070–L20074]): geometry := measured − base, wear := 0. Re-measurement (_CHBIT[3]=1):
    wear += Δ, Δ = measured − effective, geometry unchanged. The caller has already applied the
    turning §0.11 checks (_TSA, _TDIF, _TZL). The cutting-edge position ``sl`` is never changed.
    """
    checks.choice("quantity", quantity, QUANTITIES)
    before = tool_dict(tool)
    after = copy.deepcopy(before)
    base = 0.0 if quantity == "radius" else float(before["base"].get(quantity, 0.0))
    effective = float(before[quantity]) + float(before["wear"].get(quantity, 0.0)) + base
    if remeasure and not incremental:
        after["wear"][quantity] = float(before["wear"].get(quantity, 0.0)) + (float(measured) - effective)
    else:
        after[quantity] = float(measured) - base
        after["wear"][quantity] = 0.0
    return before, after


# --- the sign of a workpiece-measuring correction on a lathe (turning.md §0.11) ----------------

def correction_value(amount: float, *, scale: float, radius: bool, direction: int = 0,
                     two_point: bool = False, inside: bool = False, inverse: bool = False) -> float:
    """Compensation value c (radius) from the amount A the decision flow selected (turning.md §0.11).

    Δ = A·scale (scale ½ for a diameter difference: X with DIAMON; else 1). Lengths (L1 for X,
    L2 for Z): c = −Δ (raising L1/L2 moves the tip and the cut surface by +c, turning §0.4; manual's
    test cut Ø200.100 -> L1 60.000 -> 59.950 [L16855–L16858]). Radius: 1-point c = +d·Δ
    (d = travel direction of the probe); 2-point c = −Δ outside, +Δ inside. Inverse (_KNUM
    digit 5): c := −c.
    """
    delta = float(amount) * float(scale)
    if not radius:
        c = -delta
    elif two_point:
        c = delta if inside else -delta
    else:
        if direction not in (1, -1):
            raise ValueError("a 1-point radius correction needs the probe's travel direction")
        c = direction * delta
    return -c if inverse else c


# --- _KNUM for tool offsets (MM turning §2.3) ----------------------------------------------------------

@dataclass(frozen=True)
class ToolTarget:
    """Which offset a 974/994 correction goes to (MM turning §2.3, design jog-measuring §9.3).

    ``quantity``: "length" (the length acting on the measuring axis: X -> L1, Z -> L2, Y -> L3,
    or L1 with _CHBIT[19]), "l1", "l2", "l3" or "radius". ``geometry`` = _CHBIT[6];
    ``dl`` > 0: setup/sum offset DL number (_DLNUM) with ``setup`` = _CHBIT[8];
    ``tenv``: tool environment (_KNUM digit 7 = 2/3; the caller resolves T and D from it).
    """

    t: int = 0
    d: int = 1
    quantity: str = "length"
    inverse: bool = False
    geometry: bool = False
    dl: int = 0
    setup: bool = False
    tenv: str = ""

    def resolve(self, axis: str, y_like_x: bool = False) -> str:
        """The tool-data quantity for a measurement on ``axis``."""
        if self.quantity != "length":
            return self.quantity
        if axis == "Y" and y_like_x:
            return "l1"                                   # _CHBIT[19]: correct L1 [L26271–L26279]
        return LENGTH_OF_AXIS[axis]


def _knum_digits(n: int) -> tuple[int, int, int, int]:
    """Digits 4..7 of _KNUM, each checked (61321..61324 resp. 61407)."""
    d4, d5, d6, d7 = (n // 1000) % 10, (n // 10_000) % 10, (n // 100_000) % 10, (n // 1_000_000) % 10
    if d4 not in (0, 1, 2):
        raise MeasuringError(alarms.KNUM_DIGIT4, f"_KNUM={n}: 4th digit {d4} must be 0, 1 or 2")
    if d5 not in (0, 1):
        raise MeasuringError(alarms.KNUM_DIGIT5, f"_KNUM={n}: 5th digit {d5} must be 0 or 1")
    if d6 not in (0, 1, 2, 3, 4):
        raise MeasuringError(alarms.KNUM_DIGIT6, f"_KNUM={n}: 6th digit {d6} must be 0..4")
    if d7 not in (0, 1, 2, 3):
        raise MeasuringError(alarms.KNUM_DIGIT7, f"_KNUM={n}: 7th digit {d7} must be 0..3")
    return d4, d5, d6, d7


def _dl_number(n: int, d7: int, dlnum: int) -> int:
    """_DLNUM: 1..6 where digit 7 asks for a setup/sum offset, else 0..6 and not used (61406)."""
    if d7 in (1, 3):
        if isinstance(dlnum, bool) or int(dlnum) not in range(1, 7):
            raise MeasuringError(alarms.DL_NUMBER, f"_KNUM={n} needs a setup/sum offset _DLNUM in 1..6, got {dlnum!r}")
        return int(dlnum)
    if isinstance(dlnum, bool) or int(dlnum) not in range(0, 7):
        raise MeasuringError(alarms.DL_NUMBER, f"_DLNUM={dlnum!r} must be 0..6")
    return 0


def decode_tool_knum(knum: float | str, *, tnum: int = 0, tname: str = "", dlnum: int = 0, tenv: str = "",
                     geometry: bool = False, setup: bool = False) -> ToolTarget | None:
    """_KNUM (7-digit layout, MM turning §2.3) -> ToolTarget; 0 -> None (measure only).

    Digits 1–3 D number (0 -> 61328 unless the tool environment gives it), 4: 0/1 length in the
    measuring axis, 2 radius (else 61322); 5: 0 normal, 1 inverse (61323); 6: 0 as digit 4,
    1 L1, 2 L2, 3 L3, 4 radius (61324); 7: 0 length/radius, 1 setup/sum offset _DLNUM,
    2 tool environment _TENV, 3 both (61407, also for any higher digit). _DLNUM beyond 0..6 or 0
    where needed -> 61406; _TENV empty where needed -> 61405; no tool (_TNUM ≤ 0 and no _TNAME)
    -> 61320.
    """
    try:
        n = int(knum)
    except (TypeError, ValueError):
        raise MeasuringError(alarms.KNUM_DIGIT4, f"_KNUM={knum!r} is not a number") from None
    if n == 0:
        return None
    if n < 0 or n >= 10_000_000:
        raise MeasuringError(alarms.KNUM_DIGIT7, f"_KNUM={knum!r}: 7th and higher digits invalid")
    d = n % 1000
    d4, d5, d6, d7 = _knum_digits(n)
    env = d7 in (2, 3)
    if d == 0 and not env:
        raise MeasuringError(alarms.D_NUMBER, f"_KNUM={n}: the D number is 0")
    if env and not str(tenv or "").strip():
        raise MeasuringError(alarms.TOOL_ENVIRONMENT, f"_KNUM={n} needs a tool environment _TENV")
    dl = _dl_number(n, d7, dlnum)
    if not env and int(tnum or 0) <= 0 and not str(tname or "").strip():
        raise MeasuringError(alarms.TOOL_NUMBER, "no tool to correct: _TNUM = 0 and no _TNAME")
    quantity = {0: "radius" if d4 == 2 else "length", 1: "l1", 2: "l2", 3: "l3", 4: "radius"}[d6]
    return ToolTarget(t=int(tnum or 0), d=d, quantity=quantity, inverse=d5 == 1, geometry=bool(geometry),
                      dl=dl, setup=bool(setup), tenv=str(tenv or "") if env else "")


# --- MM turning §2.3 write rule ------------------------------------------------------------------------

def workpiece_tool_update(tool: LatheTool | Mapping[str, Any], quantity: str, c: float, target: ToolTarget
                          ) -> tuple[dict[str, Any], dict[str, Any]]:
    """Add the compensation value ``c`` (radius) per MM turning §2.3 [L26215–L26230]:

    _CHBIT[6]=0: wear += c;  _CHBIT[6]=1: geometry := geometry + wear + c, wear := 0.
    Setup/sum offsets (``target.dl`` > 0; the tool dict's "dl"[n] = {"setup": {...}, "sum": {...}}):
    _CHBIT[8]=0 as _CHBIT[6] with (geometry, wear) := (setup, sum); _CHBIT[8]=1: setup += c.
    A missing sum / setup record -> 61408 / 61409.
    """
    checks.choice("quantity", quantity, QUANTITIES)
    before = tool_dict(tool)
    after = copy.deepcopy(before)
    c = float(c)
    if target.dl:
        records = after.get("dl") or {}
        record = records.get(target.dl, records.get(str(target.dl)))
        if record is None or (target.setup or target.geometry) and "setup" not in record:
            raise MeasuringError(alarms.SETUP_OFFSET_MISSING, f"no setup offset DL{target.dl} for this tool")
        if not target.setup and "sum" not in record:
            raise MeasuringError(alarms.SUM_OFFSET_MISSING, f"no sum offset DL{target.dl} for this tool")
        if target.setup:
            record["setup"][quantity] = float(record["setup"].get(quantity, 0.0)) + c
        elif target.geometry:
            record["setup"][quantity] = (float(record["setup"].get(quantity, 0.0))
                                         + float(record["sum"].get(quantity, 0.0)) + c)
            record["sum"][quantity] = 0.0
        else:
            record["sum"][quantity] = float(record["sum"].get(quantity, 0.0)) + c
        return before, after
    wear = float(after["wear"].get(quantity, 0.0))
    if target.geometry:
        after[quantity] = float(after[quantity]) + wear + c
        after["wear"][quantity] = 0.0
    else:
        after["wear"][quantity] = wear + c
    return before, after


# --- zero offsets (MM turning §2.1, turning §2.2; turning.md §5.4) ----------------------------------------------

def zero_offset_update(coarse: Iterable[float], fine: Iterable[float], axis: str, d: float, *, fine_mode: bool) -> tuple[dict[str, Any], dict[str, Any]]:
    """T(axis) += d in an unrotated frame (MM turning §2.2, turning.md §5.4). ``fine_mode``: MD 18600=1
    and _CHBIT[21]=0 (and not _KNUM=2000): fine += d; else coarse := coarse + fine + d, fine := 0
    (MM turning §2.1, turning §2.2: the whole fine offset is folded in). Frames with a rotation: use engine.correction.correct with the measurement's fix."""
    j = index(axis)
    c_old = [float(v) for v in coarse]
    f_old = [float(v) for v in fine]
    c_new, f_new = list(c_old), list(f_old)
    if fine_mode:
        f_new[j] = f_old[j] + float(d)
    else:                                   # MM turning §2.2: T_coarse := T_coarse + T_fine + d, T_fine := 0
        c_new = [c + f for c, f in zip(c_old, f_old, strict=True)]
        c_new[j] += float(d)
        f_new = [0.0, 0.0, 0.0]
    return {"coarse": c_old, "fine": f_old}, {"coarse": c_new, "fine": f_new}

"""Tool-offset update from a workpiece measurement: compensation value c and the tool data after.

Spec: measuring-math §2.3 (_KNUM targets, write rule _CHBIT[6], halving for diameters/widths),
measuring-math §8.3/measuring-math §9.1 (CYCLE977/978), turning.md §0.4 and turning §0.11 (sign on a lathe, turning §12 Q4); manual §2.3.4 to
2.3.6. Pure: numbers and plain dicts in, a frozen value object with plain dicts out.

The sign rule, stated once for mills and lathes alike [I] (measuring-math §2.3 / measuring-math §17 Q1,
turning §0.11 / turning §12 Q4). Let A be the amount the decision flow selects (engine.strategy
``Decision.corrected``: D, Mv or 0, EV already applied) and Δ the signed deviation of the
*probed surface* along the measuring axis, radius-scaled. The correction must move the next cut
surface by −Δ, so c = −Δ / (∂s/∂c), with ∂s/∂c the shift of the cut surface per unit increase
of the corrected offset:

- length acting along the measuring axis: the tool point is P = F − L along that axis
  (measuring-math §0.3, turning §0.4), so raising L by c moves the real tip and the surface it
  cuts by +c, whatever side of the material the tool works on: ∂s/∂c = +1 → **c = −Δ**;
- radius: a larger radius keeps the tool further from the material, i.e. moves the cut surface
  towards the side the tool - and the probe - came from, against the probe's travel d (±1, the
  direction from free space into the material): ∂s/∂c = −d → **c = d·Δ**.

With Δ per feature kind:

- ``surface`` (1-point, CYCLE978/974): Δ = A (A/2 when A is a diameter value, lathe X with DIAMON);
  radius c = d·Δ, length c = −Δ;
- ``bore``, ``slot``, ``inner_rectangle`` (m = +1) and ``shaft``, ``web``, ``outer_rectangle``
  (m = −1), A = diameter/width difference: the surface probed travelling d lies at Δ = d·m·A/2,
  so radius c = d·(d·m·A/2) = m·A/2 from either side: bore/slot/inner +A/2, shaft/web/outer −A/2
  (measuring-math §2.3); rectangles get the mean of both length differences as A (measuring-math §8.3 [I]);
- a length correction from a width feature only exists for a *turned* diameter (a lathe tool
  cuts it on one side of the turning centre; a milled bore is not resized by a length offset):
  ``side`` = ±1 = the sign of that surface's coordinate, Δ = side·A/2 for OD and ID alike,
  c = −side·A/2 (turning §0.11 CYCLE994 "length c = −Δ" is side = +1; side = −1 is the case
  where the manual sets the inverse digit);
- ``inverse`` (_KNUM digit 5, digit 7 in the 9-digit form): c := −c.

Alignment with measuring-math §2.3: its 1-point rule ``c = σ·D`` is this rule's radius case
exactly (σ = d) and its length case only for surfaces probed in minus direction (σ = −1, the
mill's top face of its worked check: c = −0.02); for lengths probed in plus direction (lathe ID
and back faces, turning §12 Q4) it had the wrong sign, here c = −Δ. Its bore/shaft rules
(±D/2) are unchanged.

Write rule (manual §2.3.6, measuring-math §2.3), on the value ``correct`` ("radius" or
"length") of the tool data ``{"length", "radius", "wear": {"length", "radius"}}``:
``mode`` "wear" (_CHBIT[6]=0): wear += c; "geometry" (_CHBIT[6]=1): geometry := geometry +
wear + c, wear := 0. Setup/sum offsets (_DLNUM, _CHBIT[8]) are not part of this tool model.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from engine import checks
from engine.strategy import Decision

__all__ = ["FEATURES", "ToolOffsetUpdate", "apply_compensation", "compensation_value",
           "tool_offset_update"]

# feature kind -> m: +1 inner (bore, slot, inner rectangle), −1 outer, 0 = 1-point surface
_WIDTH_SIGN = {"bore": 1, "slot": 1, "inner_rectangle": 1,
               "shaft": -1, "web": -1, "outer_rectangle": -1}
FEATURES = ("surface", *_WIDTH_SIGN)
_CORRECT = ("radius", "length")
_MODES = ("wear", "geometry")


def compensation_value(feature: str, amount: float, correct: str = "radius", *, direction: int | None = None,
                       side: int | None = None, amount_is_diameter: bool | None = None,
                       inverse: bool = False) -> float:
    """c, the radius-scaled correction of ``correct`` for the amount A (module docstring's rule).

    ``feature``: one of FEATURES. ``amount``: A (``Decision.corrected``). ``direction``: the
    probe's travel d = ±1 along the measuring axis (needed for a ``surface``). ``side``: ±1,
    for a length correction from a turned diameter/width. ``amount_is_diameter``: whether A is
    a diameter-type value to halve (default: True for the width features, False for a surface;
    a lathe surface on X with DIAMON passes True, CYCLE994 with DIAMOF passes False).
    ``inverse``: the _KNUM "inverse" digit. Returned c goes to _OVR[20] / result ``compensation``.
    """
    if feature not in FEATURES:
        raise ValueError(f"feature must be one of {', '.join(FEATURES)}, got {feature!r}")
    if correct not in _CORRECT:
        raise ValueError(f"correct must be 'radius' or 'length', got {correct!r}")
    a = checks.real("amount", amount)
    if amount_is_diameter is None:
        amount_is_diameter = feature != "surface"
    if not isinstance(amount_is_diameter, bool):
        raise ValueError(f"amount_is_diameter must be true or false, got {amount_is_diameter!r}")
    half = a / 2.0 if amount_is_diameter else a            # radius-scaled |Δ| (measuring-math §2.3 halving)
    if direction is not None:
        direction = checks.unit_sign("direction", direction)
    if feature == "surface":
        delta = half                                       # Δ of the probed surface
        if correct == "length":
            c = -delta                                     # turning §0.11: length c = −Δ
        else:
            if direction is None:
                raise ValueError("a radius correction from a 1-point surface needs the probe's direction")
            c = checks.unit_sign("direction", direction) * delta   # measuring-math §2.3: c = σ·D
    else:
        m = _WIDTH_SIGN[feature]
        if correct == "radius":
            c = m * half                                   # measuring-math §2.3: ±D/2
        else:
            if side is None:
                raise ValueError(f"a length offset does not resize a milled {feature}: a length "
                                 "correction from a width needs the side (±1) of a turned feature")
            c = -checks.unit_sign("side", side) * half           # turning §0.11 CYCLE994: c = −Δ
    if not isinstance(inverse, bool):
        raise ValueError(f"inverse must be true or false, got {inverse!r}")
    return -c if inverse else c                            # manual §2.3.4 digit 5: sign reversed


def _tool_copy(tool: Mapping[str, Any]) -> dict[str, Any]:
    if not isinstance(tool, Mapping):
        raise ValueError(f"tool must be a mapping, got {type(tool).__name__}")
    out = copy.deepcopy(dict(tool))
    wear = out.get("wear")
    if wear is None:
        wear = {}
    if not isinstance(wear, Mapping):
        raise ValueError(f"tool wear must be a mapping, got {type(wear).__name__}")
    wear = dict(wear)
    for key in _CORRECT:
        wear[key] = checks.real(f"wear.{key}", wear.get(key, 0.0))
        if key in out:
            out[key] = checks.real(key, out[key])
    out["wear"] = wear
    return out


def apply_compensation(tool: Mapping[str, Any], compensation: float, correct: str = "radius", mode: str = "wear") -> dict[str, Any]:
    """The tool data after writing c (manual §2.3.6, measuring-math §2.3 write rule).

    ``mode`` "wear" (_CHBIT[6]=0): wear[correct] += c; "geometry" (_CHBIT[6]=1):
    tool[correct] := tool[correct] + wear[correct] + c, wear[correct] := 0. Other keys of
    ``tool`` are copied unchanged; ``tool`` itself is not modified.
    """
    if correct not in _CORRECT:
        raise ValueError(f"correct must be 'radius' or 'length', got {correct!r}")
    if mode not in _MODES:
        raise ValueError(f"mode must be 'wear' or 'geometry', got {mode!r}")
    c = checks.real("compensation", compensation)
    after = _tool_copy(tool)
    if mode == "wear":
        after["wear"][correct] = after["wear"][correct] + c
    else:
        if correct not in after:
            raise ValueError(f"a geometry correction needs the tool's {correct}")
        after[correct] = after[correct] + after["wear"][correct] + c
        after["wear"][correct] = 0.0
    return after


@dataclass(frozen=True)
class ToolOffsetUpdate:
    """One tool-offset write: ``compensation`` c (radius-scaled, 0.0 when none; result key
    ``compensation``, _OVR[20]), the amount A it came from, and the tool data ``before`` and
    ``after`` (plain dicts; equal when ``written`` is False)."""

    feature: str
    correct: str
    mode: str
    amount: float
    compensation: float
    before: dict[str, Any]
    after: dict[str, Any]
    written: bool


def tool_offset_update(tool: Mapping[str, Any], amount: Decision | float | None, feature: str, *,
                       correct: str = "radius", mode: str = "wear", direction: int | None = None,
                       side: int | None = None, amount_is_diameter: bool | None = None,
                       inverse: bool = False) -> ToolOffsetUpdate:
    """c for ``amount`` and the tool data before/after (``compensation_value`` + ``apply_compensation``).

    ``amount``: an engine.strategy Decision (its ``corrected`` amount when it ``corrects``,
    else nothing is written), a number A (always written: in geometry mode even A = 0 folds the
    wear into the geometry, manual §2.3.6), or None (nothing written). Keywords as in
    ``compensation_value`` and ``apply_compensation``. ``before`` is the tool data as read
    (numbers as floats, a missing wear as zeros), ``after`` the data to write.
    """
    if correct not in _CORRECT:
        raise ValueError(f"correct must be 'radius' or 'length', got {correct!r}")
    if mode not in _MODES:
        raise ValueError(f"mode must be 'wear' or 'geometry', got {mode!r}")
    before = _tool_copy(tool)
    if isinstance(amount, Decision):
        amount = amount.corrected if amount.corrects else None
    if amount is None:
        if feature not in FEATURES:
            raise ValueError(f"feature must be one of {', '.join(FEATURES)}, got {feature!r}")
        return ToolOffsetUpdate(feature=feature, correct=correct, mode=mode, amount=0.0, compensation=0.0,
                                before=before, after=copy.deepcopy(before), written=False)
    c = compensation_value(feature, amount, correct, direction=direction, side=side,
                           amount_is_diameter=amount_is_diameter, inverse=inverse)
    after = apply_compensation(before, c, correct, mode)
    return ToolOffsetUpdate(feature=feature, correct=correct, mode=mode, amount=float(amount), compensation=c,
                            before=before, after=after, written=True)

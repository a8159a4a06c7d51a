"""The start guard's protection model from plain data (issue 24 §1, design.md §10.1).

The machine hands its model of the work space as data (``{"bodies": [{"solid": {...},
"cutouts": [...]}], "limits": {"X": [lo, hi], ...}}``, MCS): each solid has ``name``,
``rotation`` (local -> MCS, 3x3), ``centre`` and its shape: ``sphere`` + ``radius``, a circle
``radius`` or a ``polygon`` with ``half_height`` along local z. No model (None): every
positioning move is ``unknown``.

The probe's reach (measuring-math §1.3) comes as its own data (``braking_from_data``): the signal
delay ``latency_s``, the deceleration ``decel``, the loop gain ``kv`` and the permissible
deflection of the probe that switches; none: the reach is not checked.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from engine.guard import Body, Braking, ProtectionModel, Solid


def _solid(data: Mapping[str, Any]) -> Solid:
    polygon = data.get("polygon")
    return Solid(name=str(data.get("name", "")), centre=np.asarray(data["centre"], dtype=float),
                 rotation=np.asarray(data.get("rotation", np.eye(3)), dtype=float),
                 radius=float(data.get("radius", 0.0)), half_height=float(data.get("half_height", 0.0)),
                 polygon=None if polygon is None else np.asarray(polygon, dtype=float),
                 sphere=bool(data.get("sphere", False)))


def model_from_data(data: Mapping[str, Any] | None) -> ProtectionModel:
    if data is None:
        return ProtectionModel(known=False)
    bodies = tuple(Body(_solid(b["solid"]), tuple(_solid(c) for c in b.get("cutouts", ())))
                   for b in data.get("bodies", ()))
    limits = {str(a): (float(v[0]), float(v[1])) for a, v in (data.get("limits") or {}).items()}
    return ProtectionModel(bodies, limits, True)


def braking_from_data(data: Mapping[str, Any] | None, probe: str | None, override: float = 100.0) -> Braking | None:
    """The reach check's data for the probe ``probe`` ("workpiece" or "tool") switching at the
    feed override ``override`` (percent); None when the control has no braking data or that
    probe has no permissible deflection (it is not broken by overtravel)."""
    if data is None or probe is None:
        return None
    limit = (data.get("max_deflection") or {}).get(probe)
    if limit is None:
        return None
    return Braking(latency_s=float(data["latency_s"]), decel=float(data["decel"]), kv=float(data["kv"]),
                   max_deflection=float(limit), override=float(override))

"""The control's rotary-axis kinematic data (design.md §10.6): ``GET/PUT /api/kinematics``, undo.

The NC owns its machine data (design.md Standards): the lines live in the machine
(``KinematicData`` protocol, the simulator: nominal from the scenario until written; a scenario
load resets them). The HMI writes them through the machine and keeps the audit trail (kind
"kinematics", before/after = every line), at the ``settings`` level; an undo writes the lines
before a change again. Shape: ``{axis: {"point": [x, y, z], "direction": [dx, dy, dz]}}``
(head axes relative to the tool reference point, a table's in MCS); GET adds ``"unit"``.
"""

from __future__ import annotations

import math
from typing import Any

from app.errors import ConflictError, InvalidInput
from app.machine.protocol import KinematicData
from db import Database

from .machine_service import MachineService

KIND = "kinematics"
MAX_COORD = 10_000.0          # mm: a point further out is a typo
MIN_DIRECTION = 1e-6


def _vector(value: Any, field: str) -> list[float]:
    if not isinstance(value, list | tuple) or len(value) != 3:
        raise InvalidInput(f"{field}: three numbers [x, y, z] are needed", field=field)
    out = []
    for v in value:
        if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v) or abs(v) > MAX_COORD:
            raise InvalidInput(f"{field}: finite numbers within ±{MAX_COORD:g} are needed, got {v!r}", field=field)
        out.append(float(v))
    return out


def checked_lines(body: Any, known: dict) -> dict[str, dict[str, list[float]]]:
    """A PUT body validated against the machine's axes; directions normalised (400 naming the field)."""
    if not isinstance(body, dict) or not body:
        raise InvalidInput("kinematics: an object {axis: {\"point\", \"direction\"}} is needed", field="kinematics")
    out = {}
    for axis, line in body.items():
        if axis not in known:
            raise InvalidInput(f"{axis}: no kinematic data on this machine (axes: {', '.join(sorted(known)) or 'none'})",
                               field=str(axis))
        if not isinstance(line, dict) or set(line) - {"point", "direction", "unit"}:
            raise InvalidInput(f"{axis}: {{\"point\": [x, y, z], \"direction\": [dx, dy, dz]}} is needed", field=axis)
        point = _vector(line.get("point", known[axis]["point"]), f"{axis}.point")
        direction = _vector(line.get("direction", known[axis]["direction"]), f"{axis}.direction")
        norm = math.sqrt(sum(v * v for v in direction))
        if norm < MIN_DIRECTION:
            raise InvalidInput(f"{axis}.direction: must not be the zero vector", field=f"{axis}.direction")
        out[axis] = {"point": point, "direction": [v / norm for v in direction]}
    return out


class KinematicsService:
    def __init__(self, db: Database, machine: MachineService):
        self._db = db
        self._ms = machine

    def _control(self) -> KinematicData:
        machine = self._ms.machine
        if not isinstance(machine, KinematicData):
            raise ConflictError("this controller holds no rotary-axis kinematic data", code="not_supported")
        return machine

    def get(self) -> dict:
        machine = self._ms.machine
        return machine.kinematic_data() if isinstance(machine, KinematicData) else {}

    def put(self, body: Any, source: str = "api", detail: dict | None = None) -> dict:
        control = self._control()
        before = control.kinematic_data()
        lines = checked_lines(body, before)
        with self._db.unit() as unit:
            control.write_kinematic_data(lines)
            after = control.kinematic_data()
            unit.add_audit(KIND, KIND, before, after, source, detail)
        return after

    def restore(self, entry: dict, force: bool = False) -> dict:
        """Undo (``POST /api/audit/{id}/undo``): the lines before that change, as a new audited write."""
        control = self._control()
        current = control.kinematic_data()
        if not force and not _same(current, entry["after"]):
            raise ConflictError(f"the kinematic data changed after change #{entry['id']}; send {{\"force\": true}} "
                                "to restore anyway", code="changed_since")
        before = {a: line for a, line in (entry["before"] or {}).items() if a in current}
        value = self.put(before, source="undo", detail={"undo_of": entry["id"]})
        with self._db.unit(readonly=True) as unit:
            new_id = unit.audit(1, KIND)[0]["id"]
        return {"undone": entry["id"], "audit_id": new_id, "kind": KIND, "offset": KIND, "value": value}


def _same(a: dict, b: dict | None, tol: float = 1e-12) -> bool:
    if b is None or set(a) != set(b):
        return False
    for axis, line in a.items():
        for key in ("point", "direction"):
            if any(abs(float(x) - float(y)) > tol for x, y in zip(line[key], b[axis][key], strict=True)):
                return False
    return True

"""Zero offsets (G54.., BASIC_REF, BASIC_n): validated reads and audited writes.

A write merges onto the stored frame (components not given keep their value), is written to
the NC's copy once stored, and re-sends the active frame chain to the machine when the
written frame is part of it.
"""

from __future__ import annotations

import builtins

from app import checks
from app.errors import ConflictError, InvalidInput, NotFoundError
from app.records import frame_out_of_range
from db import Database
from engine.frames import GEOMETRY_AXES

from .machine_service import MachineService

FRAME_PARTS = ("trans", "fine", "rot")


class OffsetService:
    def __init__(self, db: Database, machine: MachineService):
        self._db = db
        self._machine = machine

    def names(self) -> list[str]:
        with self._db.unit(readonly=True) as unit:
            return unit.offset_names()

    def list(self) -> dict[str, dict]:
        """{name: frame} in chain order (BASIC_REF, BASIC_n, G54.., G505..)."""
        with self._db.unit(readonly=True) as unit:
            return unit.list_offsets()

    def get(self, name: str) -> dict:
        with self._db.unit(readonly=True) as unit:
            frame = unit.get_offset(name)
        if frame is None:
            raise NotFoundError(f"unknown zero offset {name!r}", code="unknown_offset")
        return frame

    def validate(self, name: str, changes: dict) -> dict:
        """The stored frame of ``name`` with ``changes`` applied, fully checked; nothing is written."""
        current = self.get(name)
        if not isinstance(changes, dict):
            raise InvalidInput("frame must be an object with trans, fine, rot")
        unknown = sorted(set(changes) - set(FRAME_PARTS))
        if unknown:
            raise InvalidInput(f"{unknown[0]}: unknown frame component (use trans, fine, rot)", field=unknown[0])
        allowed = {"trans": GEOMETRY_AXES + self._machine.rotary_axes, "fine": GEOMETRY_AXES, "rot": GEOMETRY_AXES}
        frame = {part: dict(current.get(part, {})) for part in FRAME_PARTS}
        for part, values in changes.items():
            if values is None:
                continue
            if not isinstance(values, dict):
                raise InvalidInput(f"{part}: must be an object keyed by axis", field=part)
            for axis, value in values.items():
                field = f"{part}.{axis}"
                if axis not in allowed[part]:
                    raise InvalidInput(f"{field}: unknown axis (allowed: {', '.join(allowed[part])})",
                                       field=field)
                number = checks.number(value, field)
                wrong = frame_out_of_range({part: {axis: number}})
                if wrong:
                    raise InvalidInput(wrong[1], field=wrong[0])
                frame[part][axis] = number
        return frame

    def put(self, name: str, changes: dict, source: str = "api", detail: dict | None = None) -> dict:
        frame = self.validate(name, changes)
        self._machine.check_holds(name, frame)
        with self._db.unit() as unit:
            _before, after = unit.put_offset(name, frame, source=source, detail=detail)
        self._machine.write_offset(name, after)          # the NC holds what was stored
        if name.startswith("BASIC") or name == self._machine.active_offset:
            self._machine.refresh_frame()
        return after

    def put_field(self, name: str, field: str, text: str, source: str = "screen") -> dict:
        """One table cell (``trans.X``, ``rot.Z``, ``trans.C``) from the screen."""
        part, _, axis = field.partition(".")
        if part not in FRAME_PARTS or not axis:
            raise InvalidInput(f"{field}: unknown field", field=field)
        return self.put(name, {part: {axis: checks.parse_number(text, field)}}, source=source)

    def audit(self, limit: int = 50, name: str | None = None, kind: str | None = None,
              before_id: int | None = None) -> builtins.list[dict]:       # list: the method above
        if not isinstance(limit, int) or not 1 <= limit <= 1000:
            raise InvalidInput("limit: must be 1..1000", field="limit")
        with self._db.unit(readonly=True) as unit:
            return unit.audit(limit, name, kind, before_id)

    def audit_entry(self, audit_id: int) -> dict:
        with self._db.unit(readonly=True) as unit:
            entry = unit.get_audit(audit_id)
        if entry is None:
            raise NotFoundError(f"no audit entry {audit_id}", code="unknown_audit_entry")
        return entry

    def restore(self, entry: dict, force: bool = False) -> dict:
        """Undo of an offset change: the frame before it, as a new audited write (source "undo").
        ConflictError ``changed_since`` when the offset differs from what that change wrote."""
        name = entry["offset"]
        with self._db.unit() as unit:
            current = unit.get_offset(name)
            if current is None:
                raise NotFoundError(f"unknown zero offset {name!r}", code="unknown_offset")
            if not force and not same_values(current, entry["after"]):
                raise ConflictError(f"{name} changed after change #{entry['id']}: restoring would also undo the "
                                    "later changes; send {\"force\": true} to restore anyway", code="changed_since")
            self._machine.check_holds(name, entry["before"])
            _before, after = unit.put_offset(name, entry["before"], source="undo",
                                             detail={"undo_of": entry["id"]})
            new_id = unit.audit(1, name)[0]["id"]
        self._machine.write_offset(name, after)
        if name.startswith("BASIC") or name == self._machine.active_offset:
            self._machine.refresh_frame()
        return {"undone": entry["id"], "audit_id": new_id, "kind": "offset", "offset": name, "value": after}


def same_values(a, b, tol: float = 1e-9) -> bool:
    """Equal JSON documents, numbers within ``tol`` (a stored float read back is the same float;
    the tolerance only keeps a rounding elsewhere from blocking an undo)."""
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same_values(a[k], b[k], tol) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(same_values(x, y, tol) for x, y in zip(a, b, strict=True))
    if isinstance(a, int | float) and isinstance(b, int | float) and not isinstance(a, bool) and not isinstance(b, bool):
        return abs(float(a) - float(b)) <= tol
    return a == b

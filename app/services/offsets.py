"""Zero offsets (G54.., BASIC_REF, BASIC_n): validated reads and audited writes.

A write merges onto the stored frame (components not given keep their value) and re-sends
the active frame chain to the machine when the written frame is part of it.
"""

from __future__ import annotations

import math

from app.errors import InvalidInput, NotFoundError
from db import Database
from engine.frames import GEOMETRY_AXES

from .machine_service import MachineService

FRAME_PARTS = ("trans", "fine", "rot")
MAX_TRANSLATION = 100_000.0   # mm (or deg for rotary axes)


def _number(value, field: str) -> float:
    if isinstance(value, str):
        try:
            value = float(value.strip().replace(",", "."))
        except ValueError:
            raise InvalidInput(f"{field}: {value!r} is not a number", field=field) from None
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise InvalidInput(f"{field}: must be a finite number", field=field)
    return float(value)


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
                number = _number(value, field)
                if part == "rot" and not abs(number) < 360.0:
                    raise InvalidInput(f"{field}: rotation must lie in (-360, 360) degrees", field=field)
                if abs(number) > MAX_TRANSLATION:
                    raise InvalidInput(f"{field}: at most {MAX_TRANSLATION:g} in magnitude", field=field)
                frame[part][axis] = number
        return frame

    def put(self, name: str, changes: dict, source: str = "api", detail: dict | None = None) -> dict:
        frame = self.validate(name, changes)
        with self._db.unit() as unit:
            _before, after = unit.put_offset(name, frame, source=source, detail=detail)
        if name.startswith("BASIC") or name == self._machine.active_offset:
            self._machine.refresh_frame()
        return after

    def put_field(self, name: str, field: str, text: str, source: str = "screen") -> dict:
        """One table cell (``trans.X``, ``rot.Z``, ``trans.C``) from the screen."""
        part, _, axis = field.partition(".")
        if part not in FRAME_PARTS or not axis:
            raise InvalidInput(f"{field}: unknown field", field=field)
        return self.put(name, {part: {axis: _number(text, field)}}, source=source)

    def audit(self, limit: int = 50, name: str | None = None) -> list[dict]:
        if not isinstance(limit, int) or not 1 <= limit <= 1000:
            raise InvalidInput("limit: must be 1..1000", field="limit")
        with self._db.unit(readonly=True) as unit:
            return unit.audit(limit, name)

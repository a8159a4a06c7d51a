"""Parts and characteristics (design.md §10.3): the part rows of a job and the measured values
with their band and verdict. A mixin of ``db.repository.Unit``: the same transaction."""

from __future__ import annotations

from datetime import UTC, datetime
from typing import Any

from sqlalchemy import delete, func, select
from sqlalchemy.orm import Session

from db.models import Characteristic, Part

PART_FIELDS = ("part_number", "order", "serial", "operator", "program")
CHARACTERISTIC_FIELDS = ("name", "nominal", "upper", "lower", "actual", "deviation", "verdict", "unit",
                         "compensation", "log_id")


def _now() -> str:
    return datetime.now(UTC).isoformat(timespec="microseconds")


def _part_dict(row: Part) -> dict[str, Any]:
    return {"id": row.id, "started": row.started, **{key: getattr(row, key) for key in PART_FIELDS}}


def _characteristic_dict(row: Characteristic) -> dict[str, Any]:
    return {"id": row.id, "part_id": row.part_id, "time": row.time,
            **{key: getattr(row, key) for key in CHARACTERISTIC_FIELDS}}


class PartsUnit:
    _session: Session
    machine: str                    # parts are the machine's; a characteristic is its part's

    def add_part(self, data: dict[str, Any]) -> dict[str, Any]:
        unknown = set(data) - set(PART_FIELDS)
        if unknown:
            raise ValueError(f"unknown part keys {sorted(unknown)}")
        if not isinstance(data.get("part_number"), str) or not data["part_number"]:
            raise ValueError("a part needs a part number")
        row = Part(machine=self.machine, started=_now(), **{key: data.get(key) for key in PART_FIELDS})
        self._session.add(row)
        self._session.flush()
        return _part_dict(row)

    def get_part(self, part_id: int) -> dict[str, Any] | None:
        row = self._session.get(Part, part_id)
        if row is None or row.machine != self.machine:
            return None
        return {**_part_dict(row), "characteristics": self.part_characteristics([part_id])[part_id]}

    def count_parts(self, part_number: str | None = None) -> int:
        query = select(func.count(Part.id)).where(Part.machine == self.machine)
        if part_number is not None:
            query = query.where(Part.part_number == part_number)
        return int(self._session.scalar(query) or 0)

    def list_parts(self, part_number: str | None = None, limit: int = 100, offset: int = 0,
                   oldest_first: bool = False) -> list[dict[str, Any]]:
        """Parts with their characteristics, newest first (``oldest_first``: in measuring order)."""
        query = select(Part).where(Part.machine == self.machine)
        if part_number is not None:
            query = query.where(Part.part_number == part_number)
        query = query.order_by(Part.id.asc() if oldest_first else Part.id.desc()).offset(offset).limit(limit)
        parts = [_part_dict(row) for row in self._session.scalars(query)]
        values = self.part_characteristics([p["id"] for p in parts])
        return [{**p, "characteristics": values[p["id"]]} for p in parts]

    def part_characteristics(self, part_ids: list[int]) -> dict[int, list[dict[str, Any]]]:
        found: dict[int, list[dict[str, Any]]] = {pid: [] for pid in part_ids}
        if part_ids:
            query = select(Characteristic).where(Characteristic.part_id.in_(part_ids)).order_by(Characteristic.id)
            for row in self._session.scalars(query):
                found[row.part_id].append(_characteristic_dict(row))
        return found

    def characteristic_names(self, part_id: int) -> list[str]:
        query = select(Characteristic.name).where(Characteristic.part_id == part_id)
        return list(self._session.scalars(query))

    def add_characteristic(self, part_id: int, data: dict[str, Any]) -> dict[str, Any]:
        unknown = set(data) - set(CHARACTERISTIC_FIELDS)
        if unknown:
            raise ValueError(f"unknown characteristic keys {sorted(unknown)}")
        row = Characteristic(part_id=part_id, time=_now(), **{key: data.get(key) for key in CHARACTERISTIC_FIELDS})
        if row.unit is None:
            row.unit = "mm"
        self._session.add(row)
        self._session.flush()
        return _characteristic_dict(row)

    def remove_characteristic(self, part_id: int, name: str) -> None:
        self._session.execute(delete(Characteristic).where(Characteristic.part_id == part_id,
                                                           Characteristic.name == name))

    def characteristic_series(self, part_number: str, name: str | None = None) -> list[dict[str, Any]]:
        """Every characteristic of the parts of ``part_number`` (of one name if given), in measuring
        order, each with its part's fields (``part``)."""
        query = (select(Characteristic, Part).join(Part, Characteristic.part_id == Part.id)
                 .where(Part.machine == self.machine, Part.part_number == part_number)
                 .order_by(Characteristic.id))
        if name is not None:
            query = query.where(Characteristic.name == name)
        return [{**_characteristic_dict(c), "part": _part_dict(p)} for c, p in self._session.execute(query)]

"""Workpiece probe records (_WP) and tool probe records (_TP): validated reads and writes.

Stored records may be sparse (the db seeds ``{"number": n}``); reads fill in the defaults so
every record has the same keys. A PUT replaces the record (keys not given get their default).
"""

from __future__ import annotations

from pydantic import BaseModel, ValidationError

from app import checks
from app.errors import InvalidInput, NotFoundError
from app.records import LATHE_RECORD_KEYS, MAX_PROBE, ProbeData, ToolProbeData
from db import Database

from .settings import raise_invalid


class _Records:
    model: type[BaseModel]
    what: str

    def __init__(self, db: Database):
        self._db = db

    def check_number(self, n) -> int:
        return checks.integer(n, "n", lo=1, hi=MAX_PROBE)

    def _complete(self, stored: dict) -> dict:
        defaults = self.model().model_dump(mode="json")
        out = {**defaults, **{k: v for k, v in stored.items() if k in defaults}}
        # the lathe's fields (position_deviation, workpiece_trigger) only where a lathe wrote them
        return {k: v for k, v in out.items() if not (k in LATHE_RECORD_KEYS and v is None)}

    def validate(self, n: int, data: dict) -> dict:
        n = self.check_number(n)
        if not isinstance(data, dict):
            raise InvalidInput(f"{self.what} data must be an object")
        if "number" in data and data["number"] != n:
            raise InvalidInput(f"number: body says {data['number']!r} but the path says {n}", field="number")
        try:
            return self.model.model_validate({**data, "number": n}).model_dump(mode="json")
        except ValidationError as error:
            raise_invalid(error)

    def _read(self, unit, n: int) -> dict | None:
        raise NotImplementedError

    def _write(self, unit, n: int, data: dict, source: str | None = None, detail: dict | None = None) -> dict:
        raise NotImplementedError

    def _all(self, unit) -> list[dict]:
        raise NotImplementedError

    def list(self) -> list[dict]:
        with self._db.unit(readonly=True) as unit:
            return [self._complete(r) for r in self._all(unit)]

    def get(self, n: int) -> dict:
        n = self.check_number(n)
        with self._db.unit(readonly=True) as unit:
            stored = self._read(unit, n)
        if stored is None:
            raise NotFoundError(f"no {self.what} record {n}", code=f"unknown_{self.what.replace(' ', '_')}")
        return self._complete(stored)

    def put(self, n: int, data: dict, source: str = "api") -> dict:
        """Audited (kind "probe" item "WP<n>", or "tool_probe" "TP<n>")."""
        record = self.validate(n, data)
        with self._db.unit() as unit:
            return self._complete(self._write(unit, n, record, source))

    def restore(self, entry: dict, force: bool = False) -> dict:
        """Undo of a record change (source "undo")."""
        from app.errors import ConflictError

        from .offsets import same_values

        name = entry["offset"]
        n = int(name[2:])
        with self._db.unit() as unit:
            current = self._read(unit, n)
            if not force and not same_values(current, entry["after"]):
                raise ConflictError(f"{name} changed after change #{entry['id']}; send {{\"force\": true}} to "
                                    "restore anyway", code="changed_since")
            stored = self._write(unit, n, entry["before"] or {"number": n}, "undo", {"undo_of": entry["id"]})
            new_id = unit.audit(1, name)[0]["id"]
        return {"undone": entry["id"], "audit_id": new_id, "kind": entry["kind"], "offset": name,
                "value": self._complete(stored)}


class ProbeService(_Records):
    model = ProbeData
    what = "probe"

    def _read(self, unit, n):
        return unit.get_probe(n)

    def _write(self, unit, n, data, source=None, detail=None):
        return unit.put_probe(n, data, source=source, detail=detail)

    def _all(self, unit):
        return unit.list_probes()


class ToolProbeService(_Records):
    model = ToolProbeData
    what = "tool probe"

    def _read(self, unit, n):
        return unit.get_tool_probe(n)

    def _write(self, unit, n, data, source=None, detail=None):
        return unit.put_tool_probe(n, data, source=source, detail=detail)

    def _all(self, unit):
        return unit.list_tool_probes()

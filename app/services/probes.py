"""Workpiece probe records (_WP) and tool probe records (_TP): validated reads and writes.

Stored records may be sparse (the db seeds ``{"number": n}``); reads fill in the defaults so
every record has the same keys. A PUT replaces the record (keys not given get their default).
"""

from __future__ import annotations

from datetime import UTC, datetime

from pydantic import BaseModel, ValidationError

from app import checks
from app.errors import ConflictError, InvalidInput, NotFoundError
from app.records import LATHE_RECORD_KEYS, MAX_PROBE, ProbeData, ToolProbeData
from app.workflow import probe_trust
from db import Database

from .offsets import same_values
from .settings import SettingsService, raise_invalid


def invalidation(reason: str, text: str = "") -> dict:
    """The ``invalidated`` key of a probe record: why, when, what happened (design.md §10.4)."""
    return {"reason": reason, "at": datetime.now(UTC).isoformat(timespec="seconds"), "text": text}


class _Records:
    model: type[BaseModel]
    what: str
    probe: str                   # "workpiece" | "tool" (probe_events, validity)
    stylus_keys: tuple[str, ...]  # a change of these makes the calibration invalid (design.md §10.4)

    def __init__(self, db: Database, settings: SettingsService | None = None):
        self._db = db
        self._settings = settings

    def _max_age_h(self) -> float:
        return float(self._settings.get().calibration_max_age_h) if self._settings is not None else 0.0

    def check_number(self, n) -> int:
        return checks.integer(n, "n", lo=1, hi=MAX_PROBE)

    def _complete(self, stored: dict) -> dict:
        defaults = self.model().model_dump(mode="json")
        out = {**defaults, **{k: v for k, v in stored.items() if k in defaults}}
        out = probe_trust.with_validity(out, self._max_age_h(), self.probe)
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
            stored = self._read(unit, n) or {}
            record = self._keep_health(unit, n, stored, record)
            return self._complete(self._write(unit, n, record, source))

    def _keep_health(self, unit, n: int, stored: dict, record: dict) -> dict:
        """The HMI's own keys stay as stored (a GET-PUT round trip cannot forge a calibration);
        a change of the ball or stylus data makes a calibration invalid (design.md §10.4)."""
        record = {k: v for k, v in record.items() if k not in probe_trust.COMPUTED_KEYS}
        record.update({k: stored.get(k) for k in probe_trust.HEALTH_KEYS})
        changed = [k for k in self.stylus_keys if k in stored and stored.get(k) != record.get(k)]
        if changed and probe_trust.is_calibrated(stored, self.probe) and not stored.get("invalidated"):
            record["invalidated"] = invalidation("ball_changed", f"changed: {', '.join(changed)}")
            unit.add_probe_event(self.probe, n, "invalidated", record["invalidated"],
                                 calibration_id=stored.get("calibration_id"))
        return record

    def restore(self, entry: dict, force: bool = False) -> dict:
        """Undo of a record change (source "undo")."""

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
    probe = "workpiece"
    stylus_keys = ("ball_diameter", "skew", "length_to_tip")

    def _read(self, unit, n):
        return unit.get_probe(n)

    def _write(self, unit, n, data, source=None, detail=None):
        return unit.put_probe(n, data, source=source, detail=detail)

    def _all(self, unit):
        return unit.list_probes()


class ToolProbeService(_Records):
    model = ToolProbeData
    what = "tool probe"
    probe = "tool"
    stylus_keys = ("disc_diameter", "type", "axes")

    def _read(self, unit, n):
        return unit.get_tool_probe(n)

    def _write(self, unit, n, data, source=None, detail=None):
        return unit.put_tool_probe(n, data, source=source, detail=detail)

    def _all(self, unit):
        return unit.list_tool_probes()

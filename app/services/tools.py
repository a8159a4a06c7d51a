"""Tool table (geometry and wear). Each write goes to the NC's tool data once stored; a write to
the tool in the spindle also updates the NC's L1."""

from __future__ import annotations

from pydantic import ValidationError

from app import checks
from app.errors import ConflictError, InvalidInput, NotFoundError
from app.records import MAX_TOOL, ToolData, is_probe_tool
from app.workflow import probe_trust
from db import Database

from .machine_service import MachineService
from .offsets import same_values
from .probes import invalidation
from .settings import raise_invalid

TOOL_FIELDS = ("name", "type", "length", "radius", "wear.length", "wear.radius",
               "sl", "l1", "l2", "wear.l1", "wear.l2")          # the last five: lathe tools (turning.md §10.2)


class ToolService:
    def __init__(self, db: Database, machine: MachineService):
        self._db = db
        self._machine = machine

    @staticmethod
    def check_number(t) -> int:
        return checks.integer(t, "t", lo=1, hi=MAX_TOOL)

    def list(self) -> list[dict]:
        with self._db.unit(readonly=True) as unit:
            return unit.list_tools()

    def get(self, t: int) -> dict:
        t = self.check_number(t)
        with self._db.unit(readonly=True) as unit:
            data = unit.get_tool(t)
        if data is None:
            raise NotFoundError(f"T{t} is not in the tool table", code="unknown_tool")
        return data

    def validate(self, t: int, changes: dict, unit=None) -> dict:
        """Stored tool ``t`` (or a new one) with ``changes`` applied, checked; nothing is written.
        ``unit``: the writing unit to read the stored tool in (see ``put``)."""
        t = self.check_number(t)
        if not isinstance(changes, dict):
            raise InvalidInput("tool data must be an object")
        if "t" in changes and changes["t"] != t:
            raise InvalidInput(f"t: body says {changes['t']!r} but the path says {t}", field="t")
        if unit is None:
            with self._db.unit(readonly=True) as reader:
                current = reader.get_tool(t) or {"t": t}
        else:
            current = unit.get_tool(t) or {"t": t}
        merged = {**current, **changes, "t": t}
        if isinstance(changes.get("wear"), dict):
            merged["wear"] = {**current.get("wear", {}), **changes["wear"]}
        try:
            return ToolData.model_validate(merged).model_dump()
        except ValidationError as error:
            raise_invalid(error)

    def put(self, t: int, changes: dict, source: str = "api") -> dict:
        """Audited (kind "tool", item "T<t>", ``source``)."""
        # read, merge and write in one writing unit: a concurrent change of another field (this or
        # another HMI process) is not overwritten by the value read before it (design.md §10.5)
        with self._db.unit() as unit:
            before = unit.get_tool(int(t)) if isinstance(t, int) else None
            data = self.validate(t, changes, unit)
            stored = unit.put_tool(data["t"], data, source=source)
            _probe_data_changed(unit, before, stored)
        self._stored(stored)
        return stored

    def _stored(self, stored: dict) -> None:
        self._machine.write_tool(stored["t"], stored)    # the NC holds what was stored
        if self._machine.machine.status().tool == stored["t"]:
            self._machine.refresh_tool_offset()

    def restore(self, entry: dict, force: bool = False) -> dict:
        """Undo of a tool change (source "undo"); a creation is undone by deleting the tool."""
        t = int(entry["offset"].removeprefix("T"))
        before = entry["before"]
        if before is None and self._machine.machine.status().tool == t:
            raise ConflictError(f"T{t} is in the spindle; change the tool first", code="tool_in_spindle")
        with self._db.unit() as unit:
            current = unit.get_tool(t)
            if not force and not same_values(current, entry["after"]):
                raise ConflictError(f"T{t} changed after change #{entry['id']}; send {{\"force\": true}} to "
                                    "restore anyway", code="changed_since")
            if before is None:
                if current is not None:
                    unit.delete_tool(t, source="undo")
                stored = None
            else:
                stored = unit.put_tool(t, {k: v for k, v in before.items() if k != "t"}, source="undo",
                                       detail={"undo_of": entry["id"]})
            new_id = unit.audit(1, f"T{t}")[0]["id"]
        if stored is not None:
            self._stored(stored)
        return {"undone": entry["id"], "audit_id": new_id, "kind": "tool", "offset": f"T{t}", "value": stored}

    def put_field(self, t: int, field: str, text: str, source: str = "screen") -> dict:
        """One table cell from the screen (``length``, ``wear.radius``, ``type``, ``name``)."""
        if field not in TOOL_FIELDS:
            raise InvalidInput(f"{field}: unknown field", field=field)
        value: str | float | None
        if field == "name":
            value = text.strip() or None
        else:
            number = checks.parse_number(text, field)
            value = int(number) if field in ("type", "sl") and number.is_integer() else number
        part, _, sub = field.partition(".")
        return self.put(t, {part: {sub: value}} if sub else {part: value}, source=source)

    def delete(self, t: int) -> None:
        t = self.check_number(t)
        if self._machine.machine.status().tool == t:
            raise ConflictError(f"T{t} is in the spindle; change the tool first", code="tool_in_spindle")
        with self._db.unit() as unit:
            try:
                unit.delete_tool(t, source="api")
            except KeyError:
                raise NotFoundError(f"T{t} is not in the tool table", code="unknown_tool") from None


def _probe_data_changed(unit, before: dict | None, after: dict) -> None:
    """The probe's ball (radius) or stylus length changed in the tool table: the calibrations of
    the probe records bound to this tool are invalid (design.md §10.4)."""
    if before is None or not is_probe_tool(after):
        return
    changed = [k for k in ("radius", "length") if before.get(k) != after.get(k)]
    if not changed:
        return
    for record in unit.list_probes():
        if record.get("tool") != after["t"] or not probe_trust.is_calibrated(record) or record.get("invalidated"):
            continue
        mark = invalidation("ball_changed", f"T{after['t']} {', '.join(changed)} changed in the tool table")
        unit.add_probe_event("workpiece", record["number"], "invalidated", mark,
                             calibration_id=record.get("calibration_id"))
        unit.put_probe(record["number"], {**record, "invalidated": mark}, source="probe_health",
                       detail={"reason": "ball_changed"})

"""Tool table (geometry and wear). A write to the tool in the spindle updates the NC's L1."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from app.errors import ConflictError, InvalidInput, NotFoundError
from db import Database

from .machine_service import MachineService
from .settings import raise_invalid

MAX_TOOL = 9999


class Wear(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
    length: float = Field(0.0, ge=-100, le=100)
    radius: float = Field(0.0, ge=-100, le=100)


class ToolData(BaseModel):
    """``{"t", "name", "type", "length", "radius", "wear": {"length", "radius"}}`` (design.md §4)."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
    t: int = Field(ge=1, le=MAX_TOOL)
    name: str | None = Field(None, max_length=40)
    type: int = Field(120, ge=100, le=999)          # 1xx mills, 2xx drills, 710 3D probe
    length: float = Field(0.0, ge=0, le=2000)
    radius: float = Field(0.0, ge=0, le=500)
    wear: Wear = Field(default_factory=Wear)


TOOL_FIELDS = ("name", "type", "length", "radius", "wear.length", "wear.radius")


class ToolService:
    def __init__(self, db: Database, machine: MachineService):
        self._db = db
        self._machine = machine

    @staticmethod
    def check_number(t) -> int:
        if isinstance(t, bool) or not isinstance(t, int) or not 1 <= t <= MAX_TOOL:
            raise InvalidInput(f"t: tool number must be 1..{MAX_TOOL}", field="t")
        return t

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

    def validate(self, t: int, changes: dict) -> dict:
        """Stored tool ``t`` (or a new one) with ``changes`` applied, checked; nothing is written."""
        t = self.check_number(t)
        if not isinstance(changes, dict):
            raise InvalidInput("tool data must be an object")
        if "t" in changes and changes["t"] != t:
            raise InvalidInput(f"t: body says {changes['t']!r} but the path says {t}", field="t")
        with self._db.unit(readonly=True) as unit:
            current = unit.get_tool(t) or {"t": t}
        merged = {**current, **changes, "t": t}
        if isinstance(changes.get("wear"), dict):
            merged["wear"] = {**current.get("wear", {}), **changes["wear"]}
        try:
            return ToolData.model_validate(merged).model_dump()
        except ValidationError as error:
            raise_invalid(error)

    def put(self, t: int, changes: dict) -> dict:
        data = self.validate(t, changes)
        with self._db.unit() as unit:
            stored = unit.put_tool(data["t"], data)
        if self._machine.machine.status().tool == stored["t"]:
            self._machine.refresh_tool_offset()
        return stored

    def put_field(self, t: int, field: str, text: str) -> dict:
        """One table cell from the screen (``length``, ``wear.radius``, ``type``, ``name``)."""
        if field not in TOOL_FIELDS:
            raise InvalidInput(f"{field}: unknown field", field=field)
        if field == "name":
            value = text.strip() or None
        else:
            try:
                number = float(text.strip().replace(",", "."))
            except ValueError:
                raise InvalidInput(f"{field}: {text!r} is not a number", field=field) from None
            value = int(number) if field == "type" and number.is_integer() else number
        part, _, sub = field.partition(".")
        return self.put(t, {part: {sub: value}} if sub else {part: value})

    def delete(self, t: int) -> None:
        t = self.check_number(t)
        if self._machine.machine.status().tool == t:
            raise ConflictError(f"T{t} is in the spindle; change the tool first", code="tool_in_spindle")
        with self._db.unit() as unit:
            try:
                unit.delete_tool(t)
            except KeyError:
                raise NotFoundError(f"T{t} is not in the tool table", code="unknown_tool") from None

"""Workpiece probe records (_WP) and tool probe records (_TP): validated reads and writes.

Stored records may be sparse (the db seeds ``{"number": n}``); reads fill in the defaults so
every record has the same keys. A PUT replaces the record (keys not given get their default).
"""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from app.errors import InvalidInput, NotFoundError
from db import Database
from engine.types import TRIGGER_KEYS

from .settings import raise_invalid

MAX_PROBE = 99


def _check_trigger_keys(value: dict[str, float]) -> dict[str, float]:
    unknown = sorted(set(value) - set(TRIGGER_KEYS))
    if unknown:
        raise ValueError(f"unknown direction(s) {unknown}; use {list(TRIGGER_KEYS)}")
    return value


class ProbeData(BaseModel):
    """_WP[k]: mirrors ``engine.types.ProbeRecord`` (trigger = ball centre minus surface per direction)."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
    number: int = Field(1, ge=1, le=MAX_PROBE)
    ball_diameter: float = Field(4.0, gt=0, le=100)
    effective_diameter: float = Field(0.0, ge=0, le=100)     # 0 = not calibrated
    trigger: dict[str, float] = Field(default_factory=dict)
    skew: tuple[float, float] = (0.0, 0.0)
    length_to_tip: bool = False
    calibrated_radius: bool = False
    calibrated_length: bool = False
    calibrated_plane: Literal["G17", "G18", "G19"] | None = None
    calibration_feed: float | None = Field(None, gt=0)
    calibration_override: float | None = Field(None, ge=0, le=120)
    calibrated_at: str | None = None
    tool: int | None = Field(None, ge=1, le=9999)               # T of the probe this record belongs to
    cal_ring_diameter: float | None = Field(None, gt=0, le=1000)  # gauge of the radius calibration
    cal_height: float | None = Field(None, ge=-10000, le=10000)   # surface of the length calibration
    cal_wo: str | None = Field(None, max_length=12)              # WO the calibration was measured in

    @field_validator("trigger")
    @classmethod
    def _trigger_keys(cls, value: dict[str, float]) -> dict[str, float]:
        return _check_trigger_keys(value)


class ToolProbeData(BaseModel):
    """_TP[k]: trigger values in MCS of the tool edge at switching (spec §7.2)."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
    number: int = Field(1, ge=1, le=MAX_PROBE)
    trigger: dict[str, float] = Field(default_factory=dict)
    disc_diameter: float = Field(0.0, ge=0, le=500)
    axes: int = Field(133, ge=0, le=333)
    type: Literal[0, 101, 201, 301] = 0
    dz: float = Field(2.0, ge=0, le=100)
    calibrated_length: bool = False
    calibrated_diameter: bool = False
    calibration_tool: int | None = Field(None, ge=1)
    calibration_feed: float | None = Field(None, gt=0)
    calibration_override: float | None = Field(None, ge=0, le=120)   # feed override when calibrated
    calibrated_at: str | None = None

    @field_validator("trigger")
    @classmethod
    def _trigger_keys(cls, value: dict[str, float]) -> dict[str, float]:
        return _check_trigger_keys(value)


class _Records:
    model: type[BaseModel]
    what: str

    def __init__(self, db: Database):
        self._db = db

    def check_number(self, n) -> int:
        if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= MAX_PROBE:
            raise InvalidInput(f"n: {self.what} number must be 1..{MAX_PROBE}", field="n")
        return n

    def _complete(self, stored: dict) -> dict:
        defaults = self.model().model_dump(mode="json")
        return {**defaults, **{k: v for k, v in stored.items() if k in defaults}}

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

    def _write(self, unit, n: int, data: dict) -> dict:
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

    def put(self, n: int, data: dict) -> dict:
        record = self.validate(n, data)
        with self._db.unit() as unit:
            return self._complete(self._write(unit, n, record))


class ProbeService(_Records):
    model = ProbeData
    what = "probe"

    def _read(self, unit, n):
        return unit.get_probe(n)

    def _write(self, unit, n, data):
        return unit.put_probe(n, data)

    def _all(self, unit):
        return unit.list_probes()


class ToolProbeService(_Records):
    model = ToolProbeData
    what = "tool probe"

    def _read(self, unit, n):
        return unit.get_tool_probe(n)

    def _write(self, unit, n, data):
        return unit.put_tool_probe(n, data)

    def _all(self, unit):
        return unit.list_tool_probes()

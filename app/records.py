"""The data records the NC holds and the workflow writes: tools, workpiece and tool probe records.

Validation models shared by the services (API/screen writes) and the measuring workflow
(calibration and tool measuring results), so that both check a record the same way.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    SerializerFunctionWrapHandler,
    StrictBool,
    StrictFloat,
    StrictInt,
    ValidationInfo,
    field_validator,
    model_serializer,
)

from app import checks
from app.errors import InvalidInput
from engine.lobing import lobing_map_from_json
from engine.types import TRIGGER_KEYS

MAX_TOOL = 9999
MAX_TRANSLATION = 100_000.0   # mm (deg for rotary axes): a zero offset component beyond is a typo
PROBE_TOOL_TYPE = 710       # 3D probe, multidirectional (spec/jog-measuring.md §10: 710/1xy)


def frame_out_of_range(frame: Mapping) -> tuple[str, str] | None:
    """(field, message) of the first frame component that is not finite or beyond the offset
    limits (translation ±MAX_TRANSLATION, rotation (−360, 360) deg), else None."""
    for part in ("trans", "fine", "rot"):
        for axis, value in (frame.get(part) or {}).items():
            field = f"{part}.{axis}"
            try:
                number = checks.number(value, field)
            except InvalidInput as exc:
                return field, exc.message
            if part == "rot" and not abs(number) < 360.0:
                return field, f"{field}: rotation must lie in (-360, 360) degrees"
            if abs(number) > MAX_TRANSLATION:
                return field, f"{field}: at most {MAX_TRANSLATION:g} in magnitude"
    return None


def is_probe_tool(tool: Mapping | None) -> bool:
    """A tool table row of the workpiece probe (type 710)."""
    return tool is not None and bool(tool) and int(tool.get("type", 0) or 0) == PROBE_TOOL_TYPE


MAX_PROBE = 99
MAX_SKEW = 5.0       # mm: a stylus further off the spindle axis is bent or broken


def _check_trigger_keys(value: dict[str, float]) -> dict[str, float]:
    unknown = sorted(set(value) - set(TRIGGER_KEYS))
    if unknown:
        raise ValueError(f"unknown direction(s) {unknown}; use {list(TRIGGER_KEYS)}")
    return value


class ProbeHealthFields(BaseModel):
    """The health fields a workpiece probe record (_WP) and a tool probe record (_TP) share
    (design.md §10.4): kept by the HMI (a PUT keeps the stored ones, app.services.probes);
    ``valid``/``invalid_reason``/``calibration_age_h`` are worked out on each read and ignored
    when sent. A record dumps them last, after its own fields, as it always stored them."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
    calibration_id: StrictInt | None = None        # the calibration's probe_events row
    probe_identity: str | None = Field(None, max_length=40)    # the scenario probe that was calibrated
    invalidated: dict | None = None                # {"reason", "at", "text"}: what made it invalid
    repeatability: dict | None = None              # the last check {"n", "two_sigma", "range", "at", ...}
    valid: StrictBool | None = None
    invalid_reason: str | None = None
    calibration_age_h: float | None = None

    @model_serializer(mode="wrap")
    def _health_last(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        data = handler(self)
        health = [k for k in ProbeHealthFields.model_fields if k in data]
        return {**{k: v for k, v in data.items() if k not in ProbeHealthFields.model_fields},
                **{k: data[k] for k in health}}


class ProbeData(ProbeHealthFields):
    """_WP[k]: mirrors ``engine.types.ProbeRecord`` (trigger = ball centre minus surface per direction)."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
    number: StrictInt = Field(1, ge=1, le=MAX_PROBE)
    ball_diameter: StrictFloat = Field(4.0, gt=0, le=100)
    effective_diameter: StrictFloat = Field(0.0, ge=0, le=100)     # 0 = not calibrated
    trigger: dict[str, StrictFloat] = Field(default_factory=dict)
    skew: tuple[StrictFloat, StrictFloat] = (0.0, 0.0)
    length_to_tip: StrictBool = False
    calibrated_radius: StrictBool = False
    calibrated_length: StrictBool = False
    calibrated_plane: Literal["G17", "G18", "G19"] | None = None     # the last calibration's plane
    calibrated_planes: list[Literal["G17", "G18", "G19"]] = Field(default_factory=list)   # radius, per plane
    calibrated_spindle_angle: StrictFloat | None = Field(None, ge=0, lt=360)   # SPOS of the trigger values
    calibration_feed: StrictFloat | None = Field(None, gt=0, le=100_000)
    calibration_override: StrictFloat | None = Field(None, ge=0, le=120)
    calibrated_at: str | None = Field(None, max_length=40)
    tool: StrictInt | None = Field(None, ge=1, le=MAX_TOOL)     # T of the probe this record belongs to
    cal_ring_diameter: StrictFloat | None = Field(None, gt=0, le=1000)  # gauge of the radius calibration
    cal_height: StrictFloat | None = Field(None, ge=-10000, le=10000)   # surface of the length calibration
    cal_wo: str | None = Field(None, max_length=12)              # WO the calibration was measured in
    # the lathe's _WP[k,7]/[8] (turning.md §0.7): true ball centre minus the NC's, {"Z", "X"}
    position_deviation: dict[Literal["Z", "X"], StrictFloat] | None = None
    # the lathe's calibration status _WP[k,9]/[10] (turning.md §0.7): the directions a CYCLE973
    # calibration (groove or surface, JOG or NC) measured the trigger value of; None: never
    calibrated_directions: list[Literal["X-", "X+", "Z-", "Z+", "Y-", "Y+"]] | None = None
    # the direction-dependent trigger map of a ring calibration with more than 4 directions
    # (engine.lobing.LobingMap.values_json, design.md §9.8); None: the 4 trigger values only
    lobing: dict | None = None
    # what the ring calibration measured (issue [probe-health] item 5): the ball diameter from the
    # chord sagittas (None: the chords could not tell, the nominal was used) and whether the
    # pre-travel turns with the spindle ("probe") or stays with the machine axes ("machine")
    measured_ball_diameter: StrictFloat | None = Field(None, gt=0, le=100)
    pretravel_frame: Literal["probe", "machine"] | None = None

    # A probe's own physics bounds its data (measuring-math §5.1, measuring-math §5.2): the ball centre switches
    # within one ball diameter of the surface, the stylus is off the spindle axis by at most
    # MAX_SKEW, and pre-travel only makes the effective ball smaller than twice the real one.
    @field_validator("trigger")
    @classmethod
    def _trigger_physical(cls, value: dict[str, float], info: ValidationInfo) -> dict[str, float]:
        _check_trigger_keys(value)
        ball = info.data.get("ball_diameter")
        for key, t in value.items():
            if ball is not None and not abs(t) <= ball:
                raise ValueError(f"{key} = {t:g} mm is beyond the probe's physical range ±{ball:g} mm "
                                 "(the ball diameter)")
        return value

    @field_validator("lobing")
    @classmethod
    def _lobing_map(cls, value: dict | None) -> dict | None:
        if value is not None:
            lobing_map_from_json(value)                 # ValueError naming what is wrong
        return value

    @field_validator("effective_diameter")
    @classmethod
    def _effective_physical(cls, value: float, info: ValidationInfo) -> float:
        ball = info.data.get("ball_diameter")
        if ball is not None and value > 2.0 * ball:
            raise ValueError(f"{value:g} mm is more than twice the ball diameter {ball:g} mm")
        return value

    @field_validator("skew")
    @classmethod
    def _skew_physical(cls, value: tuple[float, float]) -> tuple[float, float]:
        for axis, s in zip("XY", value, strict=True):
            if not abs(s) <= MAX_SKEW:
                raise ValueError(f"{axis} = {s:g} mm is beyond ±{MAX_SKEW:g} mm (a bent or broken stylus)")
        return value


class ToolProbeData(ProbeHealthFields):
    """_TP[k]: trigger values in MCS of the tool edge at switching (jog-measuring §7.2)."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
    number: StrictInt = Field(1, ge=1, le=MAX_PROBE)
    trigger: dict[str, StrictFloat] = Field(default_factory=dict)
    disc_diameter: StrictFloat = Field(0.0, ge=0, le=500)
    axes: StrictInt = Field(133, ge=0, le=333)
    type: Literal[0, 101, 201, 301] = 0
    dz: StrictFloat = Field(2.0, ge=0, le=100)
    calibrated_length: StrictBool = False
    calibrated_diameter: StrictBool = False
    calibration_tool: StrictInt | None = Field(None, ge=1, le=MAX_TOOL)
    calibration_feed: StrictFloat | None = Field(None, gt=0, le=100_000)
    calibration_override: StrictFloat | None = Field(None, ge=0, le=120)   # feed override when calibrated
    calibrated_at: str | None = Field(None, max_length=40)
    # the lathe's _TPW[k] (workpiece-related trigger values, SW 6.3, turning.md §0.7), keyed as trigger
    workpiece_trigger: dict[str, StrictFloat] | None = None

    @field_validator("trigger")
    @classmethod
    def _trigger_in_travel(cls, value: dict[str, float]) -> dict[str, float]:
        """Tool edge positions at switching (MCS): within the machine's travel."""
        _check_trigger_keys(value)
        for key, t in value.items():
            if not abs(t) <= MAX_TRANSLATION:
                raise ValueError(f"{key} = {t:g} mm is beyond ±{MAX_TRANSLATION:g} mm")
        return value



# --- tools ---------------------------------------------------------------------------------

class Wear(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
    length: StrictFloat = Field(0.0, ge=-100, le=100)
    radius: StrictFloat = Field(0.0, ge=-100, le=100)
    l1: StrictFloat | None = Field(None, ge=-100, le=100)       # lathe tools (turning.md §10.2)
    l2: StrictFloat | None = Field(None, ge=-100, le=100)


class ToolData(BaseModel):
    """``{"t", "name", "type", "length", "radius", "wear": {"length", "radius"}}`` (design.md §4).

    Lathe tools and the lathe probe (types 5xy, turning.md §0.4, turning §10.2) add the cutting-edge
    position ``sl`` and the lengths ``l1`` (X), ``l2`` (Z) with ``wear.l1``/``wear.l2``, radius
    values; absent (None) on milling tools, whose data read exactly as before."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
    t: StrictInt = Field(ge=1, le=MAX_TOOL)
    name: str | None = Field(None, max_length=40)
    type: StrictInt = Field(120, ge=100, le=999)          # 1xx mills, 2xx drills, 710 3D probe, 5xy lathe
    length: StrictFloat = Field(0.0, ge=0, le=2000)
    radius: StrictFloat = Field(0.0, ge=0, le=500)
    wear: Wear = Field(default_factory=Wear)
    sl: StrictInt | None = Field(None, ge=0, le=9)
    l1: StrictFloat | None = Field(None, ge=-2000, le=2000)
    l2: StrictFloat | None = Field(None, ge=-2000, le=2000)

    @property
    def is_lathe_tool(self) -> bool:
        return self.sl is not None or self.l1 is not None or self.l2 is not None


LATHE_RECORD_KEYS = ("position_deviation", "workpiece_trigger", "calibrated_directions")   # probe / tool probe records of a lathe
LATHE_PROBE_TYPE = 580      # the lathe's workpiece probe: a 5xy tool with SL 5..8 (turning.md §0.6)


"""The simulator's truth: the scenario JSON of design.md §4 as pydantic v2 models.

Only the simulator sees these values; the HMI learns them by measuring. Units: mm, deg,
mm/min, s. Every field has a default except the ones that define a feature's size.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Annotated, Literal, TypeVar

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from .lathe_scenario import LatheScenario
from .machine_data import check_machine_data
from .polygon import check_simple_polygon, polygon_area
from .probe_signal import Radio

DEMO_SCENARIO_PATH = Path(__file__).with_name("demo_scenario.json")
LATHE_DEMO_SCENARIO_PATH = Path(__file__).with_name("lathe_demo_scenario.json")

GEOMETRY_AXES = ("X", "Y", "Z")
ROTARY_AXIS_NAMES = ("A", "B", "C")
PRETRAVEL_KEYS = ("X+", "X-", "Y+", "Y-", "Z+", "Z-")
SPINDLE_AXES = ("Z", "Y", "X")
DEFAULT_LIMITS = {"X": (-2000.0, 2000.0), "Y": (-2000.0, 2000.0), "Z": (-1000.0, 1000.0)}   # generous

Finite = Annotated[float, Field(allow_inf_nan=False)]
Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0, allow_inf_nan=False)]
Vec2 = tuple[Finite, Finite]
Vec3 = tuple[Finite, Finite, Finite]


class _Model(BaseModel):
    # unknown keys are typos in a truth file: refuse them so the message names the field
    model_config = ConfigDict(extra="forbid")


def _check_range(value: tuple[float, float], name: str) -> tuple[float, float]:
    if value[0] >= value[1]:
        raise ValueError(f"{name}: lower limit {value[0]} must be below upper limit {value[1]}")
    return value


class AxisLine(_Model):
    """A rotary axis as a line in the machine frame at the zero position of every rotary axis
    (design.md §10.6): ``point`` on it (mm; relative to the tool reference point for head axes,
    MCS for a table) and its ``direction`` (any length > 0, normalised here). The axis turns
    right-handed about ``direction`` (a table: the part by −angle, DIN 66217)."""

    point: Vec3 = (0.0, 0.0, 0.0)
    direction: Vec3 = (0.0, 0.0, 1.0)

    @field_validator("direction")
    @classmethod
    def _unit(cls, value: tuple[float, float, float]) -> tuple[float, float, float]:
        norm = math.sqrt(sum(v * v for v in value))
        if not norm > 1e-9:
            raise ValueError("direction: must not be the zero vector")
        return (value[0] / norm, value[1] / norm, value[2] / norm)


AxisLines = dict[str, AxisLine]        # keys: the unit's axes (checked by _check_lines)
AXIS_UNITS = {"A": (1.0, 0.0, 0.0), "B": (0.0, 1.0, 0.0), "C": (0.0, 0.0, 1.0)}


def _check_lines(lines: dict, axes: tuple[str, ...], field: str) -> None:
    for name in lines:
        if name not in axes:
            raise ValueError(f"{field}: {name!r} is not one of this unit's axes {list(axes)}")


class RotaryTable(_Model):
    """A rotary table: the workpiece turns with ``axis`` about a vertical line through ``center``.

    ``workpiece.pose`` is the part at axis position 0. DIN 66217: the table turning + turns the
    part clockwise seen from above (the tool's motion relative to the part is right-handed).
    Kinematic data (design.md §10.6): ``nominal`` is what the control holds (default: the vertical
    line through ``center``), ``true`` the simulator's real axis line (default: the nominal).
    """

    axis: Literal["A", "B", "C"] = "C"
    center: Vec2 = (0.0, 0.0)
    nominal: AxisLines | None = None
    true: AxisLines | None = None

    @model_validator(mode="after")
    def _lines(self) -> RotaryTable:
        for field, lines in (("rotary_table.nominal", self.nominal), ("rotary_table.true", self.true)):
            _check_lines(lines or {}, (self.axis,), field)
        return self

    def nominal_lines(self) -> dict[str, AxisLine]:
        ideal = AxisLine(point=(self.center[0], self.center[1], 0.0), direction=(0.0, 0.0, 1.0))
        given = dict(self.nominal or {})
        return {self.axis: given.get(self.axis, ideal)}

    def true_lines(self) -> dict[str, AxisLine]:
        return {**self.nominal_lines(), **(self.true or {})}


class SwivelHead(_Model):
    """A swivel head (CYCLE800-like re-alignment, jog-measuring §6.2): two rotary axes turn the tool.

    Model (one, kept simple): the head pivots about the tool reference point (spindle nose,
    the MCS X/Y/Z axis position). ``axes`` names the two head axes in alphabetical order
    (first, second) = ("A", "B"), ("A", "C") or ("B", "C"); the second is the outer axis:
    R_head = R_second(θ_second)·R_first(θ_first), e.g. A/B: Ry(B)·Rx(A) (the RPY order of
    design.md §3), B/C fork head: Rz(C)·Ry(B). Both angles 0 = tool axis +Z (3-axis machine).

    - tool axis in MCS = R_head·ẑ
    - true ball centre = A + R_head·(e(φ) − L·ẑ)  (eccentricity and length turn with the head)
    - pre-travel is a property of the probe: p(R_headᵀ·d) in the probe's own axes
    - limits: the head axes' ``rotary_axes`` limits; a swivel is checked at samples of the
      path (end pose included): the ball (or a cutter's end) must stay out of every solid.
    """

    type: Literal["swivel_head"] = "swivel_head"
    axes: tuple[Literal["A", "B", "C"], Literal["A", "B", "C"]] = ("A", "B")
    # kinematic data (design.md §10.6): the axis lines at the zero position, relative to the tool
    # reference point; ``nominal`` the control's (default: through the reference point along X/Y/Z
    # of the axis name, the model above), ``true`` the simulator's real ones (default: the nominal)
    nominal: AxisLines | None = None
    true: AxisLines | None = None

    @model_validator(mode="after")
    def _lines(self) -> SwivelHead:
        for field, lines in (("kinematics.nominal", self.nominal), ("kinematics.true", self.true)):
            _check_lines(lines or {}, tuple(self.axes), field)
        return self

    def nominal_lines(self) -> dict[str, AxisLine]:
        given = dict(self.nominal or {})
        return {a: given.get(a, AxisLine(direction=AXIS_UNITS[a])) for a in self.axes}

    def true_lines(self) -> dict[str, AxisLine]:
        return {**self.nominal_lines(), **(self.true or {})}

    @field_validator("axes")
    @classmethod
    def _pair(cls, value: tuple[str, str]) -> tuple[str, str]:
        if value[0] == value[1]:
            raise ValueError("kinematics.axes: two different rotary axes")
        first, second = sorted(value)
        return first, second


class MachineConfig(_Model):
    """Axis limits (MCS of the tool reference point), feeds and the braking model (turning §1.3)."""

    kind: Literal["mill"] = Field("mill", exclude=True)   # "lathe": app.machine.lathe_scenario
    limits: dict[str, Vec2] = Field(default_factory=lambda: dict(DEFAULT_LIMITS))   # axes not given: default
    rapid: Positive = 10000.0          # mm/min
    jog_feed: Positive = 1000.0        # mm/min, jog when no feed is given
    latency_s: NonNegative = 0.004     # signal delay t of measuring-math §1.3, s
    decel: Positive = 1.0              # braking deceleration a, m/s^2
    kv: Positive = 1.0                 # position loop gain Kv, (m/min)/mm
    time_scale: NonNegative = 1.0      # 1 = real time, 0 = no waiting
    rotary_table: RotaryTable | None = None   # the part turns with this rotary axis (vertical table)
    kinematics: SwivelHead | None = None      # swivel head (None: 3-axis tool axis +Z, no re-alignment)
    # the spindle's axis (design.md §9.8): the tool points along −spindle_axis from the spindle
    # nose (tip = A − L·axis); "Y"/"X" = a horizontal spindle (physics.SPINDLE_MOUNTS)
    spindle_axis: Literal["Z", "Y", "X"] = "Z"
    # the control's machine data as commissioned (app.machine.machine_data, manual ch. 9): MD number
    # -> value; the ones not given have the values the measuring cycles need
    machine_data: dict[str, float | list[float]] = Field(default_factory=dict)

    @field_validator("machine_data")
    @classmethod
    def _machine_data_ok(cls, value: dict) -> dict:
        return check_machine_data(value)

    @model_validator(mode="after")
    def _spindle_and_head(self) -> MachineConfig:
        if self.kinematics is not None and self.spindle_axis != "Z":
            raise ValueError(f"machine.spindle_axis: a swivel head (machine.kinematics) needs the vertical "
                             f"spindle \"Z\", got {self.spindle_axis!r}")
        return self

    @field_validator("limits")
    @classmethod
    def _limits_ok(cls, value: dict[str, tuple[float, float]]) -> dict[str, tuple[float, float]]:
        for axis, rng in value.items():
            if axis not in GEOMETRY_AXES:
                raise ValueError(f"unknown geometry axis {axis!r} (rotary limits go in rotary_axes)")
            _check_range(rng, f"limits.{axis}")
        return {**DEFAULT_LIMITS, **value}


class ProbeNominal(_Model):
    length: Positive | None = None
    ball_diameter: Positive | None = None


class LobeHarmonic(_Model):
    """One harmonic of a kinematic probe's lobing (design.md §9.8): the pre-travel grows by
    ``amplitude``·cos(order·(θ − phase)) for a travel at angle θ in the probe's own X/Y plane
    (a three-legged probe body: order 3)."""

    order: int = Field(ge=1, le=12)
    amplitude: float = Field(ge=-0.05, le=0.05)           # mm
    phase: float = Field(0.0, ge=-360.0, le=360.0)      # deg


class ProbeConfig(_Model):
    """The 3D workpiece probe (measuring-math §1.7): true values and what the HMI is told."""

    t: int = 9
    ball_diameter: Positive = 4.0
    length: Positive = 100.0                       # true L1: spindle nose to ball centre
    eccentricity: Vec2 = (0.0, 0.0)                # ball centre minus spindle axis at SPOS 0
    nominal: ProbeNominal = Field(default_factory=ProbeNominal)
    pretravel: dict[str, NonNegative] = Field(default_factory=dict)   # keys of PRETRAVEL_KEYS
    # where the pre-travel keys live (design.md §9.8): "probe" = the probe's own axes, turning with
    # SPOS like the eccentricity (and with a swivel head); "machine" = the machine axes (wave 1)
    pretravel_frame: Literal["probe", "machine"] = "probe"
    lobing: list[LobeHarmonic] = Field(default_factory=list, max_length=12)   # on top of ``pretravel``
    noise_sigma: NonNegative = 0.0
    max_deflection: Positive = 2.0
    radio: Radio | None = None                    # a radio/optical probe (design.md §10.4); None: cable

    @field_validator("pretravel")
    @classmethod
    def _pretravel_keys(cls, value: dict[str, float]) -> dict[str, float]:
        bad = sorted(set(value) - set(PRETRAVEL_KEYS))
        if bad:
            raise ValueError(f"unknown pre-travel direction(s) {bad}; use {list(PRETRAVEL_KEYS)}")
        return value

    @model_validator(mode="after")
    def _lobing_physical(self) -> ProbeConfig:
        if not self.lobing:
            return self
        if self.pretravel_frame != "probe":
            raise ValueError("lobing: the lobes belong to the probe body: needs pretravel_frame \"probe\"")
        smallest = min(self.pretravel.get(k, 0.0) for k in ("X+", "X-", "Y+", "Y-"))
        swing = sum(abs(h.amplitude) for h in self.lobing)
        if swing > smallest:
            raise ValueError(f"lobing: the amplitudes ({swing:g} mm together) exceed the smallest X/Y pre-travel "
                             f"({smallest:g} mm): a pre-travel cannot be negative")
        return self

    @property
    def nominal_length(self) -> float:
        return self.nominal.length if self.nominal.length is not None else self.length

    @property
    def nominal_ball_diameter(self) -> float:
        nominal = self.nominal.ball_diameter
        return nominal if nominal is not None else self.ball_diameter


class Pose(_Model):
    """Part -> MCS: p_mcs = R(rot) p_part + trans, R = Rz(c) Ry(b) Rx(a) (design.md §3)."""

    trans: Vec3 = (0.0, 0.0, 0.0)
    rot: Vec3 = (0.0, 0.0, 0.0)


class Block(_Model):
    type: Literal["block"]
    size: tuple[Positive, Positive, Positive]     # fills [0,Lx] x [0,Ly] x [-Lz,0] in part coords


class Prism(_Model):
    """A vertical-walled part (design.md §9.8), in place of ``block``: the simple ``polygon``
    (part x/y, mm; counter-clockwise or clockwise, any shape, convex or not) extruded from the top
    face z = 0 down to z = −height. Holes, pockets, spigots and bosses go into/onto it as on a block."""

    type: Literal["prism"]
    polygon: list[Vec2]
    height: Positive

    @field_validator("polygon")
    @classmethod
    def _simple(cls, value: list[tuple[float, float]]) -> list[tuple[float, float]]:
        check_simple_polygon(value, "polygon")
        return value

    @property
    def ccw_polygon(self) -> list[tuple[float, float]]:
        """The polygon counter-clockwise seen from the part's +z (the normalised orientation)."""
        pts = [(x, y) for x, y in self.polygon]
        return pts if polygon_area(pts) > 0.0 else pts[::-1]


class Sphere(_Model):
    """A ball of ``diameter`` with its centre at ``center`` (part coordinates): on or over the
    part (a union with it), or alone on the table when the workpiece has no block/prism. Its
    stem or holder is not modelled; holes and pockets do not cut it."""

    type: Literal["sphere"]
    center: Vec3
    diameter: Positive


class MachinedBy(_Model):
    """The cutter that makes a feature in a machined-part series (design.md §9.3)."""

    t: int = Field(ge=1, le=9999)


class Hole(_Model):
    type: Literal["hole"]
    center: Vec2
    diameter: Positive
    depth: Positive
    machined_by: MachinedBy | None = None


class Pocket(_Model):
    type: Literal["pocket"]
    center: Vec2
    size: tuple[Positive, Positive]
    depth: Positive
    machined_by: MachinedBy | None = None


class Spigot(_Model):
    type: Literal["spigot"]
    center: Vec2
    diameter: Positive
    height: Positive
    machined_by: MachinedBy | None = None


class Boss(_Model):
    type: Literal["boss"]
    center: Vec2
    size: tuple[Positive, Positive]
    height: Positive
    machined_by: MachinedBy | None = None


Feature = Annotated[Block | Prism | Hole | Pocket | Spigot | Boss | Sphere, Field(discriminator="type")]
BASE_TYPES = ("block", "prism")          # the part's body; the other features go into/onto it


class Workpiece(_Model):
    pose: Pose = Field(default_factory=Pose)
    features: list[Feature] = Field(default_factory=list)

    @model_validator(mode="after")
    def _one_block(self) -> Workpiece:
        bases = [f for f in self.features if f.type in BASE_TYPES]
        if len(bases) > 1:
            raise ValueError("features: at most one block or prism per workpiece")
        if not bases and any(f.type in ("hole", "pocket", "spigot", "boss") for f in self.features):
            raise ValueError("features: holes, pockets, spigots and bosses need a block or prism to sit in/on")
        return self

    @property
    def block(self) -> Block | None:
        return next((f for f in self.features if f.type == "block"), None)

    @property
    def base(self) -> Block | Prism | None:
        """The part's body: its block or prism (None: spheres alone, or no part)."""
        return next((f for f in self.features if isinstance(f, (Block, Prism))), None)   # BASE_TYPES

    @property
    def spheres(self) -> list[Sphere]:
        return [f for f in self.features if f.type == "sphere"]


class RingGauge(_Model):
    """Calibration ring: ``center`` = centre of its top face (MCS)."""

    center: Vec3
    diameter: Positive                       # bore
    height: Positive = 20.0
    outer_diameter: Positive | None = None   # default bore + 30

    @model_validator(mode="after")
    def _outer(self) -> RingGauge:
        if self.outer_diameter is None:
            self.outer_diameter = self.diameter + 30.0
        if self.outer_diameter <= self.diameter:
            raise ValueError("ring_gauge.outer_diameter must be larger than the bore diameter")
        return self


class ToolProbe(_Model):
    """Tool probe: a switching cylinder standing on the table, ``center`` = top-face centre."""

    center: Vec3
    disc_diameter: Positive
    height: Positive = 40.0
    pretravel: NonNegative = 0.0
    radio: Radio | None = None                    # a radio tool probe (design.md §10.4); None: cable


class ToolNominal(_Model):
    length: Positive | None = None
    radius: Positive | None = None


class WearPerPart(_Model):
    """How much the cutter loses per machined part (design.md §9.3): its true radius and length
    get smaller by these amounts after each part."""

    radius: float = Field(0.0, ge=0.0, le=1.0)
    length: float = Field(0.0, ge=0.0, le=1.0)


class Tool(_Model):
    """A true cutter: flat-end cylinder of ``radius``, tip ``length`` below the spindle nose."""

    t: int
    type: int = 120
    length: Positive
    radius: Positive
    nominal: ToolNominal = Field(default_factory=ToolNominal)
    wear_per_part: WearPerPart = Field(default_factory=WearPerPart)

    @property
    def nominal_length(self) -> float:
        return self.nominal.length if self.nominal.length is not None else self.length

    @property
    def nominal_radius(self) -> float:
        return self.nominal.radius if self.nominal.radius is not None else self.radius


class RotaryAxis(_Model):
    limits: Vec2 = (-360.0, 360.0)

    @field_validator("limits")
    @classmethod
    def _range(cls, value: tuple[float, float]) -> tuple[float, float]:
        return _check_range(value, "limits")


class Scenario(_Model):
    seed: int = Field(0, ge=0, le=2**63 - 1)          # numpy's generators take no negative seed
    machine: MachineConfig = Field(default_factory=MachineConfig)
    probe: ProbeConfig = Field(default_factory=ProbeConfig)
    workpiece: Workpiece | None = None
    ring_gauge: RingGauge | None = None
    tool_probe: ToolProbe | None = None
    tools: list[Tool] = Field(default_factory=list)
    rotary_axes: dict[str, RotaryAxis] = Field(default_factory=dict)
    start: dict[str, Finite] | None = None   # axes MCS at load; default: X/Y at 0 (clamped), Z at top

    @model_validator(mode="after")
    def _consistent(self) -> Scenario:
        for name in self.rotary_axes:
            if name not in ROTARY_AXIS_NAMES:
                raise ValueError(f"rotary_axes: unknown axis {name!r}; use one of {list(ROTARY_AXIS_NAMES)}")
        table = self.machine.rotary_table
        if table is not None and table.axis not in self.rotary_axes:
            raise ValueError(f"machine.rotary_table.axis {table.axis!r} must be one of rotary_axes")
        head = self.machine.kinematics
        if head is not None:
            for head_axis in head.axes:
                if head_axis not in self.rotary_axes:
                    raise ValueError(f"machine.kinematics.axes: {head_axis!r} must be one of rotary_axes")
                if table is not None and table.axis == head_axis:
                    raise ValueError(f"machine.kinematics.axes: {head_axis!r} is the rotary table's axis")
        numbers = [tool.t for tool in self.tools]
        if len(set(numbers)) != len(numbers):
            raise ValueError("tools: tool numbers must be unique")
        if self.probe.t in numbers:
            raise ValueError(f"tools: T{self.probe.t} is the probe's number (probe.t)")
        if self.start is not None:
            for axis, value in self.start.items():
                if axis in GEOMETRY_AXES:
                    lo, hi = self.machine.limits[axis]
                elif axis in self.rotary_axes:
                    lo, hi = self.rotary_axes[axis].limits
                else:
                    raise ValueError(f"start: unknown axis {axis!r}")
                if not lo <= value <= hi:
                    raise ValueError(f"start.{axis} = {value} is outside the limits [{lo}, {hi}]")
        return self

    @property
    def kind(self) -> str:
        """The machine the scenario describes: "mill" (this model) or "lathe" (lathe_scenario)."""
        return "mill"

    @property
    def axes(self) -> tuple[str, ...]:
        return GEOMETRY_AXES + tuple(a for a in ROTARY_AXIS_NAMES if a in self.rotary_axes)

    def limits(self) -> dict[str, tuple[float, float]]:
        out = {a: self.machine.limits[a] for a in GEOMETRY_AXES}       # (lo, hi) tuples: no copies needed
        out.update({a: ax.limits for a, ax in self.rotary_axes.items()})
        return out

    def start_position(self) -> dict[str, float]:
        """Axes at load: ``start`` where given, else Z and the spindle axis at their top (the tool
        retracted), the others at 0 clamped into the limits."""
        position = {}
        retracted = {"Z", self.machine.spindle_axis}
        for axis, (lo, hi) in self.limits().items():
            default = hi if axis in retracted else min(max(0.0, lo), hi)
            position[axis] = float((self.start or {}).get(axis, default))
        return position

    def tool(self, t: int) -> Tool | None:
        return next((tool for tool in self.tools if tool.t == t), None)


def _describe(error: ValidationError) -> str:
    parts = []
    for item in error.errors():
        loc = ".".join(str(p) for p in item["loc"]) or "scenario"
        parts.append(f"{loc}: {item['msg']}")
    return "invalid scenario: " + "; ".join(parts)


def load_scenario(data: dict) -> Scenario | LatheScenario:
    """Validate a scenario dict; bad input raises ValueError naming the field(s).

    ``machine.kind`` picks the model: "lathe" the simulated lathe's (lathe_scenario, turning.md
    turning §10.2), else the milling machine's (unknown keys refused by each, the lathe's fields too)."""
    if not isinstance(data, dict):
        raise ValueError(f"invalid scenario: expected a JSON object, got {type(data).__name__}")
    machine = data.get("machine")
    if isinstance(machine, dict) and machine.get("kind") == "lathe":
        return _validated(LatheScenario, data)
    return _validated(Scenario, data)


_ScenarioT = TypeVar("_ScenarioT", Scenario, LatheScenario)


def _validated(model: type[_ScenarioT], data: dict) -> _ScenarioT:
    try:
        return model.model_validate(data)
    except ValidationError as exc:
        raise ValueError(_describe(exc)) from None


def demo_scenario() -> Scenario:
    """The built-in demo: a rotated block with hole, pocket, spigot and boss, gauges, two cutters."""
    return _validated(Scenario, json.loads(DEMO_SCENARIO_PATH.read_text(encoding="utf-8")))   # a milling one


def lathe_demo_scenario() -> LatheScenario:
    """The lathe demo (README): turning.md §10.2's example truth (1-B, 2-A, 4-A, 5-C) on one lathe."""
    return _validated(LatheScenario, json.loads(LATHE_DEMO_SCENARIO_PATH.read_text(encoding="utf-8")))

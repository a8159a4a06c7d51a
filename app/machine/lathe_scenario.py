"""The simulated lathe's truth: the scenario of turning.md §10.2 with ``machine.kind: "lathe"``.

Only the simulator sees these values; the HMI learns them by measuring. Units: mm, deg,
mm/min, s; X is always a **radius** here (the MCS X of the turret reference point F is its
distance from the spindle axis), whatever ``diameter_programming`` says (turning.md §0.3, turning §11).

Fields are turning.md §10.2's, names kept exactly; this module adds what turning §11 needs besides,
each optional with a default:

- ``machine``: ``kind`` "lathe", ``diameter_programming`` (DIAMON: display and WCS input of X
  as a diameter), ``spos`` (an SPOS-capable main spindle, 61372 otherwise), ``limits`` X/Z and
  an optional Y (a "Y" entry gives the lathe its Y axis), feeds and the braking model as on the
  milling machine (measuring-math §1.3); the latch latency ``latency_s`` defaults to 0 here, so
  that turning §10.2's example scenario reproduces the worked examples' latched values exactly (with a
  latency the latch lies v·t behind the switch, and calibration and measurement must use the
  same feed, as the manual requires).
- ``tools[]``: turning tools (type 5xy) with their true ``l1`` (X), ``l2`` (Z), nose ``radius``
  and cutting-edge position ``sl`` 1..9; ``nominal`` is what the HMI's tool table starts from
  (the truth where absent). ``wear_per_part`` (extension, as the milling series): the true L1/L2
  shrink by it per machined part.
- ``probe``: the workpiece probe in the turret (type 580, SL 5..8): true ``l1``/``l2`` to the
  ball centre, ``ball_diameter``, ``pretravel`` keyed by travel direction, ``noise_sigma``,
  ``max_deflection``; ``nominal`` {l1, l2, ball_diameter}.
- ``tool_probe``: the cube of the tool probe, ``faces`` keyed by the travel direction that
  touches them (X− top, X+ bottom, Z− right, Z+ left face, MCS radius/Z), ``pretravel``,
  ``max_deflection``; ``y_size`` (extension) its depth in Y; ``nominal`` (extension) the rough
  ``_TP`` values the HMI starts from, default the faces rounded to whole mm (1-B's 220/200/400/380).
- ``grooves[]``: the reference grooves' truth (``sl7`` / ``sl8`` ring bodies, turning.md §10.2);
  ``nominal`` (extension) the _KB record the HMI starts from, default the truth.
- ``workpiece``: ``chuck_face_z`` (MCS Z of the chuck face; the chuck is everything at Z below
  it), ``eccentricity`` (clamping eccentricity (x, y) at spindle 0°, turns with the spindle),
  ``face_runout_deg`` (axis tilt, turns likewise), ``profile`` of ``cylinder`` / ``bore`` items
  along z from the chuck face; an item's ``machined_by`` {t} (extension) makes it a cut surface
  of a part series (its true diameter follows the NC's tool data, turning.md §11 closed loop).
- ``spindle.angle``: the main spindle's position at load.
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from .probe_signal import Radio

PRETRAVEL_KEYS = ("X+", "X-", "Y+", "Y-", "Z+", "Z-")
FACE_KEYS = ("Z-", "Z+", "X-", "X+")          # the _TP order (turning.md §0.7)
DEFAULT_LIMITS = {"X": (-50.0, 600.0), "Z": (-50.0, 800.0)}

Finite = Annotated[float, Field(allow_inf_nan=False)]
Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0, allow_inf_nan=False)]
Vec2 = tuple[Finite, Finite]


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid")      # a typo in a truth file names its field


class LatheMachineConfig(_Model):
    kind: Literal["lathe"]
    diameter_programming: bool = True
    spos: bool = True
    limits: dict[str, Vec2] = Field(default_factory=lambda: dict(DEFAULT_LIMITS))
    rapid: Positive = 10000.0
    jog_feed: Positive = 1000.0
    latency_s: NonNegative = 0.0         # 0: turning §10.2's example reproduces 1-B/2-A/4-A/5-C exactly
    decel: Positive = 1.0
    kv: Positive = 1.0
    time_scale: NonNegative = 1.0

    @field_validator("limits")
    @classmethod
    def _limits(cls, value: dict[str, tuple[float, float]]) -> dict[str, tuple[float, float]]:
        for axis, (lo, hi) in value.items():
            if axis not in ("X", "Y", "Z"):
                raise ValueError(f"unknown axis {axis!r}: a lathe has X, Z and optionally Y")
            if lo >= hi:
                raise ValueError(f"limits.{axis}: lower limit {lo} must be below upper limit {hi}")
        return {**DEFAULT_LIMITS, **value}

    @property
    def has_y(self) -> bool:
        return "Y" in self.limits


class Spindle(_Model):
    angle: Finite = 0.0


class ToolNominal(_Model):
    l1: Finite | None = None
    l2: Finite | None = None
    radius: NonNegative | None = None


class LengthWear(_Model):
    l1: float = Field(0.0, ge=0.0, le=1.0)
    l2: float = Field(0.0, ge=0.0, le=1.0)


class LatheTool(_Model):
    """A true turning tool (type 5xy): tip P = F − (l1·x̂ + l2·ẑ), nose centre S = P − radius·s(SL)."""

    t: int = Field(ge=1, le=9999)
    type: int = Field(500, ge=500, le=599)
    sl: int = Field(ge=1, le=9)
    l1: Finite
    l2: Finite
    radius: NonNegative = 0.0
    name: str | None = Field(None, max_length=40)
    nominal: ToolNominal = Field(default_factory=ToolNominal)
    wear_per_part: LengthWear = Field(default_factory=LengthWear)

    def nominal_value(self, name: str) -> float:
        value = getattr(self.nominal, name)
        return float(getattr(self, name) if value is None else value)


class ProbeNominal(_Model):
    l1: Finite | None = None
    l2: Finite | None = None
    ball_diameter: Positive | None = None


class LatheProbe(_Model):
    """The workpiece probe in the turret: true ball centre F − (l1·x̂ + l2·ẑ); it does not turn."""

    t: int = Field(8, ge=1, le=9999)
    type: int = Field(580, ge=500, le=599)
    sl: int = Field(7, ge=5, le=8)
    l1: Finite
    l2: Finite
    ball_diameter: Positive = 6.0
    pretravel: dict[str, NonNegative] = Field(default_factory=dict)
    noise_sigma: NonNegative = 0.0
    max_deflection: Positive = 2.0
    nominal: ProbeNominal = Field(default_factory=ProbeNominal)
    radio: Radio | None = None                    # a radio/optical probe (design.md §10.4); None: cable

    @field_validator("pretravel")
    @classmethod
    def _keys(cls, value: dict[str, float]) -> dict[str, float]:
        bad = sorted(set(value) - set(PRETRAVEL_KEYS))
        if bad:
            raise ValueError(f"unknown travel direction(s) {bad}; use {list(PRETRAVEL_KEYS)}")
        return value

    def nominal_value(self, name: str) -> float:
        value = getattr(self.nominal, name)
        return float(getattr(self, name) if value is None else value)


class ToolProbeCube(_Model):
    faces: dict[str, Finite]
    pretravel: NonNegative = 0.0
    max_deflection: Positive = 1.0
    y_size: Positive = 20.0
    nominal: dict[str, Finite] | None = None
    radio: Radio | None = None                    # a radio tool probe (design.md §10.4); None: cable

    @field_validator("faces", "nominal")
    @classmethod
    def _four_faces(cls, value: dict[str, float] | None) -> dict[str, float] | None:
        if value is None:
            return value
        if set(value) != set(FACE_KEYS):
            raise ValueError(f"the four faces {list(FACE_KEYS)} keyed by the travel direction that touches them")
        if not value["X-"] > value["X+"] or not value["Z-"] > value["Z+"]:
            raise ValueError("X- (top) must lie above X+ (bottom) and Z- (right) right of Z+ (left)")
        return value

    def rough(self) -> dict[str, float]:
        """The _TP record the HMI starts from: ``nominal``, else the faces rounded to whole mm."""
        return dict(self.nominal) if self.nominal is not None else {k: float(round(v)) for k, v in self.faces.items()}


class Sl7Groove(_Model):
    """Axial groove (SL 7): an annular gap x_minus < r < x_plus open towards +Z, bottom at bottom_z."""

    x_minus: Positive
    x_plus: Positive
    bottom_z: Finite
    top_z: Finite | None = None
    wall: Positive = 5.0

    @model_validator(mode="after")
    def _shape(self) -> Sl7Groove:
        if self.top_z is None:
            self.top_z = self.bottom_z + 10.0
        if not self.x_minus < self.x_plus:
            raise ValueError("sl7: x_minus must be below x_plus")
        if not self.top_z > self.bottom_z:
            raise ValueError("sl7: top_z must lie above bottom_z")
        return self

    def bodies(self) -> list[tuple[float, float, float, float]]:
        """Solid rings (r_in, r_out, z_lo, z_hi): inner wall, outer wall, bottom."""
        z0, top = self.bottom_z - self.wall, self.top_z
        assert top is not None                          # _shape sets it on validation
        return [(max(self.x_minus - self.wall, 0.0), self.x_minus, z0, top),
                (self.x_plus, self.x_plus + self.wall, z0, top),
                (self.x_minus, self.x_plus, z0, self.bottom_z)]


class Sl8Groove(_Model):
    """Radial groove (SL 8): a gap z_minus < z < z_plus open towards +X, bottom at radius bottom_x."""

    z_minus: Finite
    z_plus: Finite
    top_x: Positive
    bottom_x: Positive
    wall: Positive = 5.0

    @model_validator(mode="after")
    def _shape(self) -> Sl8Groove:
        if not self.z_minus < self.z_plus:
            raise ValueError("sl8: z_minus must be left of z_plus")
        if not self.bottom_x < self.top_x:
            raise ValueError("sl8: bottom_x must lie below top_x")
        return self

    def bodies(self) -> list[tuple[float, float, float, float]]:
        r0 = max(self.bottom_x - self.wall, 0.0)
        return [(r0, self.top_x, self.z_minus - self.wall, self.z_minus),
                (r0, self.top_x, self.z_plus, self.z_plus + self.wall),
                (r0, self.bottom_x, self.z_minus, self.z_plus)]


GROOVE_KB_KEYS = ("x_minus", "x_plus", "bottom_z", "z_minus", "z_plus", "top_x", "bottom_x")


class Groove(_Model):
    """A reference groove pair; ``nominal`` (extension): the _KB values the HMI starts from when
    they differ from the truth (default: the truth, as its certificate gives it)."""

    sl7: Sl7Groove | None = None
    sl8: Sl8Groove | None = None
    nominal: dict[str, Finite] | None = None

    @field_validator("nominal")
    @classmethod
    def _kb_keys(cls, value: dict[str, float] | None) -> dict[str, float] | None:
        bad = sorted(set(value or {}) - set(GROOVE_KB_KEYS))
        if bad:
            raise ValueError(f"unknown groove value(s) {bad}; use {list(GROOVE_KB_KEYS)}")
        return value

    def bodies(self) -> list[tuple[float, float, float, float]]:
        return [*(self.sl7.bodies() if self.sl7 else []), *(self.sl8.bodies() if self.sl8 else [])]

    def kb(self) -> dict[str, float]:
        """The groove's surfaces as the operator enters them (params.groove, _KB, turning.md §0.6)."""
        if self.nominal is not None:
            return dict(self.nominal)
        out: dict[str, float] = {}
        if self.sl7 is not None:
            out.update(x_minus=self.sl7.x_minus, x_plus=self.sl7.x_plus, bottom_z=self.sl7.bottom_z)
        if self.sl8 is not None:
            out.update(z_minus=self.sl8.z_minus, z_plus=self.sl8.z_plus, top_x=self.sl8.top_x,
                       bottom_x=self.sl8.bottom_x)
        return out


class MachinedBy(_Model):
    t: int = Field(ge=1, le=9999)


class ProfileItem(_Model):
    """A cylinder (solid) or a bore (cut from the cylinders) from z[0] to z[1] (part z from the chuck face)."""

    type: Literal["cylinder", "bore"]
    z: Vec2
    diameter: Positive
    machined_by: MachinedBy | None = None

    @field_validator("z")
    @classmethod
    def _range(cls, value: tuple[float, float]) -> tuple[float, float]:
        if not value[0] < value[1]:
            raise ValueError(f"z: {value[0]} must be below {value[1]}")
        if value[0] < 0.0:
            raise ValueError("z: the part starts at the chuck face (z >= 0)")
        return value


class LatheWorkpiece(_Model):
    chuck_face_z: Finite = 0.0
    eccentricity: Vec2 = (0.0, 0.0)
    face_runout_deg: float = Field(0.0, ge=-5.0, le=5.0)
    profile: list[ProfileItem] = Field(default_factory=list)

    @model_validator(mode="after")
    def _cylinders(self) -> LatheWorkpiece:
        if any(p.type == "bore" for p in self.profile) and not any(p.type == "cylinder" for p in self.profile):
            raise ValueError("profile: a bore needs a cylinder to be cut from")
        return self

    @property
    def cylinders(self) -> list[ProfileItem]:
        return [p for p in self.profile if p.type == "cylinder"]

    @property
    def bores(self) -> list[ProfileItem]:
        return [p for p in self.profile if p.type == "bore"]


class LatheScenario(_Model):
    seed: int = Field(0, ge=0, le=2**63 - 1)
    machine: LatheMachineConfig
    spindle: Spindle = Field(default_factory=Spindle)
    tools: list[LatheTool] = Field(default_factory=list)
    probe: LatheProbe
    tool_probe: ToolProbeCube | None = None
    grooves: list[Groove] = Field(default_factory=list)
    workpiece: LatheWorkpiece | None = None
    start: dict[str, Finite] | None = None

    @model_validator(mode="after")
    def _consistent(self) -> LatheScenario:
        numbers = [tool.t for tool in self.tools]
        if len(set(numbers)) != len(numbers):
            raise ValueError("tools: tool numbers must be unique")
        if self.probe.t in numbers:
            raise ValueError(f"tools: T{self.probe.t} is the probe's number (probe.t)")
        for axis, value in (self.start or {}).items():
            if axis not in self.axes:
                raise ValueError(f"start: unknown axis {axis!r} (the lathe has {', '.join(self.axes)})")
            lo, hi = self.machine.limits[axis]
            if not lo <= value <= hi:
                raise ValueError(f"start.{axis} = {value} is outside the limits [{lo}, {hi}]")
        self._check_clearances()
        return self

    def _check_clearances(self) -> None:
        """Groove bodies and the tool probe clear of the part (widened by |e|) and of the chuck
        (turning.md §10.2: such a scenario is refused, nothing loaded)."""
        wp = self.workpiece or LatheWorkpiece()
        chuck, ecc = wp.chuck_face_z, math.hypot(*wp.eccentricity)
        part = [(0.0, c.diameter / 2.0 + ecc, chuck + c.z[0], chuck + c.z[1]) for c in wp.cylinders]
        for k, groove in enumerate(self.grooves):
            for r0, r1, z0, z1 in groove.bodies():
                where = f"grooves[{k}]"
                if z0 < chuck - 1e-9:
                    raise ValueError(f"{where}: its body reaches Z {z0:g}, into the chuck (Z < {chuck:g})")
                for p0, p1, q0, q1 in part:
                    if r0 < p1 and p0 < r1 and z0 < q1 and q0 < z1:
                        raise ValueError(f"{where}: its body (radii {r0:g}..{r1:g}, Z {z0:g}..{z1:g}) overlaps "
                                         "the workpiece")
        tp = self.tool_probe
        if tp is not None:
            if tp.faces["Z+"] < chuck - 1e-9:
                raise ValueError("tool_probe: the cube reaches into the chuck")
            for _p0, p1, q0, q1 in part:
                if tp.faces["X+"] < p1 and tp.faces["Z+"] < q1 and q0 < tp.faces["Z-"]:
                    raise ValueError("tool_probe: the cube overlaps the workpiece")

    # --- what the rest of the app asks of a scenario ----------------------------------------
    @property
    def kind(self) -> str:
        return "lathe"

    @property
    def axes(self) -> tuple[str, ...]:
        return ("X", "Y", "Z") if self.machine.has_y else ("X", "Z")

    def limits(self) -> dict[str, tuple[float, float]]:
        out = {a: self.machine.limits[a] for a in self.axes}          # (lo, hi) tuples: no copies needed
        out.setdefault("Y", (0.0, 0.0))
        return out

    def start_position(self) -> dict[str, float]:
        """Axes at load: ``start`` where given, else X and Z at their upper limits (turret
        retracted, above and right of everything), Y at 0 (clamped)."""
        limits = self.limits()
        default = {"X": limits["X"][1], "Z": limits["Z"][1], "Y": min(max(0.0, limits["Y"][0]), limits["Y"][1])}
        return {a: float((self.start or {}).get(a, default[a])) for a in ("X", "Y", "Z")}

    def tool(self, t: int) -> LatheTool | None:
        return next((tool for tool in self.tools if tool.t == t), None)

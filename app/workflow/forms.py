"""Declarative input fields of every measuring screen (spec/jog-measuring.md §2.3, design.md §4).

A field's ``name`` is the API parameter (``setpoint.X`` for one axis of a plane setpoint).
Labels are the manual's English texts. One form builder per task family; the task registry
(``app/workflow/tasks.py``) names each task's builder. Validation is the engine's; the screens
(``app/web/task_forms.py``) only turn typed text into API params and back.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from app.gud import GudSettings
from app.workflow.context import MEASURE_ONLY
from engine.planes import Plane


@dataclass(frozen=True)
class FieldSpec:
    name: str                       # API param; "setpoint.X" = one axis of the setpoint object
    label: str                      # the manual's English text
    kind: str = "number"            # number | choice | position
    unit: str = ""
    default: str = ""
    choices: tuple[tuple[str, str], ...] = ()   # (value, text)
    locks: bool = False             # decides how the points are probed: locked while one is stored
    group: str = ""                 # "tool": shown with the target "Tool offset" only
    param: str = ""                 # the cycle's parameter name, shown under the label (lathe screens)


@dataclass(frozen=True)
class FormEnv:
    """What the fields depend on at run time."""

    plane: Plane
    offsets: tuple[str, ...]        # stored frames in chain order
    active_offset: str
    rotary_axes: tuple[str, ...]
    gud: GudSettings
    diameter_programming: bool = False      # a lathe with DIAMON: X values of the cycles are diameters

    @property
    def extended(self) -> bool:
        return self.gud.compensation_choice == "extended"


def target_choices(env: FormEnv) -> tuple[tuple[str, str], ...]:
    """Measure only, G54.. and G505.., Basic reference, basic frames (extended choice, jog-measuring §4.1/4.2)."""
    out = [(MEASURE_ONLY, "Measure only")]
    out += [(n, n) for n in env.offsets if n.startswith("G")]
    if "BASIC_REF" in env.offsets:
        out.append(("BASIC_REF", "Basic reference"))
    if env.extended:
        out += [(n, f"Basic frame {n.split('_')[1]}") for n in env.offsets
                if n.startswith("BASIC_") and n != "BASIC_REF"]
    return tuple(out)


TOOL_TARGET = "tool"            # the target choice of a tool offset (design.md §9.3)


def tool_offset_fields(env: FormEnv) -> list[FieldSpec]:
    """The tool to correct and the tolerance band (manual §1.10, measuring-math §3.2): shown
    under "Zero offset = Tool offset"; empty tolerance fields take the settings' values."""
    g = env.gud
    tol: list[tuple[str, str, str, float | str]] = [
        ("setpoint", "Setpoint (nominal size)", "mm", ""), ("upper", "Upper tolerance", "mm", g.tol_upper),
        ("lower", "Lower tolerance", "mm", g.tol_lower), ("zero_range", "Zero offset range", "mm", g.tol_zero_range),
        ("mean_range", "Mean value range", "mm", g.tol_mean_range),
        ("dim_difference", "Dimension difference", "mm", g.tol_dim_difference),
        ("safe_area", "Safe area", "mm", g.tol_safe_area), ("k", "Weighting factor k", "", g.tol_k),
        ("evnum", "Empirical / mean value memory", "", g.tol_evnum)]
    out = [FieldSpec("tool_target.tool", "Tool T", default="", group="tool"),
           FieldSpec("tool_target.correct", "Correct", "choice", default="radius", group="tool",
                     choices=(("radius", "Radius"), ("length", "Length"))),
           FieldSpec("tool_target.mode", "Correct into", "choice", group="tool",
                     default="geometry" if g.tool_offset_geometry else "wear",
                     choices=(("wear", "Wear"), ("geometry", "Geometry")))]
    out += [FieldSpec(f"tolerance.{key}", label, unit=unit, group="tool",
                      default="" if value == "" else number_text(float(value))) for key, label, unit, value in tol]
    out.append(FieldSpec("tolerance.keep_mean", "Keep the mean value over the parts", "choice", group="tool",
                         default="yes" if g.tol_keep_mean else "no", choices=(("no", "No"), ("yes", "Yes"))))
    return out


def with_tool_offset(fields: list[FieldSpec], env: FormEnv) -> list[FieldSpec]:
    """A task that may correct a tool: "Tool offset" among the targets, and its fields."""
    out = []
    for spec in fields:
        if spec.name == "target":
            spec = dataclasses.replace(spec, choices=(*spec.choices, (TOOL_TARGET, "Tool offset")))
        out.append(spec)
    return out + tool_offset_fields(env)


def default_target(env: FormEnv) -> str:
    """Preset to the WO active during measurement (manual §4.3.9, jog-measuring §4.4: _JM_I[4], "active" =
    the one active now). Under G500 nothing could be corrected: the first settable WO (G54) is
    proposed instead of "Measure only", which stays one choice away."""
    measuring = env.gud.measuring_wo if env.gud.measuring_wo != "active" else env.active_offset
    if measuring in env.offsets and measuring != "G500":
        return measuring
    settable = [n for n in env.offsets if n.startswith("G") and n != "G500"]
    return settable[0] if settable else MEASURE_ONLY


def _target(env: FormEnv) -> FieldSpec:
    return FieldSpec("target", "Zero offset", "choice", default=default_target(env), choices=target_choices(env))


def _axis_field(env: FormEnv, default: str, label: str = "Axis") -> FieldSpec:
    return FieldSpec("axis", label, "choice", default=default, choices=tuple((a, a) for a in env.plane.axes),
                     locks=True)


def _direction(name: str = "direction", label: str = "Direction", default: str = "+") -> FieldSpec:
    return FieldSpec(name, label, "choice", default=default, choices=(("+", "+"), ("-", "−")), locks=True)


def _plane_setpoints(env: FormEnv, of: str = "P0") -> list[FieldSpec]:
    return [FieldSpec(f"setpoint.{a}", f"Setpoint {a}0 ({of})", unit="mm", default="0")
            for a in (env.plane.first, env.plane.second)]


def _angle_correction(env: FormEnv, allow_none: bool) -> FieldSpec:
    choices = ((("none", "none"),) if allow_none else ()) + (("rotation", "Coordinate rotation"),)
    choices += tuple((a, f"Rotary axis {a}") for a in env.rotary_axes)
    return FieldSpec("angle_correction", "Angle correction", "choice",
                     default="none" if allow_none else "rotation", choices=choices)


def _setpoint_angle() -> FieldSpec:
    return FieldSpec("setpoint_angle", "Setpoint angle", unit="°", default="0")


def _diameter() -> FieldSpec:
    # a hole's diameter may stay empty: probing then starts at the start point (jog-measuring §2.3)
    return FieldSpec("diameter", "Approx. diameter", unit="mm", locks=True)


def _infeed() -> FieldSpec:
    return FieldSpec("infeed", "Infeed DZ", unit="mm", locks=True)


def edge_form(variant: str, env: FormEnv) -> list[FieldSpec]:
    """Set edge / align edge / distance 2 edges (jog-measuring §2.5)."""
    plane = env.plane
    out = [_target(env), _axis_field(env, plane.second if variant == "align" else plane.first)]
    if variant == "align":
        out += [_direction(), _points(2),
                FieldSpec("reference_axis", "Angle reference axis", "choice", default=plane.first,
                          choices=((plane.first, plane.first), (plane.second, plane.second)), locks=True),
                _angle_correction(env, False), _setpoint_angle()]
    elif variant == "distance":
        out += [_direction(label="Direction P1"), _direction("direction_p2", "Direction P2", "-"),
                FieldSpec("setpoint", "Setpoint of the centre", unit="mm", default="0")]
    else:
        out += [_direction(), FieldSpec("setpoint", "Setpoint", unit="mm", default="0")]
    return out


def corner_form(variant: str, env: FormEnv) -> list[FieldSpec]:
    """Right-angled / any corner (jog-measuring §2.6)."""
    return [_target(env),
            FieldSpec("kind", "Inside / outside corner", "choice", default="outside",
                      choices=(("outside", "Outside corner"), ("inside", "Inside corner")), locks=True),
            FieldSpec("position", "Corner position", "position", default="1",
                      choices=tuple((str(n), str(n)) for n in range(1, 5)), locks=True),
            *_plane_setpoints(env)]


def rect_form(spigot: bool):
    """Rectangular pocket / spigot (jog-measuring §2.7.1, jog-measuring §2.8)."""
    def form(variant: str, env: FormEnv) -> list[FieldSpec]:
        plane = env.plane
        out = [_target(env), FieldSpec("length", f"Length L ({plane.first})", unit="mm", locks=True),
               FieldSpec("width", f"Width W ({plane.second})", unit="mm", locks=True)]
        if spigot:
            out.append(_infeed())
        return out + _plane_setpoints(env)
    return form


def circles_form(spigot: bool):
    """1..4 holes / circular spigots (jog-measuring §2.7, jog-measuring §2.8); ``variant`` is the count."""
    def form(variant: str, env: FormEnv) -> list[FieldSpec]:
        out = [_target(env), _diameter()]
        if spigot:
            out.append(_infeed())
        if variant == "1":
            out.append(FieldSpec("probe_angle", "Probing angle", unit="°", default="0", locks=True))
            return out + _plane_setpoints(env)
        out += [_angle_correction(env, variant != "2"), _setpoint_angle()]
        if variant == "2":
            out.append(FieldSpec("set_p1", "Set P1", "choice", default="no", choices=(("no", "No"), ("yes", "Yes"))))
            return out + _plane_setpoints(env, "P1")
        return out + _plane_setpoints(env)
    return form


def plane_form(variant: str, env: FormEnv) -> list[FieldSpec]:
    """Orient plane (jog-measuring §2.9)."""
    return [_target(env), _points(3)]


SCREEN_MAX_POINTS = 6         # the vertical softkeys hold P1..P6


def _points(minimum: int) -> FieldSpec:
    """More points than the minimum: a least-squares line / plane with its form error (design.md §9.8)."""
    return FieldSpec("points", "Number of points", "choice", default=str(minimum),
                     choices=tuple((str(n), str(n)) for n in range(minimum, SCREEN_MAX_POINTS + 1)), locks=True)


def probe_length_form(variant: str, env: FormEnv) -> list[FieldSpec]:
    """Calibrate length (jog-measuring §5.2): the surface height preset from E_MESS_CAL_L."""
    return [FieldSpec("setpoint", f"Calibration height {env.plane.infeed}", unit="mm",
                      default=number_text(env.gud.cal_height))]


def probe_radius_form(variant: str, env: FormEnv) -> list[FieldSpec]:
    """Calibrate radius (jog-measuring §5.3): the ring preset from E_MESS_CAL_D."""
    ring = float(env.gud.cal_ring_diameter)
    return [FieldSpec("diameter", "Diameter of calibration ring", unit="mm",
                      default=number_text(ring) if ring > 0 else ""),
            # more than 4: the direction-dependent trigger map (engine.lobing, design.md §9.8)
            FieldSpec("directions", "Probing directions", "choice", default="4",
                      choices=(("4", "4 (±X, ±Y)"), ("8", "8"), ("12", "12 (trigger map)"),
                               ("24", "24 (trigger map)")), locks=True)]


def toolprobe_form(variant: str, env: FormEnv) -> list[FieldSpec]:
    """Calibrate the tool probe (jog-measuring §7.2)."""
    return [FieldSpec("mode", "Calibration type (Select)", "choice", default="length",
                      choices=(("length", "Length only"), ("length_diameter", "Length and diameter")))]


def tool_form(variant: str, env: FormEnv) -> list[FieldSpec]:
    """Tool length / diameter (jog-measuring §7.3)."""
    return [FieldSpec("offset_v", "Offset V", unit="mm", default="0")]


def number_text(value: float) -> str:
    return f"{float(value):g}"


# --- the lathe tasks (turning.md §10.2, a product extension) -----------------------------------------
#
# Field names are the API params, nested ones dotted ("tolerance.safe_area", "groove.number",
# "zone.Z", "target.tool"); yes/no choices are booleans. The tool-offset fields (group "tool")
# show with the target "Tool offset". Units per turning.md §10.2: on X with diameter programming
# the setpoint, the 974/994 bands and their results are diameters, the rest radius values.

LATHE_YES_NO = (("no", "No"), ("yes", "Yes"))
RADIUS = " (radius)"           # label suffixes are translated by their pattern (app/web/texts.py LABELS)
LATHE_TOOL_TARGET = "tool"


def _x(env: FormEnv) -> str:
    """The label suffix of a value that follows diameter programming on X (turning.md §10.2 Units)."""
    return " (Ø on X)" if env.diameter_programming else " (radius on X)"


def _yes_no(name: str, label: str, default: str = "no", locks: bool = False, param: str = "") -> FieldSpec:
    return FieldSpec(name, label, "choice", default=default, choices=LATHE_YES_NO, locks=locks, param=param)


def _lathe_axis(axes: tuple[str, ...], default: str = "X") -> FieldSpec:
    return FieldSpec("axis", "Measuring axis", "choice", default=default, choices=tuple((a, a) for a in axes),
                     param="_MA")


def _lathe_common() -> list[FieldSpec]:
    return [FieldSpec("measuring_path", "Measuring path" + RADIUS, unit="mm", default="2", param="_FA"),
            FieldSpec("feed", "Measuring feed (0: 150 or 300)", unit="mm/min", default="0", param="_VMS"),
            FieldSpec("probe", "Probe number", default="1", param="_PRNUM"),
            FieldSpec("measurements", "Measurements at one place", default="1", param="_NMSP")]


# the operator's words are the milling screens' (tool_offset_fields); the cycle's name under them
LATHE_TOLERANCES = {"upper": ("Upper tolerance", "mm", "_TUL"), "lower": ("Lower tolerance", "mm", "_TLL"),
                    "zero_range": ("Zero offset range", "mm", "_TZL"), "mean_range": ("Mean value range", "mm", "_TMV"),
                    "dim_difference": ("Dimension difference", "mm", "_TDIF"), "safe_area": ("Safe area", "mm", "_TSA"),
                    "k": ("Weighting factor k", "", "_K"), "evnum": ("Empirical / mean value memory", "", "_EVNUM")}


def _lathe_tolerances(keys: tuple[str, ...], suffix: str) -> list[FieldSpec]:
    out = [FieldSpec(f"tolerance.{k}", LATHE_TOLERANCES[k][0] + (suffix if LATHE_TOLERANCES[k][1] else ""),
                     unit=LATHE_TOLERANCES[k][1], param=LATHE_TOLERANCES[k][2])
           for k in keys if k in LATHE_TOLERANCES]
    if "keep_mean" in keys:
        out.append(_yes_no("tolerance.keep_mean", "Keep the mean value over the parts", param="_CHBIT[4]"))
    return out


def _lathe_tool_target(correct: tuple[tuple[str, str], ...]) -> list[FieldSpec]:
    return [FieldSpec("target.tool", "Tool T to correct", group="tool", param="_TNUM"),
            FieldSpec("target.correct", "Correct", "choice", default="length", group="tool", choices=correct,
                      param="_KNUM"),
            FieldSpec("target.mode", "Correct into", "choice", default="wear", group="tool",
                      choices=(("wear", "Wear"), ("geometry", "Geometry")), param="_CHBIT[6]"),
            dataclasses.replace(_yes_no("target.inverse", "Inverse correction", param="_KNUM (digit 5)"),
                                group="tool")]


def lathe_form(variant: str, env: FormEnv) -> list[FieldSpec]:
    """The fields of the lathe task ``lathe.<variant>`` (turning.md §10.2; the manual's cycle
    support screens measuring-math §10.1): each label in the operator's words, the cycle
    parameter it sets in ``param`` (the screen shows it under the label)."""
    radius = RADIUS
    axes = tuple(a for a in ("Z", "X", "Y") if a in env.plane.axes)
    reference = FieldSpec("reference", "Probe data", "choice", default="machine", param="_TP / _TPW",
                          choices=(("machine", "machine-related"), ("workpiece", "workpiece-related")))
    compensation = FieldSpec("compensation", "Tool data", "choice", default="geometry", param="_CHBIT[3]",
                             choices=(("geometry", "first measurement: geometry"), ("wear", "re-measurement: wear")))
    direction = FieldSpec("direction", "Direction (incremental only)", "choice", default="-",
                          choices=(("-", "−"), ("+", "+")), param="_MD")
    incremental = _yes_no("incremental", "Incremental (tool placed by hand)", param="_MVAR")
    if variant == "toolprobe.calibrate":
        return [_lathe_axis(("Z", "X")), reference, incremental,
                direction, *_lathe_tolerances(("zero_range", "safe_area"), radius), *_lathe_common()]
    if variant in ("tool.measure", "tool.auto"):
        out = [] if variant == "tool.auto" else [_lathe_axis(("Z", "X"))]
        out += [reference, compensation]
        if variant == "tool.measure":
            out += [incremental, direction]
        return out + _lathe_tolerances(("zero_range", "dim_difference", "safe_area", "evnum"), radius) \
            + _lathe_common()
    if variant == "probe.groove":
        return [FieldSpec("groove.number", "Reference groove", "choice", default="1", param="_CALNUM",
                          choices=(("1", "1"), ("2", "2"), ("3", "3"))),
                _lathe_axis(("Z", "X")),
                FieldSpec("direction", "Direction", "choice", default="both", param="_MD",
                          choices=(("both", "both directions"), ("-", "−"), ("+", "+"))),
                _yes_no("skew", "Position deviation (skew)"), _yes_no("ball_diameter", "Effective ball diameter"),
                *_lathe_tolerances(("zero_range", "safe_area"), radius), *_lathe_common()]
    if variant == "probe.surface":
        return [_lathe_axis(axes, "Z"), FieldSpec("direction", "Direction", "choice", default="-", param="_MD",
                                                  choices=(("-", "−"), ("+", "+"))),
                FieldSpec("setpoint", "Surface position" + _x(env), unit="mm", param="_SETVAL"),
                *_lathe_tolerances(("zero_range", "safe_area"), radius), *_lathe_common()]
    keys = ("upper", "lower", "zero_range", "mean_range", "dim_difference", "safe_area", "k", "evnum", "keep_mean")
    correct = (("length", "Length acting on the axis"), ("radius", "Radius"), ("l1", "L1"), ("l2", "L2"))
    if variant == "point":
        targets = ((MEASURE_ONLY, "Measure only"), *((n, n) for n in env.offsets if n.startswith("G")),
                   (LATHE_TOOL_TARGET, "Tool offset"))
        return [FieldSpec("target", "Correction", "choice", default=MEASURE_ONLY, choices=targets, param="_KNUM"),
                _lathe_axis(axes),
                FieldSpec("setpoint", "Setpoint" + _x(env), unit="mm", param="_SETVAL"),
                _yes_no("reversal", "Spindle reversal 180°", param="_MVAR=1000"),
                FieldSpec("start_angle", "Start angle of the reversal", unit="°", default="0", param="_STA1"),
                *_lathe_tool_target(correct),
                *_lathe_tolerances(keys, _x(env)), *_lathe_common()]
    return [FieldSpec("target", "Correction", "choice", default=MEASURE_ONLY, param="_KNUM",
                      choices=((MEASURE_ONLY, "Measure only"), (LATHE_TOOL_TARGET, "Tool offset"))),
            _lathe_axis(axes),
            FieldSpec("setpoint", "Diameter" + _x(env), unit="mm", param="_SETVAL"),
            _yes_no("inside", "Inside diameter (bore)"),
            FieldSpec("zone.Z", "Protection zone in Z (detour)", unit="mm", param="_SZA"),
            FieldSpec("zone.X", "Protection zone in X" + (" (Ø)" if env.diameter_programming else radius),
                      unit="mm", param="_SZO"),
            _yes_no("use_ball_diameter", "Use the ball diameter (probe not calibrated)", param="_CHBIT[7]"),
            *_lathe_tool_target(correct),
            *_lathe_tolerances(keys, _x(env)), *_lathe_common()]

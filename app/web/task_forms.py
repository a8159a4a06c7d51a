"""Declarative input fields of every measuring screen (spec/jog-measuring.md §2.3, design.md §4).

A field's ``name`` is the API parameter (``setpoint.X`` for one axis of a plane setpoint).
Labels are the manual's English texts. Validation is the workflow's (``engine.plan``); this
module only turns typed text into API params and back.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from engine.planes import Plane

WORKPIECE_FAMILIES = ("edge", "corner", "pocket", "hole", "spigot", "plane")
MEASURE_ONLY = "measure_only"


@dataclass(frozen=True)
class FieldSpec:
    name: str                       # API param; "setpoint.X" = one axis of the setpoint object
    label: str                      # the manual's English text
    kind: str = "number"            # number | choice | position
    unit: str = ""
    default: str = ""
    choices: tuple[tuple[str, str], ...] = ()   # (value, text)
    locks: bool = False             # decides how the points are probed: locked while one is stored


@dataclass(frozen=True)
class FormEnv:
    """What the fields depend on at run time."""

    plane: Plane
    offsets: tuple[str, ...]        # stored frames in chain order
    active_offset: str
    rotary_axes: tuple[str, ...]
    gud: object                     # app.gud.GudSettings

    @property
    def extended(self) -> bool:
        return getattr(self.gud, "compensation_choice", "standard") == "extended"


def is_workpiece(task: str) -> bool:
    return task.split(".")[0] in WORKPIECE_FAMILIES


def target_choices(env: FormEnv) -> tuple[tuple[str, str], ...]:
    """Measure only, G54.. and G505.., Basic reference, basic frames (extended choice, spec §4.1/4.2)."""
    out = [(MEASURE_ONLY, "Measure only")]
    out += [(n, n) for n in env.offsets if n.startswith("G")]
    if "BASIC_REF" in env.offsets:
        out.append(("BASIC_REF", "Basic reference"))
    if env.extended:
        out += [(n, f"Basic frame {n.split('_')[1]}") for n in env.offsets
                if n.startswith("BASIC_") and n != "BASIC_REF"]
    return tuple(out)


def default_target(env: FormEnv) -> str:
    """Preset to the WO active during measurement (manual §4.3.9); G500 = measure only."""
    return env.active_offset if env.active_offset in env.offsets else MEASURE_ONLY


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
    # a hole's diameter may stay empty: probing then starts at the start point (spec §2.3)
    return FieldSpec("diameter", "Approx. diameter", unit="mm", locks=True)


def _infeed() -> FieldSpec:
    return FieldSpec("infeed", "Infeed DZ", unit="mm", locks=True)


def fields_for(task: str, env: FormEnv) -> list[FieldSpec]:
    """The input fields of ``task`` in screen order."""
    family, _, variant = task.partition(".")
    plane = env.plane
    if family == "edge":
        out = [_target(env), _axis_field(env, plane.second if variant == "align" else plane.first)]
        if variant == "align":
            out += [_direction(),
                    FieldSpec("reference_axis", "Angle reference axis", "choice", default=plane.first,
                              choices=((plane.first, plane.first), (plane.second, plane.second)), locks=True),
                    _angle_correction(env, False), _setpoint_angle()]
        elif variant == "distance":
            out += [_direction(label="Direction P1"), _direction("direction_p2", "Direction P2", "-"),
                    FieldSpec("setpoint", "Setpoint of the centre", unit="mm", default="0")]
        else:
            out += [_direction(), FieldSpec("setpoint", "Setpoint", unit="mm", default="0")]
        return out
    if family == "corner":
        return [_target(env),
                FieldSpec("kind", "Inside / outside corner", "choice", default="outside",
                          choices=(("outside", "Outside corner"), ("inside", "Inside corner")), locks=True),
                FieldSpec("position", "Corner position", "position", default="1",
                          choices=tuple((str(n), str(n)) for n in range(1, 5)), locks=True),
                *_plane_setpoints(env)]
    if task in ("pocket.rect", "spigot.rect"):
        out = [_target(env), FieldSpec("length", f"Length L ({plane.first})", unit="mm", locks=True),
               FieldSpec("width", f"Width W ({plane.second})", unit="mm", locks=True)]
        if family == "spigot":
            out.append(_infeed())
        return out + _plane_setpoints(env)
    if family in ("hole", "spigot"):
        spigot = family == "spigot"
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
    if family == "plane":
        return [_target(env)]
    if task == "probe.length":
        return [FieldSpec("setpoint", f"Calibration height {plane.infeed}", unit="mm",
                          default=_number_text(getattr(env.gud, "cal_height", 0.0)))]
    if task == "probe.radius":
        ring = float(getattr(env.gud, "cal_ring_diameter", 0.0) or 0.0)
        return [FieldSpec("diameter", "Diameter of calibration ring", unit="mm",
                          default=_number_text(ring) if ring > 0 else "")]
    if task == "toolprobe.calibrate":
        return [FieldSpec("mode", "Calibration type (Select)", "choice", default="length",
                          choices=(("length", "Length only"), ("length_diameter", "Length and diameter")))]
    if family == "tool":
        return [FieldSpec("offset_v", "Offset V", unit="mm", default="0")]
    return []


def _number_text(value: float) -> str:
    return f"{float(value):g}"


@dataclass
class FormData:
    """Typed text per field, the API params made from it, and errors per field name."""

    values: dict[str, str]
    params: dict
    target: str | None
    errors: dict[str, str] = field(default_factory=dict)


def defaults(fields: list[FieldSpec]) -> dict[str, str]:
    return {f.name: f.default for f in fields}


def form_data(task: str, fields: list[FieldSpec], form: dict | None, gud=None) -> FormData:
    """API params from the typed text; empty numbers are left out (the workflow's defaults apply)."""
    values = defaults(fields)
    if form:
        values.update({f.name: str(form[f.name]).strip() for f in fields if f.name in form})
    params: dict = {}
    target = None
    for spec in fields:
        text = values.get(spec.name, "")
        if spec.name == "target":
            target = text or None
            continue
        if spec.kind == "number":
            if text == "":
                continue
            value: object = text.replace(",", ".")
        elif spec.name == "set_p1":
            value = text == "yes"
        else:
            value = text
        if spec.name.startswith("setpoint."):
            params.setdefault("setpoint", {})[spec.name.split(".", 1)[1]] = value
        else:
            params[spec.name] = value
    if task.startswith("tool.") and gud is not None:
        params["compensation"] = gud.tool_offset_mode     # _JM_B[0], shown read-only
    return FormData(values=values, params=params, target=target)


def values_from_params(fields: list[FieldSpec], params: dict) -> dict[str, str]:
    """Text of the locked fields from a session's normalised params."""
    out = {}
    for spec in fields:
        if spec.name.startswith("setpoint."):
            continue
        value = params.get(spec.name)
        if value is None:
            continue
        if isinstance(value, bool):
            out[spec.name] = "yes" if value else "no"
        elif isinstance(value, float):
            out[spec.name] = _number_text(value)
        else:
            out[spec.name] = str(value)
    return out


def field_of_error(fields: list[FieldSpec], name: str | None) -> str:
    """The screen field an API error names ("setpoint.X" on a one-axis setpoint is "setpoint")."""
    names = {f.name for f in fields}
    if name in names:
        return name
    if name and name.startswith("setpoint") and "setpoint" in names:
        return "setpoint"
    return "_form"


def friendly(fields: list[FieldSpec], field_name: str, message: str) -> str:
    """The workflow's message with the parameter name replaced by the field's label."""
    first, _, rest = message.partition(" ")
    for spec in fields:
        if spec.name == field_name and (first == spec.name or first.startswith(spec.name + ".")):
            return f"{spec.label} {rest}"
    return message

"""Parameter validation of every measuring task (spec/jog-measuring.md §2.3 [I], design.md §4).

One validator per task family: ``validate_xxx(variant, params, plane) -> normalised params`` or
``ParamError(field, message)``. ``engine.tasks`` names the validator of each task; ``target`` is
passed through untouched (the app validates it) and unknown keys are dropped.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from engine.checks import ParamError, param_choice, param_number, param_positive
from engine.planes import Plane

ROTARY_AXES = ("A", "B", "C")   # design.md §3: optional rotary axes
MAX_MAGNITUDE = 100_000.0       # mm/deg: no measuring quantity beyond the offset limits (design.md §9.1)

ParamsValidator = Callable[[str, dict[str, Any], Plane], dict[str, Any]]   # (variant, params, plane)


def _axis(params: dict[str, Any], name: str, default: str) -> str:
    value = params.get(name, default)
    value = value.upper() if isinstance(value, str) else value
    if value not in ("X", "Y", "Z"):
        raise ParamError(name, f"{name} must be X, Y or Z, got {params.get(name)!r}")
    return value


def _setpoint_axis(params: dict[str, Any], axis: str) -> dict[str, float]:
    """Set edge / distance / probe length: {axis: value} (design.md §4); a bare number is accepted."""
    value = params.get("setpoint", 0.0)
    if isinstance(value, dict):
        extra = [k for k in value if k != axis]
        if extra:
            raise ParamError(f"setpoint.{extra[0]}", f"setpoint may only give the {axis} value")
        value = value.get(axis, 0.0)
    return {axis: param_number({f"setpoint.{axis}": value}, f"setpoint.{axis}", 0.0, bound=MAX_MAGNITUDE) or 0.0}   # empty = 0


def _setpoint_point(params: dict[str, Any], plane: Plane) -> dict[str, float]:
    """Plane setpoints keyed by the plane's axis names (design.md §4), default 0."""
    value = params.get("setpoint", {}) or {}
    if not isinstance(value, dict):
        raise ParamError("setpoint", "setpoint must be an object keyed by the plane's axis names")
    out = {}
    for axis in (plane.first, plane.second):
        out[axis] = param_number({f"setpoint.{axis}": value.get(axis, 0.0)}, f"setpoint.{axis}", 0.0, bound=MAX_MAGNITUDE) or 0.0
    for key in value:
        if key not in out:
            raise ParamError(f"setpoint.{key}", f"setpoint axis {key!r} is not an axis of the plane {plane.name}")
    return out


def _angle_correction(params: dict[str, Any], allowed_none: bool, default: str) -> str:
    value = params.get("angle_correction", default)
    choices = ("rotation", "none", *ROTARY_AXES) if allowed_none else ("rotation", *ROTARY_AXES)
    value = value.upper() if isinstance(value, str) and len(value) == 1 else value
    if value not in choices:
        raise ParamError("angle_correction",
                         f"angle_correction must be one of {', '.join(choices)}, got {params.get('angle_correction')!r}")
    return value


def _setpoint_angle(params: dict[str, Any]) -> float:
    value = param_number(params, "setpoint_angle", 0.0, bound=MAX_MAGNITUDE) or 0.0     # empty field = 0 (jog-measuring §2.3)
    if not -360.0 < value < 360.0:      # jog-measuring §2.3 [I]: setpoint angle in (−360, 360)
        raise ParamError("setpoint_angle", f"setpoint_angle must lie in (-360, 360), got {value:g}")
    return value


def _passthrough_target(params: dict[str, Any], out: dict[str, Any]) -> dict[str, Any]:
    if "target" in params:
        out["target"] = params["target"]
    return out


def validate_edge(variant: str, params: dict[str, Any], plane: Plane) -> dict[str, Any]:
    """Set edge / align edge / distance 2 edges (jog-measuring §2.5)."""
    out: dict[str, Any] = {"axis": _axis(params, "axis", plane.second if variant == "align" else plane.first),
                 "direction": param_choice(params, "direction", ("+", "-"), "+")}
    if variant == "align":
        others = tuple(a for a in (plane.first, plane.second) if a != out["axis"])
        ref = _axis(params, "reference_axis", others[0])
        if ref == out["axis"] or ref not in (plane.first, plane.second):
            raise ParamError("reference_axis",
                             f"reference_axis must be a plane axis ({plane.first}/{plane.second}) "
                             f"other than the measuring axis {out['axis']}, got {ref}")
        out["reference_axis"] = ref
        out["angle_correction"] = _angle_correction(params, False, "rotation")
        out["setpoint_angle"] = _setpoint_angle(params)
    else:
        if variant == "distance":
            opposite = "-" if out["direction"] == "+" else "+"
            out["direction_p2"] = param_choice(params, "direction_p2", ("+", "-"), opposite)
        if variant == "distance" and params.get("line_angle") is not None:
            out["line_angle"] = _line_angle(params)
            out["setpoint"] = _setpoint_point(params, plane)
        else:
            out["setpoint"] = _setpoint_axis(params, out["axis"])
    return _passthrough_target(params, out)


def _line_angle(params: dict[str, Any]) -> float:
    """Distance 2 edges measured along a line at an angle (CYCLE979 slot/web, measuring-math §10.2):
    the line's angle from the plane's 1st axis, −360..360° (``_STA1``, manual §5.6 parameters).
    Then ``direction``/``direction_p2`` are the travels' signs along the line, ``setpoint`` the
    point (a, o) the line runs through."""
    value = param_number(params, "line_angle", 0.0, bound=MAX_MAGNITUDE) or 0.0
    if not -360.0 <= value <= 360.0:
        raise ParamError("line_angle", f"line_angle must lie in -360..360, got {value:g}")
    return value


def validate_corner(variant: str, params: dict[str, Any], plane: Plane) -> dict[str, Any]:
    """Right-angled / any corner (jog-measuring §2.6)."""
    out: dict[str, Any] = {"kind": param_choice(params, "kind", ("outside", "inside"), "outside")}
    position = param_number(params, "position", 1, bound=MAX_MAGNITUDE)
    if position not in (1.0, 2.0, 3.0, 4.0):
        raise ParamError("position", f"position must be 1, 2, 3 or 4, got {params.get('position')!r}")
    out["position"] = int(position)
    out["setpoint"] = _setpoint_point(params, plane)
    return _passthrough_target(params, out)


def validate_rect(spigot: bool) -> ParamsValidator:
    """Rectangular pocket (``spigot`` False) or spigot (jog-measuring §2.7.1, jog-measuring §2.8)."""
    def validate(variant: str, params: dict[str, Any], plane: Plane) -> dict[str, Any]:
        out: dict[str, Any] = {"length": param_positive(params, "length", required=spigot, bound=MAX_MAGNITUDE),
                     "width": param_positive(params, "width", required=spigot, bound=MAX_MAGNITUDE)}
        if spigot:
            out["infeed"] = param_positive(params, "infeed", required=True, bound=MAX_MAGNITUDE)
        out["setpoint"] = _setpoint_point(params, plane)
        return _passthrough_target(params, out)
    return validate


MIN_CIRCLE_POINTS = 3       # a circle fit's minimum (engine.fit.fit_circle)
MAX_CIRCLE_POINTS = 36


def circle_touches(params: dict[str, Any]) -> dict[str, Any]:
    """``points`` (touches per circle, evenly spaced from the probing angle) and/or ``angles`` (the
    travel directions in degrees from the 1st plane axis), design.md §10.2. Absent: the 4-touch
    programs of the manual (measuring-math §8.2)."""
    out: dict[str, Any] = {}
    n = params.get("points")
    if n is not None:
        n = int(n) if isinstance(n, str) and n.strip().isdigit() else n       # typed on a screen
        if isinstance(n, bool) or not isinstance(n, int) or not MIN_CIRCLE_POINTS <= n <= MAX_CIRCLE_POINTS:
            raise ParamError("points", f"points must be a whole number {MIN_CIRCLE_POINTS}..{MAX_CIRCLE_POINTS} "
                             f"(touches on each circle), got {params['points']!r}")
        out["points"] = n
    angles = params.get("angles")
    if angles is not None:
        _check_circle_angles(angles)
        if "points" in out and out["points"] != len(angles):
            raise ParamError("points", f"points = {out['points']} but {len(angles)} angles are given")
        out["angles"] = [float(a) for a in angles]
        out["points"] = len(angles)
    return out


def _check_circle_angles(angles: Any) -> None:
    """A list of MIN..MAX finite numbers (deg), at least 1° apart, no gap of 180° or more."""
    if not isinstance(angles, list) or not MIN_CIRCLE_POINTS <= len(angles) <= MAX_CIRCLE_POINTS or any(
            isinstance(a, bool) or not isinstance(a, int | float) or not math.isfinite(a) for a in angles):
        raise ParamError("angles", f"angles must be a list of {MIN_CIRCLE_POINTS}..{MAX_CIRCLE_POINTS} numbers "
                         "(degrees)")
    spread = sorted(float(a) % 360.0 for a in angles)
    gaps = [b - a for a, b in zip(spread, [*spread[1:], spread[0] + 360.0], strict=True)]
    if min(gaps) < 1.0 or max(gaps) >= 180.0:
        raise ParamError("angles", "angles must differ by at least 1° and leave no gap of 180° or more "
                         "(the circle would not be determined)")


def validate_circles(spigot: bool) -> ParamsValidator:
    """1..4 holes (``spigot`` False) or circular spigots (jog-measuring §2.7, jog-measuring §2.8); ``variant`` = count."""
    def validate(variant: str, params: dict[str, Any], plane: Plane) -> dict[str, Any]:
        out: dict[str, Any] = {"diameter": param_positive(params, "diameter", required=spigot, bound=MAX_MAGNITUDE)}  # hole: may be empty
        if spigot:
            out["infeed"] = param_positive(params, "infeed", required=True, bound=MAX_MAGNITUDE)
        out["probe_angle"] = param_number(params, "probe_angle", 0.0, bound=MAX_MAGNITUDE) or 0.0
        if variant in ("2", "3", "4"):
            out["angle_correction"] = _angle_correction(params, variant != "2",
                                                        "rotation" if variant == "2" else "none")
            out["setpoint_angle"] = _setpoint_angle(params)
        if variant == "2":
            set_p1 = params.get("set_p1", False)
            if not isinstance(set_p1, bool):
                raise ParamError("set_p1", f"set_p1 must be true or false, got {set_p1!r}")
            out["set_p1"] = set_p1
        out["setpoint"] = _setpoint_point(params, plane)
        out.update(circle_touches(params))
        return _passthrough_target(params, out)
    return validate


def validate_plane(variant: str, params: dict[str, Any], plane: Plane) -> dict[str, Any]:
    """Orient plane (jog-measuring §2.9): no parameters besides the target."""
    return _passthrough_target(params, {})


def validate_probe_length(variant: str, params: dict[str, Any], plane: Plane) -> dict[str, Any]:
    """Calibrate length (jog-measuring §5.2): the surface on the infeed axis."""
    return _passthrough_target(params, {"setpoint": _setpoint_axis(params, plane.infeed)})


def validate_probe_radius(variant: str, params: dict[str, Any], plane: Plane) -> dict[str, Any]:
    """Calibrate radius (jog-measuring §5.3): the ring gauge's diameter; optionally the number of probing
    directions per pass and the offset of off-centre chords (engine.plan_workpiece.ring_program)."""
    out: dict[str, Any] = {"diameter": param_positive(params, "diameter", required=True, bound=MAX_MAGNITUDE)}
    if params.get("points") not in (None, ""):            # design.md §10.2: the touches per pass
        if params.get("directions") not in (None, "", params["points"]):
            raise ParamError("points", "give points or directions, not both")
        params = {**params, "directions": params["points"]}
    if params.get("directions") not in (None, ""):
        n = param_number(params, "directions", required=True, bound=MAX_MAGNITUDE)     # given: never None
        if n != int(n) or not 4 <= n <= 36:
            raise ParamError("directions", f"directions must be a whole number 4..36, got {params['directions']!r}")
        out["directions"] = int(n)
    if params.get("chord_offset") not in (None, ""):
        h = param_number(params, "chord_offset", required=True, bound=MAX_MAGNITUDE)   # given: never None
        if h < 0.0 or h >= 0.45 * out["diameter"]:
            raise ParamError("chord_offset", f"chord_offset must lie in [0, {0.45 * out['diameter']:g}) mm")
        out["chord_offset"] = h
    return _passthrough_target(params, out)


def validate_toolprobe(variant: str, params: dict[str, Any], plane: Plane) -> dict[str, Any]:
    """Calibrate the tool probe (jog-measuring §7.2)."""
    return _passthrough_target(params, {"mode": param_choice(params, "mode", ("length", "length_diameter"),
                                                        "length")})


def validate_tool(variant: str, params: dict[str, Any], plane: Plane) -> dict[str, Any]:
    """Tool length / diameter (jog-measuring §7.3): offset V and geometry or wear (_JM_B[0])."""
    value = param_number(params, "offset_v", 0.0, bound=MAX_MAGNITUDE) or 0.0
    if value < 0.0:
        raise ParamError("offset_v", f"offset_v must be >= 0, got {value:g}")
    out: dict[str, Any] = {"offset_v": value,
                 "compensation": param_choice(params, "compensation", ("geometry", "wear"), "geometry")}
    return _passthrough_target(params, out)

"""Typed text of a measuring screen <-> API params (spec/jog-measuring.md §2.3, design.md §4).

The fields themselves are declared per task in ``app.workflow.forms`` (named by the task
registry); validation is the engine's. This module only turns typed text into API params and
back, and puts the workflow's messages next to the field they name. Lengths (unit "mm") are
typed and shown in the screen's unit (``app.web.units``); the params are always mm.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from app.web import units
from app.web.texts import label_text, translate_message
from app.workflow.forms import LATHE_TOOL_TARGET, TOOL_TARGET, FieldSpec, number_text
from app.workflow.tasks import Category, TaskSpec


@dataclass
class FormData:
    """Typed text per field, the API params made from it, and errors per field name."""

    values: dict[str, str]
    params: dict
    target: str | dict | None                 # a dict: the tool target's fields (tool offsets)
    errors: dict[str, str] = field(default_factory=dict)


def _mm_default(spec: FieldSpec) -> float | None:
    """The default of a length field as mm (defaults are written in mm)."""
    if spec.unit != "mm" or spec.default == "":
        return None
    try:
        return float(spec.default)
    except ValueError:
        return None


def defaults(fields: list[FieldSpec], gud=None) -> dict[str, str]:
    """The fields' default text, lengths in the screen's unit."""
    out = {}
    for f in fields:
        mm = _mm_default(f) if gud is not None else None
        out[f.name] = units.field_text(mm, gud) if mm is not None else f.default
    return out


def _number_value(spec: FieldSpec, text: str, gud, known: dict):
    """Typed text of a number field -> the param: a length in mm (from the screen's unit), another
    number as it is; text that is no number is passed on for the workflow to name the field."""
    try:
        if spec.unit == "mm" and gud is not None:
            for candidate in (known.get(spec.name), _mm_default(spec)):
                if candidate is not None and text in units.shown_texts(candidate, gud):
                    return float(candidate)
            return units.parse_length(text, gud)
        return units.parse_number(text)
    except units.NumberError:
        return text.replace(",", ".")


def form_data(task: TaskSpec, fields: list[FieldSpec], form: dict | None, gud=None,
              known: dict | None = None) -> FormData:
    """API params from the typed text; empty numbers are left out (the workflow's defaults apply).
    ``known``: mm values the fields showed (a session's params), kept exactly when not edited."""
    values = defaults(fields, gud)
    known = known or {}
    if form:
        values.update({f.name: str(form[f.name]).strip() for f in fields if f.name in form})
    if getattr(task, "lathe", False):
        return _lathe_form_data(fields, values, gud)
    params: dict = {}
    target: str | dict | None = None
    tool: dict = {}
    tolerance: dict = {}
    for spec in fields:
        text = values.get(spec.name, "")
        if spec.name == "target":
            target = text or None
        elif spec.group == "tool":          # the tool offset's fields (design.md §9.3 target object)
            _tool_field(spec, text, gud, known, tool, tolerance)
        else:
            _param_field(spec, text, gud, known, params)
    if task.category == Category.TOOL_MEASURING and gud is not None:
        params["compensation"] = gud.tool_offset_mode     # _JM_B[0], shown read-only
    if target == TOOL_TARGET:
        target = tool                                     # the workflow names a missing or bad tool
        params["tolerance"] = tolerance
    return FormData(values=values, params=params, target=target)


def _tool_field(spec: FieldSpec, text: str, gud, known: dict, tool: dict, tolerance: dict) -> None:
    """A typed tool-offset field into the tool target (``tool_target.*``) or its tolerance."""
    if text == "":
        return
    part, _sep, key = spec.name.partition(".")
    typed = _typed_value(key, text)
    if spec.unit == "mm" and isinstance(typed, float) and gud is not None:
        typed = _number_value(spec, text, gud, known)
    (tool if part == "tool_target" else tolerance)[key] = typed


def _param_field(spec: FieldSpec, text: str, gud, known: dict, params: dict) -> None:
    """A typed field into the API params (``setpoint.X`` into the setpoint object); an empty
    number is left out."""
    if spec.kind == "number":
        if text == "":
            return
        value: object = _number_value(spec, text, gud, known)
    elif spec.name == "set_p1":
        value = text == "yes"
    else:
        value = text
    if spec.name.startswith("setpoint."):
        params.setdefault("setpoint", {})[spec.name.split(".", 1)[1]] = value
    else:
        params[spec.name] = value


def _typed_value(key: str, text: str):
    """Typed text of a tool-offset field: yes/no, whole numbers, decimals (a comma is a point)."""
    if text in ("yes", "no"):
        return text == "yes"
    if key in ("tool", "k", "evnum"):
        return int(text) if text.lstrip("-").isdigit() else text
    if key in ("correct", "mode"):
        return text
    try:
        return float(text.replace(",", "."))
    except ValueError:
        return text


def known_values(fields: list[FieldSpec], params: dict) -> dict[str, float]:
    """The mm values of a session's params per length field (``setpoint.X`` included)."""
    out = {}
    for spec in fields:
        if spec.unit != "mm":
            continue
        if spec.name.startswith("setpoint"):
            value = _setpoint_value(spec.name, params.get("setpoint"))
        else:
            value = params.get(spec.name)
        if isinstance(value, int | float) and not isinstance(value, bool):
            out[spec.name] = float(value)
    return out


def values_from_params(fields: list[FieldSpec], params: dict, setpoints: bool = False, gud=None) -> dict[str, str]:
    """Text of the fields from a session's normalised params (``setpoints``: also the setpoint
    fields, e.g. to show a session again after a refresh); lengths in the screen's unit."""
    out = {}
    for spec in fields:
        if spec.name.startswith("setpoint"):
            if setpoints:
                value = _setpoint_value(spec.name, params.get("setpoint"))
                if value is not None:
                    out[spec.name] = _text(spec, value, gud)
            continue
        value = params.get(spec.name)
        if value is None:
            continue
        if isinstance(value, bool):
            out[spec.name] = "yes" if value else "no"
        elif isinstance(value, float):
            out[spec.name] = _text(spec, value, gud)
        else:
            out[spec.name] = str(value)
    return out


def _text(spec: FieldSpec, value: float, gud) -> str:
    if spec.unit == "mm" and gud is not None:
        return units.field_text(float(value), gud)
    return number_text(float(value))


def _setpoint_value(name: str, value) -> float | None:
    """``setpoint.X`` of {"X": ..}, or the single value of a one-axis setpoint field."""
    if isinstance(value, dict):
        axis = name.partition(".")[2]
        value = value.get(axis) if axis else (next(iter(value.values())) if len(value) == 1 else None)
    return None if value is None else float(value)


def field_of_error(fields: list[FieldSpec], name: str | None) -> str:
    """The screen field an API error names ("setpoint.X" on a one-axis setpoint is "setpoint")."""
    names = {f.name for f in fields}
    if name in names:
        return name
    if name and name.startswith("setpoint") and "setpoint" in names:
        return "setpoint"
    return "_form"


def friendly(fields: list[FieldSpec], field_name: str, message: str) -> str:
    """The workflow's message in the operator's words: the parameter key replaced by the field's
    label (``app.web.texts``), in the screen's language."""
    labels = {spec.name: label_text(spec.label) for spec in fields}

    def label_of(key: str) -> str | None:
        if key in labels:
            return str(labels[key])
        if key.startswith("setpoint") and "setpoint" in labels:
            return str(labels["setpoint"])
        if key.startswith("setpoint.") and f"setpoint.{key[9:]}" in labels:
            return str(labels[f"setpoint.{key[9:]}"])
        if key.startswith("tolerance.") or key.startswith("tool_target."):
            return None
        for prefix in ("tolerance.", "tool_target."):
            if prefix + key in labels:
                return str(labels[prefix + key])
        return None

    return translate_message(message, label_of)


# --- the lathe tasks (turning.md §10.2): nested params by dotted names, yes/no booleans ---------------

def _lathe_number(text: str):
    text = text.replace(",", ".")
    try:
        number = float(text)
    except ValueError:
        return text                                  # the engine names the field and the bad text
    return int(number) if number.is_integer() and "." not in text and "e" not in text.lower() else number


def _lathe_form_data(fields: list[FieldSpec], values: dict[str, str], gud=None) -> FormData:
    """The lathe task's params; ``target`` is one of them (a WO name, measure only, or the tool
    object from the ``target.*`` fields)."""
    params: dict = {}
    target_choice = values.get("target")
    for spec in fields:
        text = values.get(spec.name, "")
        if spec.name == "target" or text == "":
            continue
        if spec.group == "tool" and target_choice != LATHE_TOOL_TARGET:
            continue
        if spec.kind == "choice" and text in ("yes", "no") and {v for v, _ in spec.choices} == {"yes", "no"}:
            value: object = text == "yes"
        elif spec.kind == "number" and spec.unit == "mm" and gud is not None:
            value = _number_value(spec, text, gud, {})        # typed in the screen's unit, mm here
        elif spec.kind == "number" or spec.name == "groove.number":
            value = _lathe_number(text)
        else:
            value = text
        node = params
        *path, last = spec.name.split(".")
        for key in path:
            node = node.setdefault(key, {})
        node[last] = value
    if target_choice:
        params["target"] = params.get("target", {}) if target_choice == LATHE_TOOL_TARGET else target_choice
    return FormData(values=values, params=params, target=None)


def lathe_values_from_params(fields: list[FieldSpec], params: dict, gud=None) -> dict[str, str]:
    """The fields' text from a lathe session's params (a refresh or another tab shows them again)."""
    out: dict[str, str] = {}
    target = params.get("target")
    if isinstance(target, dict):
        out["target"] = LATHE_TOOL_TARGET
    elif target is not None:
        out["target"] = str(target)
    for spec in fields:
        if spec.name == "target":
            continue
        node: object = params
        for key in spec.name.split("."):
            node = node.get(key) if isinstance(node, dict) else None
            if node is None:
                break
        if node is None:
            continue
        if isinstance(node, bool):
            out[spec.name] = "yes" if node else "no"
        elif isinstance(node, float):
            out[spec.name] = _text(spec, node, gud)
        elif not isinstance(node, dict):
            out[spec.name] = str(node)
    return out

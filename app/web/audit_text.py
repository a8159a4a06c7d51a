"""The audit trail in the operator's words (issue 29 item 6): each change named as the screens name
the value, lengths in the screen's unit, angles in degrees, yes/no, numbers and times in the
operator's language, the item ("Workpiece probe 1", "Settings") and the source of the change.

The stored rows keep the raw before/after documents (the JSON API shows them unchanged); only the
screen reads them here.
"""

from __future__ import annotations

from app.gud import GudSettings
from app.i18n import N_, format_fixed, format_number, gettext
from app.web import texts, units

# what the screens never show: the wave-1 mirror of ``units``, bookkeeping of the records
HIDDEN = frozenset({"inch_display", "number", "t", "calibration_id"})
ROTARY = ("A", "B", "C")
ANGLE_PARTS = frozenset({"rot", "rotation", "angle", "setpoint_angle", "calibrated_spindle_angle", "skew"})
LENGTH_KEYS = frozenset({"length", "radius", "ball_diameter", "effective_diameter", "disc_diameter", "dz",
                         "cal_ring_diameter", "cal_height", "value", "offset_v", "diameter", "l1", "l2",
                         "trigger", "wear", "trans", "fine", "eccentricity", "repeatability", "two_sigma",
                         "range", "point", "center"})
NAMES = {
    # record fields the screens show under these names (besides texts.FIELD_NAMES)
    "calibrated_radius": N_("calibrated (radius)"), "calibrated_length": N_("calibrated (length)"),
    "calibrated_diameter": N_("calibrated (diameter)"), "calibrated_plane": N_("calibrated in plane"),
    "calibrated_planes": N_("calibrated in planes"), "calibrated_spindle_angle": N_("spindle angle at calibration"),
    "calibrated_directions": N_("calibrated directions"),
    "calibration_feed": N_("calibration feed"), "calibration_override": N_("calibration override"),
    "length_to_tip": N_("length to the ball's tip"), "valid": N_("calibration valid"),
    "invalid_reason": N_("why invalid"), "cal_ring_diameter": N_("calibration ring diameter"),
    "calibration_tool": N_("calibration tool"), "value": N_("value"), "position": N_("position"),
    "guard": N_("start guard"), "password": N_("password"), "level": N_("access level"),
    "reset_data": N_("stored data reset"), "seed": N_("noise seed"), "eccentricity": N_("eccentricity"),
    "repeatability": N_("repeatability"),
}
ITEMS = {"settings": N_("Settings"), "kinematics": N_("Kinematics (machine data)"), "scenario": N_("Scenario"),
         "keyswitch": N_("Keyswitch")}


def item_text(entry: dict) -> str:
    """What was changed: "G54", "T1", "Workpiece probe 1", "Tool probe 1", "Settings", "EV 10"."""
    kind, name = entry.get("kind"), str(entry.get("offset") or "")
    if kind == "probe" and name.startswith("WP"):
        return gettext("Workpiece probe %(n)s", n=name[2:])
    if kind == "tool_probe" and name.startswith("TP"):
        return gettext("Tool probe %(n)s", n=name[2:])
    if kind == "memory":
        return name.upper()[:2] + " " + name[2:]
    if kind == "user":
        return gettext("User %(name)s", name=name)
    if kind == "token":
        return gettext("API token %(name)s", name=name)
    if kind == "guard":
        return gettext("Start guard of %(task)s", task=name)
    return gettext(ITEMS[name]) if name in ITEMS else name


def value_name(kind: str | None, key: str) -> str:
    """The operator's name of a changed value (``trans.X``, ``calibrated_radius``, ``units``)."""
    if kind == "settings":
        field = GudSettings.model_fields.get(key)
        if field is not None and field.description:
            return gettext(field.description)
    if key in NAMES:
        return gettext(NAMES[key])
    named = texts.field_name(key)
    if named != key:
        return named
    part, _, rest = key.partition(".")
    if part in NAMES:
        return f"{gettext(NAMES[part])} {rest}".strip()
    return key.replace("_", " ")


def _is_angle(key: str) -> bool:
    parts = key.split(".")
    return parts[0] in ANGLE_PARTS or parts[-1] in ROTARY or key.endswith("angle")


def _is_length(key: str) -> bool:
    return key.split(".")[0] in LENGTH_KEYS


def value_text(key: str, value, gud) -> str:
    """A stored value as the screens show it."""
    if value is None or value == "" or value == [] or value == {}:
        return "–"
    if isinstance(value, bool):
        return gettext("yes") if value else gettext("no")
    if isinstance(value, int | float):
        if _is_angle(key):
            return f"{format_fixed(float(value), 4)}°"
        if _is_length(key):
            return f"{units.format_length(float(value), gud)} {units.unit(gud)}"
        if key.endswith("override"):
            return f"{format_number(float(value))} %"
        if key.endswith("feed"):
            return f"{units.format_feed(float(value), gud)} {units.unit(gud, 'mm/min')}"
        return format_number(round(float(value), 6)) if isinstance(value, float) else str(value)
    if isinstance(value, list | tuple):
        return ", ".join(value_text(key, v, gud) for v in value)
    return gettext(str(value)) if str(value) in ("mm", "inch") else str(value)


def changes(kind: str | None, before, after, gud, prefix: str = "") -> list[dict]:
    """``{"name", "before", "after", "key"}`` for every shown value that differs."""
    if isinstance(before, dict) or isinstance(after, dict):
        before = before if isinstance(before, dict) else {}
        after = after if isinstance(after, dict) else {}
        out: list[dict] = []
        for key in dict.fromkeys([*before, *after]):
            if prefix == "" and key in HIDDEN:
                continue
            out += changes(kind, before.get(key), after.get(key), gud, f"{prefix}{key}.")
        return out
    key = prefix.rstrip(".")
    if before == after or (before in (None, [], {}, "") and after in (None, [], {}, "")):
        return []
    return [{"key": key, "name": value_name(kind, key), "before": value_text(key, before, gud),
             "after": value_text(key, after, gud)}]


def who_text(entry: dict) -> str:
    who = entry.get("who") or "–"
    if who == "trainer":
        who = gettext("Trainer")
    if entry.get("level") is not None:
        return gettext("%(who)s (level %(level)s)", who=who, level=entry["level"])
    return who


def audit_rows(entries: list[dict], gud) -> list[dict]:
    """The rows of the audit and history screens."""
    rows = []
    for e in entries:
        shown = changes(e.get("kind"), e.get("before"), e.get("after"), gud)
        rows.append({**e, "item": item_text(e), "changes": shown, "who_text": who_text(e),
                     "source_text": texts.source_text(e.get("source"))})
    return rows

"""What the JogMeasure nodes show (design.md §9.7), as plain data: {browse path: (value, type)}.

A path is the tuple of browse names below ``Objects/JogMeasure``; the values are those of the JSON
API (``GET /api/machine``, ``GET /api/offsets``, ``GET /api/log``), so a client reads over OPC UA
exactly what it reads over HTTP.
"""

from __future__ import annotations

import json

from asyncua import ua

from engine.frames import GEOMETRY_AXES

Path = tuple[str, ...]
Values = dict[Path, tuple[object, ua.VariantType]]

DOUBLE, STRING, BOOLEAN, INT32 = ua.VariantType.Double, ua.VariantType.String, ua.VariantType.Boolean, ua.VariantType.Int32
PARTS = {"Trans": "trans", "Fine": "fine", "Rot": "rot"}          # browse name -> frame component
ROOT = "JogMeasure"


def machine_values(status: dict) -> Values:
    """``Machine/...`` from the ``GET /api/machine`` body."""
    values: Values = {}
    for coords, key in (("MCS", "mcs"), ("WCS", "wcs")):
        for axis, position in status[key].items():
            values[("Machine", coords, axis)] = (float(position), DOUBLE)
    values[("Machine", "ActiveOffset")] = (status["active_offset"], STRING)
    values[("Machine", "Alarms")] = (json.dumps(status["alarms"]), STRING)
    values[("Machine", "Mode")] = (status["mode"] or "", STRING)
    values[("Machine", "ProgramState")] = (status["program_state"], STRING)
    values[("Machine", "Busy")] = (bool(status["busy"]), BOOLEAN)
    values[("Machine", "Tool")] = (int(status["tool"] or 0), INT32)
    values[("Machine", "ToolLength")] = (float(status["tool_length"]), DOUBLE)
    values[("Machine", "FeedOverride")] = (float(status["feed_override"]), DOUBLE)
    return values


def offset_axes(rotary_axes: tuple[str, ...]) -> dict[str, tuple[str, ...]]:
    """The axes of each frame component, as the offsets service allows them."""
    return {"Trans": GEOMETRY_AXES + tuple(rotary_axes), "Fine": GEOMETRY_AXES, "Rot": GEOMETRY_AXES}


def offset_values(offsets: dict[str, dict], rotary_axes: tuple[str, ...]) -> Values:
    """``ZeroOffsets/<name>/Trans|Fine|Rot/<axis>`` from ``GET /api/offsets`` (a component the
    stored frame lacks is 0, as the NC reads it)."""
    values: Values = {}
    axes = offset_axes(rotary_axes)
    for name, frame in offsets.items():
        for part, key in PARTS.items():
            stored = frame.get(key) or {}
            for axis in axes[part]:
                values[("ZeroOffsets", name, part, axis)] = (float(stored.get(axis, 0.0)), DOUBLE)
    return values


def offset_target(path: Path) -> tuple[str, str, str] | None:
    """(offset name, frame component, axis) of a writable ``ZeroOffsets`` leaf, else None."""
    if len(path) == 4 and path[0] == "ZeroOffsets" and path[2] in PARTS:
        return path[1], PARTS[path[2]], path[3]
    return None


def measurement_value(newest: dict | None) -> Values:
    """``LastMeasurement``: the newest log entry as JSON (``null`` before the first)."""
    return {("LastMeasurement",): (json.dumps(newest), STRING)}


def alarm_keys(status: dict) -> set[tuple[int, str]]:
    return {(int(a["code"]), str(a["text"])) for a in status["alarms"]}

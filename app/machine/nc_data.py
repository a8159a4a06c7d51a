"""The simulated NC's copy of the named zero offsets and the tool data the HMI writes.

A real control holds these (design.md, Standards); the simulator keeps them as written so that
what the HMI stored is also what the NC holds. Motion and display use the active frame
(``activate_frame``) and the offset length of ``change_tool``, not these copies. Shapes are
checked like a control's data interface would: a ValueError names the bad field.
"""

from __future__ import annotations

import copy

from engine.checks import real

from .scenario import GEOMETRY_AXES

FRAME_PARTS = ("trans", "fine", "rot")
TOOL_KEYS = ("type", "length", "radius", "wear")
WEAR_KEYS = ("length", "radius")


def _object(value, field: str, allowed) -> dict:
    if not isinstance(value, dict):
        raise ValueError(f"{field}: must be an object, got {type(value).__name__}")
    unknown = sorted(str(k) for k in value if k not in allowed)
    if unknown:
        prefix = f"{field}." if field else ""
        raise ValueError(f"{prefix}{unknown[0]}: unknown field (allowed: {', '.join(allowed)})")
    return value


class NcData:
    """Named frames ``{"trans", "fine", "rot"}`` and tool data ``{"type", "length", "radius", "wear"}``."""

    def __init__(self, axes: tuple[str, ...]) -> None:
        self._axes = tuple(axes)
        self._offsets: dict[str, dict] = {}
        self._tools: dict[int, dict] = {}

    @property
    def offsets(self) -> dict[str, dict]:
        """What the NC holds, as copies."""
        return copy.deepcopy(self._offsets)

    @property
    def tools(self) -> dict[int, dict]:
        return copy.deepcopy(self._tools)

    def write_offset(self, name: str, frame: dict) -> None:
        if not isinstance(name, str) or not name:
            raise ValueError(f"name: a zero offset needs a name, got {name!r}")
        _object(frame, "frame", FRAME_PARTS)
        allowed = {"trans": self._axes, "fine": GEOMETRY_AXES, "rot": GEOMETRY_AXES}
        checked = {}
        for part in FRAME_PARTS:
            values = _object(frame.get(part) or {}, part, allowed[part])
            checked[part] = {axis: real(f"{part}.{axis}", v) for axis, v in values.items()}
        self._offsets[name] = checked

    def write_tool(self, t: int, data: dict) -> None:
        if isinstance(t, bool) or not isinstance(t, int) or t < 1:
            raise ValueError(f"t: a tool number is an integer >= 1, got {t!r}")
        _object(data, "tool", TOOL_KEYS)
        missing = [k for k in TOOL_KEYS[:3] if k not in data]
        if missing:
            raise ValueError(f"{missing[0]}: missing in the tool data of T{t}")
        tool_type = data["type"]
        if isinstance(tool_type, bool) or not isinstance(tool_type, int):
            raise ValueError(f"type: must be an integer tool type, got {tool_type!r}")
        wear = _object(data.get("wear") or {}, "wear", WEAR_KEYS)
        self._tools[t] = {"type": tool_type, "length": real("length", data["length"]),
                          "radius": real("radius", data["radius"]),
                          "wear": {k: real(f"wear.{k}", wear.get(k, 0.0)) for k in WEAR_KEYS}}

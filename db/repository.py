"""The unit of work: every read and write of the app's persistent data, as JSON-ready dicts.

A ``Unit`` lives inside one transaction (``Database.unit()``); it never commits itself, so
everything it writes in one ``with`` block is stored together or not at all.
"""

from __future__ import annotations

import copy
import json
import math
from collections.abc import Iterable
from dataclasses import dataclass
from datetime import UTC, datetime
from typing import Any

from sqlalchemy import select
from sqlalchemy.orm import Session

from db.models import (
    AXES,
    GEOMETRY_AXES,
    MAX_PROBE_NUMBER,
    ROTARY_AXES,
    FrameAxis,
    MachineState,
    MeasurementLog,
    OffsetAudit,
    Probe,
    Setting,
    Tool,
    ToolProbe,
)

CHANNEL = 1
DEFAULT_PROBE_RECORDS = 3        # _CVAL[0], _CVAL[1]: 3 records each by default
MAX_EXTRA_SETTABLE = 95          # G505..G599
LOG_FIELDS = ("task", "params", "raw", "points", "result", "correction", "probe", "target", "status",
              "measuring_wo", "warnings")
TOOL_FIELDS = ("t", "name", "type", "length", "radius", "wear")
DEFAULT_TOOL = {"name": None, "type": 120, "length": 0.0, "radius": 0.0, "wear": {"length": 0.0, "radius": 0.0}}


@dataclass(frozen=True)
class OffsetSlot:
    """A frame of the chain: API name, kind (spec §4.5) and index (G54 -> 1, G505 -> 5)."""

    name: str
    kind: str
    index: int


def offset_layout(extra_settable: int, basic_frames: int) -> tuple[OffsetSlot, ...]:
    """The configured frames in chain order, outside in: BASIC_REF, BASIC_0.., G54..G57, G505.."""
    if not 0 <= extra_settable <= MAX_EXTRA_SETTABLE:
        raise ValueError(f"extra_settable must be 0..{MAX_EXTRA_SETTABLE}, got {extra_settable}")
    if not 0 <= basic_frames <= 16:
        raise ValueError(f"basic_frames must be 0..16, got {basic_frames}")
    basic = [OffsetSlot(f"BASIC_{i}", "chbasic", i) for i in range(basic_frames)]
    settable = [OffsetSlot(f"G{53 + i}", "settable", i) for i in range(1, 5)]
    settable += [OffsetSlot(f"G{500 + i}", "settable", i) for i in range(5, 5 + extra_settable)]
    return (OffsetSlot("BASIC_REF", "setframe", 0), *basic, *settable)


def identity_frame(rotary_axes: Iterable[str] = ()) -> dict:
    return {
        "trans": {axis: 0.0 for axis in (*GEOMETRY_AXES, *rotary_axes)},
        "fine": dict.fromkeys(GEOMETRY_AXES, 0.0),
        "rot": dict.fromkeys(GEOMETRY_AXES, 0.0),
    }


def seed_defaults(session: Session, layout: Iterable[OffsetSlot], rotary_axes: Iterable[str]) -> None:
    """Adds what is missing (identity frames, empty probe records); never changes stored data."""
    rotary_axes = tuple(rotary_axes)
    unknown = set(rotary_axes) - set(ROTARY_AXES)
    if unknown:
        raise ValueError(f"unknown rotary axes {sorted(unknown)}")
    present = set(session.execute(select(FrameAxis.name, FrameAxis.axis).where(FrameAxis.channel == CHANNEL)))
    for slot in layout:
        for axis in (*GEOMETRY_AXES, *rotary_axes):
            if (slot.name, axis) not in present:
                session.add(_new_frame_axis(slot, axis))
    for model in (Probe, ToolProbe):
        numbers = set(session.scalars(select(model.number)))
        for number in range(1, DEFAULT_PROBE_RECORDS + 1):
            if number not in numbers:
                session.add(model(number=number, calibrated_at=None, data={"number": number}))


class Unit:
    """Repository methods of one transaction; all take and return plain JSON-ready values."""

    def __init__(self, session: Session, layout: tuple[OffsetSlot, ...]):
        self._session: Session = session
        self._slots = {slot.name: slot for slot in layout}

    def detach(self) -> None:
        """Called when the transaction ends: later use fails loudly instead of writing nowhere."""
        self._session = _EndedTransaction()  # type: ignore[assignment]

    # --- zero offsets / frames ---------------------------------------------------------

    def offset_names(self) -> list[str]:
        return list(self._slots)

    def list_offsets(self) -> dict[str, dict]:
        rows = self._session.scalars(
            select(FrameAxis).where(FrameAxis.channel == CHANNEL, FrameAxis.name.in_(self._slots))
        )
        by_name: dict[str, list[FrameAxis]] = {name: [] for name in self._slots}
        for row in rows:
            by_name[row.name].append(row)
        return {name: _frame_from_rows(axis_rows) for name, axis_rows in by_name.items()}

    def get_offset(self, name: str) -> dict | None:
        if name not in self._slots:
            return None
        return _frame_from_rows(self._frame_rows(name).values())

    def put_offset(self, name: str, frame: dict, source: str, detail: dict | None = None) -> tuple[dict, dict]:
        """Replaces the whole frame (components not given become 0) and records the change.

        Returns (before, after). KeyError for a name that is not a configured offset,
        ValueError for a malformed frame.
        """
        slot = self._slots.get(name)
        if slot is None:
            raise KeyError(name)
        values = _parse_frame(frame)
        rows = self._frame_rows(name)
        before = _frame_from_rows(rows.values())
        for axis in AXES:
            if axis not in values and axis not in rows:
                continue
            row = rows.get(axis)
            if row is None:
                row = rows[axis] = _new_frame_axis(slot, axis)
                self._session.add(row)
            row.coarse, row.fine, row.rot = values.get(axis, (0.0, 0.0, 0.0 if axis in GEOMETRY_AXES else None))
        after = _frame_from_rows(rows.values())
        self._session.add(OffsetAudit(
            time=_utc_now(), offset=name, before=before, after=after, source=str(source),
            detail=_json_ready(detail, "detail"),
        ))
        self._session.flush()
        return copy.deepcopy(before), copy.deepcopy(after)

    def audit(self, limit: int = 200, name: str | None = None) -> list[dict]:
        """Offset changes, newest first."""
        query = select(OffsetAudit).order_by(OffsetAudit.id.desc()).limit(limit)
        if name is not None:
            query = query.where(OffsetAudit.offset == name)
        return [
            copy.deepcopy({"id": row.id, "time": row.time, "offset": row.offset, "before": row.before,
                           "after": row.after, "source": row.source, "detail": row.detail})
            for row in self._session.scalars(query)
        ]

    def _frame_rows(self, name: str) -> dict[str, FrameAxis]:
        rows = self._session.scalars(
            select(FrameAxis).where(FrameAxis.channel == CHANNEL, FrameAxis.name == name)
        )
        return {row.axis: row for row in rows}

    # --- tools ---------------------------------------------------------------------------

    def list_tools(self) -> list[dict]:
        return [_tool_dict(row) for row in self._session.scalars(select(Tool).order_by(Tool.t))]

    def get_tool(self, t: int) -> dict | None:
        row = self._session.get(Tool, t)
        return None if row is None else _tool_dict(row)

    def put_tool(self, t: int, data: dict) -> dict:
        """Creates or updates tool ``t``; fields not given keep their value (or the default)."""
        t = _positive_int(t, "t")
        _check_keys(data, TOOL_FIELDS, "tool")
        if "t" in data and data["t"] != t:
            raise ValueError(f"tool data says t={data['t']!r} but is stored as T{t}")
        row = self._session.get(Tool, t)
        current = DEFAULT_TOOL if row is None else _tool_dict(row)
        wear = data.get("wear", {})
        _check_keys(wear, ("length", "radius"), "tool wear")
        name = data.get("name", current["name"])
        if name is not None and not isinstance(name, str):
            raise ValueError("tool name must be a string or null")
        if row is None:
            row = Tool(t=t)
            self._session.add(row)
        row.name = name
        row.type = _int(data.get("type", current["type"]), "type")
        row.length = _finite(data.get("length", current["length"]), "length")
        row.radius = _finite(data.get("radius", current["radius"]), "radius")
        row.wear_length = _finite(wear.get("length", current["wear"]["length"]), "wear.length")
        row.wear_radius = _finite(wear.get("radius", current["wear"]["radius"]), "wear.radius")
        self._session.flush()
        return _tool_dict(row)

    def delete_tool(self, t: int) -> None:
        """KeyError when there is no tool ``t``."""
        row = self._session.get(Tool, t)
        if row is None:
            raise KeyError(t)
        self._session.delete(row)
        self._session.flush()

    # --- workpiece probe (_WP) and tool probe (_TP) records ------------------------------

    def get_probe(self, n: int) -> dict | None:
        return self._get_record(Probe, n)

    def put_probe(self, n: int, data: dict) -> dict:
        return self._put_record(Probe, n, data)

    def list_probes(self) -> list[dict]:
        return self._list_records(Probe)

    def get_tool_probe(self, n: int) -> dict | None:
        return self._get_record(ToolProbe, n)

    def put_tool_probe(self, n: int, data: dict) -> dict:
        return self._put_record(ToolProbe, n, data)

    def list_tool_probes(self) -> list[dict]:
        return self._list_records(ToolProbe)

    def _get_record(self, model: type[Probe] | type[ToolProbe], n: int) -> dict | None:
        row = self._session.get(model, n)
        return None if row is None else copy.deepcopy(row.data)

    def _put_record(self, model: type[Probe] | type[ToolProbe], n: int, data: dict) -> dict:
        """Replaces the record's document; ``number`` is set to n, ``calibrated_at`` indexed."""
        n = _positive_int(n, "probe number")
        if n > MAX_PROBE_NUMBER:
            raise ValueError(f"probe number must be 1..{MAX_PROBE_NUMBER}, got {n}")
        if not isinstance(data, dict):
            raise ValueError("probe data must be an object")
        document = _json_ready({**data, "number": n}, "probe data")
        calibrated_at = document.get("calibrated_at")
        if calibrated_at is not None and not isinstance(calibrated_at, str):
            raise ValueError("calibrated_at must be an ISO time string or null")
        row = self._session.get(model, n)
        if row is None:
            row = model(number=n)
            self._session.add(row)
        row.data, row.calibrated_at = document, calibrated_at
        self._session.flush()
        return copy.deepcopy(document)

    def _list_records(self, model: type[Probe] | type[ToolProbe]) -> list[dict]:
        return [copy.deepcopy(row.data) for row in self._session.scalars(select(model).order_by(model.number))]

    # --- settings and machine state (key -> JSON value) ---------------------------------

    def get_settings(self) -> dict:
        rows = self._session.scalars(select(Setting).order_by(Setting.key))
        return {row.key: copy.deepcopy(row.value) for row in rows}

    def put_settings(self, values: dict) -> dict:
        """Merges ``values`` into the stored settings; returns all settings."""
        if not isinstance(values, dict) or not all(isinstance(key, str) for key in values):
            raise ValueError("settings must be an object with string keys")
        for key, value in values.items():
            self._upsert(Setting, key, value)
        self._session.flush()
        return self.get_settings()

    def get_state(self, key: str, default: Any = None) -> Any:
        row = self._session.get(MachineState, key)
        return default if row is None else copy.deepcopy(row.value)

    def set_state(self, key: str, value: Any) -> None:
        self._upsert(MachineState, key, value)
        self._session.flush()

    def _upsert(self, model: type[Setting] | type[MachineState], key: str, value: Any) -> None:
        value = _json_ready(value, key)
        row = self._session.get(model, key)
        if row is None:
            self._session.add(model(key=key, value=value))
        else:
            row.value = value

    # --- measurement log -----------------------------------------------------------------

    def add_log(self, entry: dict) -> int:
        _check_keys(entry, LOG_FIELDS, "log entry")
        if not isinstance(entry.get("task"), str):
            raise ValueError("log entry needs a task name")
        row = MeasurementLog(time=_utc_now(), **{key: _json_ready(entry.get(key), key) for key in LOG_FIELDS})
        self._session.add(row)
        self._session.flush()
        return row.id

    def list_log(self, limit: int = 500) -> list[dict]:
        """Newest first."""
        query = select(MeasurementLog).order_by(MeasurementLog.id.desc()).limit(limit)
        return [_log_dict(row) for row in self._session.scalars(query)]

    def get_log(self, log_id: int) -> dict | None:
        row = self._session.get(MeasurementLog, log_id)
        return None if row is None else _log_dict(row)


class _EndedTransaction:
    def __getattr__(self, name: str) -> Any:
        raise RuntimeError("this Unit's transaction has ended; open a new one with Database.unit()")


# --- row <-> dict helpers -------------------------------------------------------------------

def _new_frame_axis(slot: OffsetSlot, axis: str) -> FrameAxis:
    return FrameAxis(
        channel=CHANNEL, name=slot.name, kind=slot.kind, frame_index=slot.index, axis=axis,
        coarse=0.0, fine=0.0, rot=0.0 if axis in GEOMETRY_AXES else None, mirror=False, scale=1.0,
    )


def _frame_from_rows(rows: Iterable[FrameAxis]) -> dict:
    by_axis = {row.axis: row for row in rows}
    frame = identity_frame()
    for axis in AXES:
        row = by_axis.get(axis)
        if row is None:
            continue
        frame["trans"][axis] = row.coarse
        if axis in GEOMETRY_AXES:
            frame["fine"][axis] = row.fine
            frame["rot"][axis] = row.rot if row.rot is not None else 0.0
    return frame


def _parse_frame(frame: dict) -> dict[str, tuple[float, float, float | None]]:
    """Frame dict -> {axis: (coarse, fine, rot)}; rot is None for rotary axes."""
    if not isinstance(frame, dict):
        raise ValueError("a frame must be an object with trans, fine, rot")
    _check_keys(frame, ("trans", "fine", "rot"), "frame")
    parts = {}
    for part, allowed in (("trans", AXES), ("fine", GEOMETRY_AXES), ("rot", GEOMETRY_AXES)):
        components = frame.get(part) or {}
        if not isinstance(components, dict):
            raise ValueError(f"frame {part} must be an object keyed by axis")
        _check_keys(components, allowed, f"frame {part}")
        parts[part] = {axis: _finite(value, f"{part}.{axis}") for axis, value in components.items()}
    values: dict[str, tuple[float, float, float | None]] = {
        axis: (parts["trans"].get(axis, 0.0), parts["fine"].get(axis, 0.0), parts["rot"].get(axis, 0.0))
        for axis in GEOMETRY_AXES
    }
    for axis, coarse in parts["trans"].items():
        if axis not in GEOMETRY_AXES:
            values[axis] = (coarse, 0.0, None)
    return values


def _tool_dict(row: Tool) -> dict:
    return {"t": row.t, "name": row.name, "type": row.type, "length": row.length, "radius": row.radius,
            "wear": {"length": row.wear_length, "radius": row.wear_radius}}


def _log_dict(row: MeasurementLog) -> dict:
    return {"id": row.id, "time": row.time, **{key: copy.deepcopy(getattr(row, key)) for key in LOG_FIELDS}}


def _utc_now() -> str:
    return datetime.now(UTC).isoformat(timespec="microseconds")


def _json_ready(value: Any, what: str) -> Any:
    """A deep copy of ``value`` as JSON gives it back (tuples -> lists); rejects NaN and objects."""
    try:
        return json.loads(json.dumps(value, allow_nan=False))
    except (TypeError, ValueError) as error:
        raise ValueError(f"{what} is not JSON-ready: {error}") from None


def _check_keys(data: Any, allowed: Iterable[str], what: str) -> None:
    if not isinstance(data, dict):
        raise ValueError(f"{what} must be an object")
    unknown = set(data) - set(allowed)
    if unknown:
        raise ValueError(f"unknown {what} keys {sorted(map(str, unknown))}")


def _finite(value: Any, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ValueError(f"{what} must be a finite number, got {value!r}")
    return float(value)


def _int(value: Any, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise ValueError(f"{what} must be an integer, got {value!r}")
    return value


def _positive_int(value: Any, what: str) -> int:
    value = _int(value, what)
    if value < 1:
        raise ValueError(f"{what} must be >= 1, got {value}")
    return value

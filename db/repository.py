"""The unit of work: every read and write of the app's persistent data, as JSON-ready dicts.

A ``Unit`` lives inside one transaction (``Database.unit()``); it never commits itself, so
everything it writes in one ``with`` block is stored together or not at all.
"""

from __future__ import annotations

import copy
import json
import math
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass
from datetime import UTC, datetime
from typing import Any, TypeVar, cast

from sqlalchemy import Insert, Row, Table, bindparam, delete, exists, func, insert, select, update
from sqlalchemy.orm import Session

from db.models import (
    AXES,
    GEOMETRY_AXES,
    MAX_PROBE_NUMBER,
    ROTARY_AXES,
    ApiToken,
    AuthSession,
    FrameAxis,
    Machine,
    MachineState,
    MeasurementLog,
    MemoryValue,
    OffsetAudit,
    Probe,
    Program,
    Setting,
    Tool,
    ToolProbe,
    User,
)
from db.parts import PartsUnit
from db.plant import PlantUnit
from db.probe_events import ProbeEventsUnit

CHANNEL = 1
DEFAULT_PROBE_RECORDS = 3        # _CVAL[0], _CVAL[1]: 3 records each by default
MAX_EXTRA_SETTABLE = 95          # G505..G599
LOG_FIELDS = ("task", "params", "raw", "points", "result", "correction", "probe", "target", "status",
              "measuring_wo", "warnings", "program", "block", "part_id", "calibration_id")
PROGRAM_TEXT_MAX = 200_000       # characters of one part program
TOOL_FIELDS = ("t", "name", "type", "length", "radius", "wear", "sl", "l1", "l2")
LATHE_TOOL_FIELDS = ("sl", "l1", "l2")          # lathe tools only (turning.md §10.2); None = not a lathe value
_Record = TypeVar("_Record", Probe, ToolProbe)              # the numbered JSON records
_KeyValue = TypeVar("_KeyValue", Setting, MachineState)      # the key -> JSON value tables

DEFAULT_TOOL: dict[str, Any] = {"name": None, "type": 120, "length": 0.0, "radius": 0.0, "wear": {"length": 0.0, "radius": 0.0}}


@dataclass(frozen=True)
class Actor:
    """Who writes: ``who`` as the audit shows it ("user:anna", "token:mes", "trainer", "panel",
    "cli") and the protection level it acted with (0 highest .. 7)."""

    who: str
    level: int | None = None


# The acting identity of the current request (or command): the app sets it per request; every
# audit row a unit writes names it. A ContextVar reaches the threads FastAPI runs endpoints in;
# code that starts its own thread carries it over with ``contextvars.copy_context()``.
_ACTOR: ContextVar[Actor | None] = ContextVar("hmi_actor", default=None)
SYSTEM = Actor("system")      # writes nobody asked for (seeding, start-up scenario)


def current_actor() -> Actor | None:
    return _ACTOR.get()


@contextmanager
def acting_as(actor: Actor | None) -> Iterator[None]:
    """Audit rows written inside the block name ``actor``."""
    token = _ACTOR.set(actor)
    try:
        yield
    finally:
        _ACTOR.reset(token)


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


def identity_frame(rotary_axes: Iterable[str] = ()) -> dict[str, Any]:
    return {
        "trans": {axis: 0.0 for axis in (*GEOMETRY_AXES, *rotary_axes)},
        "fine": dict.fromkeys(GEOMETRY_AXES, 0.0),
        "rot": dict.fromkeys(GEOMETRY_AXES, 0.0),
    }


def seed_defaults(session: Session, layout: Iterable[OffsetSlot], rotary_axes: Iterable[str], machine: str) -> None:
    """Adds what is missing of ``machine`` (its row in machines, identity frames, empty probe
    records); never changes stored data."""
    rotary_axes = tuple(rotary_axes)
    unknown = set(rotary_axes) - set(ROTARY_AXES)
    if unknown:
        raise ValueError(f"unknown rotary axes {sorted(unknown)}")
    now = utc_now()
    known = session.get(Machine, machine)
    if known is None:
        session.add(Machine(name=machine, registered=now, last_seen=now, writes=0))
    else:
        known.last_seen = now
    present = set(session.execute(select(FrameAxis.name, FrameAxis.axis)
                                  .where(FrameAxis.machine == machine, FrameAxis.channel == CHANNEL)))
    for slot in layout:
        for axis in (*GEOMETRY_AXES, *rotary_axes):
            if (slot.name, axis) not in present:
                session.add(_new_frame_axis(slot, axis, machine))
    for model in (Probe, ToolProbe):
        numbers = set(session.scalars(select(model.number).where(model.machine == machine)))
        for number in range(1, DEFAULT_PROBE_RECORDS + 1):
            if number not in numbers:
                session.add(model(machine=machine, number=number, calibrated_at=None, data={"number": number}))


class Unit(PartsUnit, PlantUnit, ProbeEventsUnit):
    """Repository methods of one transaction; all take and return plain JSON-ready values."""

    def __init__(self, session: Session, layout: tuple[OffsetSlot, ...], machine: str):
        self._session: Session = session
        self._slots = {slot.name: slot for slot in layout}
        self.machine = machine              # every machine-owned row read or written is this machine's

    def detach(self) -> None:
        """Called when the transaction ends: later use fails loudly instead of writing nowhere."""
        self._session = _EndedTransaction()  # type: ignore[assignment]

    def hold_write_lock(self) -> None:
        """Start the transaction now (a writing unit takes SQLite's write lock at BEGIN)."""
        self._session.connection()

    # --- zero offsets / frames ---------------------------------------------------------

    def offset_names(self) -> list[str]:
        return list(self._slots)

    def list_offsets(self) -> dict[str, dict[str, Any]]:
        # columns, not ORM objects: every measurement reads all frames (several times)
        rows = self._session.execute(
            select(FrameAxis.name, FrameAxis.axis, FrameAxis.coarse, FrameAxis.fine, FrameAxis.rot)
            .where(FrameAxis.machine == self.machine, FrameAxis.channel == CHANNEL,
                   FrameAxis.name.in_(self._slots))
        )
        by_name: dict[str, list[Row[str, str, float, float, float | None]]] = {name: [] for name in self._slots}
        for row in rows:
            by_name[row.name].append(row)
        return {name: _frame_from_rows(axis_rows) for name, axis_rows in by_name.items()}

    def get_offset(self, name: str) -> dict[str, Any] | None:
        if name not in self._slots:
            return None
        return _frame_from_rows(self._frame_rows(name).values())

    def put_offset(self, name: str, frame: dict[str, Any], source: str, detail: dict[str, Any] | None = None) -> tuple[dict[str, Any], dict[str, Any]]:
        """Replaces the whole frame (components not given become 0) and records the change.

        Returns (before, after). KeyError for a name that is not a configured offset,
        ValueError for a malformed frame.
        """
        slot = self._slots.get(name)
        if slot is None:
            raise KeyError(name)
        values = _parse_frame(frame)
        self._session.flush()                  # what the session holds is written first, in order
        connection = self._session.connection()
        rows = self._frame_rows(name)
        before = _frame_from_rows(rows.values())
        # prepared Core statements (issue 30), written as the ORM's unit of work wrote them: a
        # column keeps its stored value unless the new one differs (==), an unchanged row is not
        # written, a missing axis row is inserted with the defaults of _new_frame_axis
        for axis in AXES:
            if axis not in values and axis not in rows:
                continue
            coarse, fine, rot = values.get(axis, (0.0, 0.0, 0.0 if axis in GEOMETRY_AXES else None))
            row = rows.get(axis)
            if row is None:
                connection.execute(_FRAME_AXIS_INSERT, {
                    "machine": self.machine, "channel": CHANNEL, "name": slot.name, "kind": slot.kind,
                    "frame_index": slot.index, "axis": axis, "coarse": coarse, "fine": fine, "rot": rot,
                    "mirror": False, "scale": 1.0})
            elif coarse != row.coarse or fine != row.fine or rot != row.rot:
                coarse = coarse if coarse != row.coarse else row.coarse
                fine = fine if fine != row.fine else row.fine
                rot = rot if rot != row.rot else row.rot
                connection.execute(_FRAME_AXIS_UPDATE, {"row_id": row.id, "coarse": coarse, "fine": fine, "rot": rot})
            else:
                continue
            rows[axis] = _AxisValues(axis, coarse, fine, rot, row.id if row is not None else None)
        after = _frame_from_rows(rows.values())
        self.add_audit("offset", name, before, after, source, detail)
        return before, after

    # --- audit trail -----------------------------------------------------------------------

    def add_audit(self, kind: str, name: str, before: Any, after: Any, source: str,
                  detail: dict[str, Any] | None = None) -> int:
        """One audit row naming the acting identity (``current_actor()``, else "system")."""
        actor = current_actor() or SYSTEM
        return self._insert(_AUDIT_INSERT, {
            "machine": self.machine, "time": _utc_now(), "kind": kind, "offset": str(name),
            "before": _json_ready(before, "before"), "after": _json_ready(after, "after"), "source": str(source),
            "detail": _json_ready(detail, "detail"), "who": actor.who[:80], "who_level": actor.level})

    def _insert(self, statement: Insert, values: dict[str, Any]) -> int:
        """One row by a prepared INSERT (no unit-of-work bookkeeping for a row nobody changes
        afterwards in the transaction); what the session holds is written before it, in order."""
        self._session.flush()
        key = self._session.connection().execute(statement, values).inserted_primary_key
        assert key is not None                 # an INSERT of one row always has its key
        return int(key[0])

    def audit(self, limit: int = 200, name: str | None = None, kind: str | None = None,
              before_id: int | None = None) -> list[dict[str, Any]]:
        """Audit rows, newest first (``name``: one item, e.g. G54; ``kind``: one kind of data)."""
        query = (select(OffsetAudit).where(OffsetAudit.machine == self.machine)
                 .order_by(OffsetAudit.id.desc()).limit(limit))
        if name is not None:
            query = query.where(OffsetAudit.offset == name)
        if kind is not None:
            query = query.where(OffsetAudit.kind == kind)
        if before_id is not None:
            query = query.where(OffsetAudit.id < before_id)
        return [_audit_dict(row) for row in self._session.scalars(query)]

    def get_audit(self, audit_id: int) -> dict[str, Any] | None:
        row = self._session.get(OffsetAudit, audit_id)
        return None if row is None or row.machine != self.machine else _audit_dict(row)

    def _frame_rows(self, name: str) -> dict[str, Any]:
        """The stored axis rows of frame ``name`` as columns (no ORM objects: put_offset writes
        them by Core statements)."""
        rows = self._session.connection().execute(_FRAME_ROWS, {"machine": self.machine, "name": name})
        return {row.axis: row for row in rows}

    # --- tools ---------------------------------------------------------------------------

    def list_tools(self) -> list[dict[str, Any]]:
        query = select(Tool).where(Tool.machine == self.machine).order_by(Tool.t)
        return [_tool_dict(row) for row in self._session.scalars(query)]

    def _key(self, **key: Any) -> dict[str, Any]:
        """The primary key of a machine-owned row of this machine (``Session.get``)."""
        return {"machine": self.machine, **key}

    def get_tool(self, t: int) -> dict[str, Any] | None:
        row = self._session.get(Tool, self._key(t=t))
        return None if row is None else _tool_dict(row)

    def put_tool(self, t: int, data: dict[str, Any], source: str | None = None, detail: dict[str, Any] | None = None) -> dict[str, Any]:
        """Creates or updates tool ``t``; fields not given keep their value (or the default).
        With ``source`` the change is audited (kind "tool", item "T<t>")."""
        t = _positive_int(t, "t")
        before = self.get_tool(t)
        _check_keys(data, TOOL_FIELDS, "tool")
        if "t" in data and data["t"] != t:
            raise ValueError(f"tool data says t={data['t']!r} but is stored as T{t}")
        row = self._session.get(Tool, self._key(t=t))
        current = DEFAULT_TOOL if row is None else _tool_dict(row)
        wear = data.get("wear", {})
        _check_keys(wear, ("length", "radius", "l1", "l2"), "tool wear")
        name = data.get("name", current["name"])
        if name is not None and not isinstance(name, str):
            raise ValueError("tool name must be a string or null")
        if row is None:
            row = Tool(machine=self.machine, t=t)
            self._session.add(row)
        row.name = name
        row.type = _int(data.get("type", current["type"]), "type")
        row.length = _finite(data.get("length", current["length"]), "length")
        row.radius = _finite(data.get("radius", current["radius"]), "radius")
        row.wear_length = _finite(wear.get("length", current["wear"]["length"]), "wear.length")
        row.wear_radius = _finite(wear.get("radius", current["wear"]["radius"]), "wear.radius")
        row.lathe = _lathe_fields(data, wear, row.lathe)
        self._session.flush()
        after = _tool_dict(row)
        if source is not None:
            self.add_audit("tool", f"T{t}", before, after, source, detail)
        return after

    def delete_tool(self, t: int, source: str | None = None) -> None:
        """KeyError when there is no tool ``t``; with ``source`` audited."""
        row = self._session.get(Tool, self._key(t=t))
        if row is None:
            raise KeyError(t)
        before = _tool_dict(row)
        self._session.delete(row)
        self._session.flush()
        if source is not None:
            self.add_audit("tool", f"T{t}", before, None, source)

    # --- workpiece probe (_WP) and tool probe (_TP) records ------------------------------

    def get_probe(self, n: int) -> dict[str, Any] | None:
        return self._get_record(Probe, n)

    def put_probe(self, n: int, data: dict[str, Any], source: str | None = None, detail: dict[str, Any] | None = None) -> dict[str, Any]:
        """With ``source`` audited (kind "probe", item "WP<n>")."""
        return self._put_record(Probe, n, data, source, detail)

    def list_probes(self) -> list[dict[str, Any]]:
        return self._list_records(Probe)

    def get_tool_probe(self, n: int) -> dict[str, Any] | None:
        return self._get_record(ToolProbe, n)

    def put_tool_probe(self, n: int, data: dict[str, Any], source: str | None = None, detail: dict[str, Any] | None = None) -> dict[str, Any]:
        """With ``source`` audited (kind "tool_probe", item "TP<n>")."""
        return self._put_record(ToolProbe, n, data, source, detail)

    def list_tool_probes(self) -> list[dict[str, Any]]:
        return self._list_records(ToolProbe)

    def _get_record(self, model: type[_Record], n: int) -> dict[str, Any] | None:
        row = self._session.get(model, self._key(number=n))
        return None if row is None else copy.deepcopy(row.data)

    def _put_record(self, model: type[_Record], n: int, data: dict[str, Any],
                    source: str | None = None, detail: dict[str, Any] | None = None) -> dict[str, Any]:
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
        row = self._session.get(model, self._key(number=n))
        before = None if row is None else copy.deepcopy(row.data)
        if row is None:
            row = model(machine=self.machine, number=n)
            self._session.add(row)
        row.data, row.calibrated_at = document, calibrated_at
        self._session.flush()
        if source is not None:
            kind, prefix = ("probe", "WP") if model is Probe else ("tool_probe", "TP")
            self.add_audit(kind, f"{prefix}{n}", before, document, source, detail)
        return copy.deepcopy(document)

    def _list_records(self, model: type[_Record]) -> list[dict[str, Any]]:
        query = select(model).where(model.machine == self.machine).order_by(model.number)
        return [copy.deepcopy(row.data) for row in self._session.scalars(query)]

    # --- settings and machine state (key -> JSON value) ---------------------------------

    def get_settings(self) -> dict[str, Any]:
        rows = self._session.scalars(select(Setting).where(Setting.machine == self.machine).order_by(Setting.key))
        return {row.key: copy.deepcopy(row.value) for row in rows}

    def put_settings(self, values: dict[str, Any]) -> dict[str, Any]:
        """Merges ``values`` into the stored settings; returns all settings."""
        if not isinstance(values, dict) or not all(isinstance(key, str) for key in values):
            raise ValueError("settings must be an object with string keys")
        for key, value in values.items():
            self._upsert(Setting, key, value)
        self._session.flush()
        return self.get_settings()

    def get_state(self, key: str, default: Any = None) -> Any:
        # a prepared Core SELECT after a flush (what the session holds is what it reads): the
        # value is decoded from its JSON, a new object for the caller
        self._session.flush()
        row = self._session.connection().execute(_STATE_VALUE, {"machine": self.machine, "key": key}).first()
        return default if row is None else row[0]

    def set_state(self, key: str, value: Any) -> None:
        self._upsert(MachineState, key, value)
        self._session.flush()

    def _upsert(self, model: type[_KeyValue], key: str, value: Any) -> None:
        value = _json_ready(value, key)
        row = self._session.get(model, self._key(key=key))
        if row is None:
            self._session.add(model(machine=self.machine, key=key, value=value))
        else:
            row.value = value

    # --- EV / MV memories (measuring-math §3.3) ----------------------------------------------

    def get_memory(self, kind: str, number: int) -> float:
        """The memory's value; 0 for one never written (the NC's initial value)."""
        row = self._session.get(MemoryValue, self._key(kind=_memory_kind(kind),
                                                       number=_positive_int(number, "memory number")))
        return 0.0 if row is None else float(row.value)

    def list_memories(self, kind: str) -> dict[int, float]:
        rows = self._session.scalars(select(MemoryValue).where(MemoryValue.machine == self.machine,
                                                               MemoryValue.kind == _memory_kind(kind))
                                     .order_by(MemoryValue.number))
        return {row.number: float(row.value) for row in rows}

    def put_memory(self, kind: str, number: int, value: float, source: str, detail: dict[str, Any] | None = None
                   ) -> tuple[float, float]:
        """Writes the memory and an audit row (offset name "EV10", "MV10"); (before, after)."""
        kind, number = _memory_kind(kind), _positive_int(number, "memory number")
        value = _finite(value, f"{kind}{number}")
        row = self._session.get(MemoryValue, self._key(kind=kind, number=number))
        before = 0.0 if row is None else float(row.value)
        if row is None:
            self._session.add(MemoryValue(machine=self.machine, kind=kind, number=number, value=value))
        else:
            row.value = value
        self.add_audit("memory", f"{kind}{number}", {"value": before}, {"value": value}, source, detail)
        return before, value

    # --- part programs (design.md §9.4) -------------------------------------------------

    def list_programs(self) -> list[dict[str, Any]]:
        """Every stored program without its text: name, size (characters, lines), times."""
        rows = self._session.execute(select(Program.name, func.length(Program.text), Program.text,
                                            Program.created_at, Program.updated_at)
                                     .where(Program.machine == self.machine).order_by(Program.name))
        return [{"name": name, "size": int(size or 0), "lines": text.count("\n") + (1 if text and not
                 text.endswith("\n") else 0), "created_at": created, "updated_at": updated}
                for name, size, text, created, updated in rows]

    def get_program(self, name: str) -> dict[str, Any] | None:
        row = self._session.get(Program, self._key(name=name))
        return None if row is None else _program_dict(row)

    def put_program(self, name: str, text: str) -> tuple[dict[str, Any], bool]:
        """Creates or replaces program ``name``; (program, created)."""
        if not isinstance(name, str) or not name:
            raise ValueError("a program needs a name")
        if not isinstance(text, str) or len(text) > PROGRAM_TEXT_MAX:
            raise ValueError(f"a program is a text of at most {PROGRAM_TEXT_MAX} characters")
        now = _utc_now()
        row = self._session.get(Program, self._key(name=name))
        created = row is None
        if row is None:
            row = Program(machine=self.machine, name=name, text=text, created_at=now, updated_at=now)
            self._session.add(row)
        else:
            row.text, row.updated_at = text, now
        self._session.flush()
        return _program_dict(row), created

    def delete_program(self, name: str) -> None:
        """KeyError when there is no program ``name``."""
        row = self._session.get(Program, self._key(name=name))
        if row is None:
            raise KeyError(name)
        self._session.delete(row)
        self._session.flush()

    # --- measurement log -----------------------------------------------------------------

    def add_log(self, entry: dict[str, Any]) -> int:
        _check_keys(entry, LOG_FIELDS, "log entry")
        if not isinstance(entry.get("task"), str):
            raise ValueError("log entry needs a task name")
        return self._insert(_LOG_INSERT, {"machine": self.machine, "time": _utc_now(),
                                          **{key: _json_ready(entry.get(key), key) for key in LOG_FIELDS}})

    def list_log(self, limit: int = 500, offset: int = 0, before_id: int | None = None,
                 fields: Iterable[str] | None = None) -> list[dict[str, Any]]:
        """Newest first: ``limit`` entries after skipping ``offset`` (or those older than
        ``before_id``, for paging through all of them); ``fields`` reads only those columns."""
        names = LOG_FIELDS if fields is None else tuple(f for f in LOG_FIELDS if f in set(fields))
        columns = [MeasurementLog.id, MeasurementLog.time, *(getattr(MeasurementLog, f) for f in names)]
        query = select(*columns).where(MeasurementLog.machine == self.machine).order_by(MeasurementLog.id.desc())
        if before_id is not None:
            query = query.where(MeasurementLog.id < before_id)
        query = query.offset(offset).limit(limit)
        return [{"id": row[0], "time": row[1], **dict(zip(names, row[2:], strict=True))}
                for row in self._session.execute(query)]

    def count_log(self) -> int:
        query = select(func.count(MeasurementLog.id)).where(MeasurementLog.machine == self.machine)
        return int(self._session.scalar(query) or 0)

    def get_log(self, log_id: int) -> dict[str, Any] | None:
        row = self._session.get(MeasurementLog, log_id)
        return None if row is None or row.machine != self.machine else _log_dict(row)


    # --- users, API tokens, sign-in sessions (access levels, design.md §9.2) ---------------

    def users_exist(self) -> bool:
        return bool(self._session.scalar(select(exists().where(User.id.is_not(None)))))

    def list_users(self) -> list[dict[str, Any]]:
        return [_user_dict(row) for row in self._session.scalars(select(User).order_by(User.name))]

    def get_user(self, name: str, with_hash: bool = False) -> dict[str, Any] | None:
        row = self._session.scalar(select(User).where(User.name == name))
        if row is None:
            return None
        return {**_user_dict(row), "password_hash": row.password_hash} if with_hash else _user_dict(row)

    def add_user(self, name: str, level: int, password_hash: str) -> dict[str, Any]:
        """ValueError when the name is taken."""
        if self.get_user(name) is not None:
            raise ValueError(f"user {name!r} exists already")
        row = User(name=name, level=level, password_hash=password_hash, created=_utc_now())
        self._session.add(row)
        self._session.flush()
        return _user_dict(row)

    def set_password_hash(self, name: str, password_hash: str) -> None:
        row = self._session.scalar(select(User).where(User.name == name))
        if row is None:
            raise KeyError(name)
        row.password_hash = password_hash
        self._session.flush()

    def delete_user(self, name: str) -> dict[str, Any]:
        """KeyError when there is no such user; the user's sessions end with it."""
        row = self._session.scalar(select(User).where(User.name == name))
        if row is None:
            raise KeyError(name)
        data = _user_dict(row)
        self._session.execute(delete(AuthSession).where(AuthSession.user_id == row.id))
        self._session.delete(row)
        self._session.flush()
        return data

    def list_tokens(self) -> list[dict[str, Any]]:
        return [_token_dict(row) for row in self._session.scalars(select(ApiToken).order_by(ApiToken.name))]

    def add_token(self, name: str, level: int, token_hash: str) -> dict[str, Any]:
        if self._session.scalar(select(ApiToken).where(ApiToken.name == name)) is not None:
            raise ValueError(f"token {name!r} exists already")
        row = ApiToken(name=name, level=level, token_hash=token_hash, created=_utc_now())
        self._session.add(row)
        self._session.flush()
        return _token_dict(row)

    def token_by_hash(self, token_hash: str) -> dict[str, Any] | None:
        row = self._session.scalar(select(ApiToken).where(ApiToken.token_hash == token_hash))
        return None if row is None else _token_dict(row)

    def delete_token(self, name: str) -> dict[str, Any]:
        row = self._session.scalar(select(ApiToken).where(ApiToken.name == name))
        if row is None:
            raise KeyError(name)
        data = _token_dict(row)
        self._session.delete(row)
        self._session.flush()
        return data

    def add_session(self, session_hash: str, user_name: str | None, expires: str) -> None:
        """A sign-in: ``user_name`` None is the operator panel (keyswitch level)."""
        now = _utc_now()
        self._session.execute(delete(AuthSession).where(AuthSession.expires < now))
        user_id = None
        if user_name is not None:
            user_id = self._session.scalar(select(User.id).where(User.name == user_name))
            if user_id is None:
                raise KeyError(user_name)
        self._session.add(AuthSession(id=session_hash, machine=self.machine, user_id=user_id, created=now,
                                      expires=expires))
        self._session.flush()

    def get_session(self, session_hash: str) -> dict[str, Any] | None:
        """{"user": {...} or None (panel), "expires"} of a session that has not expired."""
        row = self._session.get(AuthSession, session_hash)
        if row is None or row.machine != self.machine or row.expires < _utc_now():
            return None
        user = None
        if row.user_id is not None:
            user_row = self._session.get(User, row.user_id)
            if user_row is None:
                return None
            user = _user_dict(user_row)
        return {"user": user, "expires": row.expires, "created": row.created}

    def delete_session(self, session_hash: str) -> None:
        self._session.execute(delete(AuthSession).where(AuthSession.id == session_hash))
        self._session.flush()


class _EndedTransaction:
    def __getattr__(self, name: str) -> Any:
        raise RuntimeError("this Unit's transaction has ended; open a new one with Database.unit()")


# --- row <-> dict helpers -------------------------------------------------------------------

# prepared once (building a statement costs more than running it): the rows a measurement writes
_FRAME_ROWS = (select(FrameAxis.axis, FrameAxis.coarse, FrameAxis.fine, FrameAxis.rot, FrameAxis.id)
               .where(FrameAxis.machine == bindparam("machine"), FrameAxis.channel == CHANNEL,
                      FrameAxis.name == bindparam("name")))
_FRAMES_TABLE = cast(Table, FrameAxis.__table__)
_FRAME_AXIS_INSERT = insert(_FRAMES_TABLE)
_FRAME_AXIS_UPDATE = (update(_FRAMES_TABLE).where(_FRAMES_TABLE.c.id == bindparam("row_id"))
                      .values(coarse=bindparam("coarse"), fine=bindparam("fine"), rot=bindparam("rot")))
_STATE_VALUE = select(MachineState.value).where(MachineState.machine == bindparam("machine"),
                                                MachineState.key == bindparam("key"))


@dataclass(frozen=True)
class _AxisValues:
    """One frame axis as put_offset wrote it (the columns _frame_from_rows reads)."""

    axis: str
    coarse: float
    fine: float
    rot: float | None
    id: int | None
_AUDIT_INSERT = insert(cast(Table, OffsetAudit.__table__))
_LOG_INSERT = insert(cast(Table, MeasurementLog.__table__))


def _new_frame_axis(slot: OffsetSlot, axis: str, machine: str) -> FrameAxis:
    return FrameAxis(
        machine=machine, channel=CHANNEL, name=slot.name, kind=slot.kind, frame_index=slot.index, axis=axis,
        coarse=0.0, fine=0.0, rot=0.0 if axis in GEOMETRY_AXES else None, mirror=False, scale=1.0,
    )


def _frame_from_rows(rows: Iterable[Any]) -> dict[str, Any]:
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


def _parse_frame(frame: dict[str, Any]) -> dict[str, tuple[float, float, float | None]]:
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


def _tool_dict(row: Tool) -> dict[str, Any]:
    out: dict[str, Any] = {"t": row.t, "name": row.name, "type": row.type, "length": row.length, "radius": row.radius,
           "wear": {"length": row.wear_length, "radius": row.wear_radius}}
    lathe = row.lathe
    if lathe:                                    # a lathe tool: SL, L1, L2 and their wear (radius values)
        out.update(sl=int(lathe["sl"]), l1=float(lathe["l1"]), l2=float(lathe["l2"]))
        out["wear"].update(l1=float(lathe["wear_l1"]), l2=float(lathe["wear_l2"]))
    return out


def _lathe_fields(data: dict[str, Any], wear: dict[str, Any], current: dict[str, Any] | None) -> dict[str, Any] | None:
    """The lathe column after a write: given values (not None) replace the stored ones; a tool
    that never had one stays a milling tool (NULL)."""
    given = {k: data[k] for k in LATHE_TOOL_FIELDS if data.get(k) is not None}
    given.update({f"wear_{k}": wear[k] for k in ("l1", "l2") if wear.get(k) is not None})
    if not given and not current:
        return None
    out = {"sl": 0, "l1": 0.0, "l2": 0.0, "wear_l1": 0.0, "wear_l2": 0.0, **(current or {})}
    for key, value in given.items():
        out[key] = _int(value, key) if key == "sl" else _finite(value, key.replace("wear_", "wear."))
    return out


def _audit_dict(row: OffsetAudit) -> dict[str, Any]:
    return {"id": row.id, "time": row.time, "kind": row.kind or "offset", "offset": row.offset,
            "before": copy.deepcopy(row.before), "after": copy.deepcopy(row.after), "source": row.source,
            "detail": copy.deepcopy(row.detail), "who": row.who, "level": row.who_level,
            "machine": row.machine}


def _user_dict(row: User) -> dict[str, Any]:
    return {"name": row.name, "level": row.level, "created": row.created}


def _token_dict(row: ApiToken) -> dict[str, Any]:
    return {"name": row.name, "level": row.level, "created": row.created}


def _log_dict(row: MeasurementLog) -> dict[str, Any]:
    # the unit's session ends with the unit: nobody else holds these JSON values, no copy needed
    return {"id": row.id, "time": row.time, **{key: getattr(row, key) for key in LOG_FIELDS}}


def _program_dict(row: Program) -> dict[str, Any]:
    return {"name": row.name, "text": row.text, "created_at": row.created_at, "updated_at": row.updated_at}


def _memory_kind(kind: str) -> str:
    if kind not in ("EV", "MV"):
        raise ValueError(f"memory kind must be EV or MV, got {kind!r}")
    return kind


def utc_now() -> str:
    return datetime.now(UTC).isoformat(timespec="microseconds")


_utc_now = utc_now


def _json_ready(value: Any, what: str) -> Any:
    """A deep copy of ``value`` as JSON gives it back (tuples -> lists); rejects NaN and objects."""
    try:
        return _plain_copy(value)
    except (_NotPlain, RecursionError):       # a cycle too: the round trip names it
        pass
    try:
        return json.loads(json.dumps(value, allow_nan=False))
    except (TypeError, ValueError) as error:
        raise ValueError(f"{what} is not JSON-ready: {error}") from None


class _NotPlain(Exception):
    """A value the JSON round trip must judge (a subclass, a non-text key, NaN, an object)."""


def _plain_copy(value: Any) -> Any:
    """The JSON round trip's answer for plain values, without the text (issue 30: the log and the
    audit copy every field of every NC Start): exact types str, int, bool, None, finite float
    (``float`` -> ``repr`` -> ``float`` is the same number), dict with text keys, list and tuple
    (-> list). Anything else is ``_NotPlain``: the round trip answers or refuses it."""
    kind = type(value)
    if kind is str or kind is int or kind is bool or value is None:
        return value
    if kind is float:
        if math.isfinite(value):
            return value
        raise _NotPlain
    if kind is dict:
        copied = {}
        for key, item in value.items():
            if type(key) is not str:
                raise _NotPlain
            copied[key] = _plain_copy(item)
        return copied
    if kind is list or kind is tuple:
        return [_plain_copy(item) for item in value]
    raise _NotPlain


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
    number = _int(value, what)
    if number < 1:
        raise ValueError(f"{what} must be >= 1, got {number}")
    return number

"""ORM models of the HMI's persistent data (design.md §6, spec/jog-measuring.md §4.5, §8).

The initial migration (``migrations/versions/0001_initial.py``) creates exactly these tables;
``tests/db`` checks that the two never drift apart.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from sqlalchemy import JSON, CheckConstraint, Float, ForeignKey, Index, Integer, String, UniqueConstraint
from sqlalchemy.dialects.postgresql import JSONB
from sqlalchemy.orm import DeclarativeBase, Mapped, declared_attr, mapped_column

GEOMETRY_AXES = ("X", "Y", "Z")
ROTARY_AXES = ("A", "B", "C")
AXES = GEOMETRY_AXES + ROTARY_AXES

# Frame kinds in the order of the frame chain, outside in (spec §4.5; no global basic frames here).
FRAME_KINDS = ("setframe", "chbasic", "settable")
MAX_PROBE_NUMBER = 99            # probe and tool-probe records 1..99

# JSON documents: JSONB on PostgreSQL (design.md §10.5); NullableJSON stores Python None as SQL NULL.
Document = JSON().with_variant(JSONB(), "postgresql")
NullableJSON = JSON(none_as_null=True).with_variant(JSONB(none_as_null=True), "postgresql")
MACHINE_NAME_LENGTH = 64


def machine_key() -> Mapped[str]:
    """The machine (HMI) a row belongs to, part of the key (design.md §10.5)."""
    return mapped_column(String(MACHINE_NAME_LENGTH), primary_key=True, sort_order=-1)


def machine_column() -> Mapped[str]:
    """The machine (HMI) that wrote a row; '' only for a row of no machine (never written so)."""
    return mapped_column(String(MACHINE_NAME_LENGTH), server_default="", sort_order=-1)


class Base(DeclarativeBase):
    pass


class FrameAxis(Base):
    """One axis of one frame: coarse and fine translation, rotation about it (geometry axes only)."""

    __tablename__ = "frames"
    __table_args__ = (
        UniqueConstraint("machine", "channel", "name", "axis", name="uq_frames_machine_channel_name_axis"),
        CheckConstraint(f"kind IN {FRAME_KINDS}", name="ck_frames_kind"),
        CheckConstraint(f"axis IN {AXES}", name="ck_frames_axis"),
        CheckConstraint(f"rot IS NULL OR axis IN {GEOMETRY_AXES}", name="ck_frames_rot_geometry_only"),
        CheckConstraint("scale > 0", name="ck_frames_scale_positive"),
    )

    id: Mapped[int] = mapped_column(primary_key=True)
    machine: Mapped[str] = machine_column()
    channel: Mapped[int] = mapped_column(Integer, default=1)
    name: Mapped[str] = mapped_column(String(16))            # API name: G54, BASIC_REF, BASIC_0 ...
    kind: Mapped[str] = mapped_column(String(16))
    frame_index: Mapped[int] = mapped_column(Integer)        # G54..G57 -> 1..4, G505 -> 5 (as _JM_I[4])
    axis: Mapped[str] = mapped_column(String(1))
    coarse: Mapped[float] = mapped_column(Float, default=0.0)
    fine: Mapped[float] = mapped_column(Float, default=0.0)
    rot: Mapped[float | None] = mapped_column(Float)         # degrees, RPY component about this axis
    mirror: Mapped[bool] = mapped_column(default=False)
    scale: Mapped[float] = mapped_column(Float, default=1.0)


# what an audit row records (``OffsetAudit.kind``); ``offset`` names the item of that kind
AUDIT_KINDS = ("offset", "memory", "tool", "probe", "tool_probe", "settings", "scenario", "user", "token",
               "keyswitch")
MIN_LEVEL, MAX_LEVEL = 0, 7          # SINUMERIK protection levels: 0 highest .. 7 lowest
PASSWORD_LEVELS = (1, 2, 3)          # a user's password gives one of these (keyswitch: 4..7)


class OffsetAudit(Base):
    """Every change of stored data: before/after, who (user or token, and its access level at the
    time), through what (source: api/screen/measure/...), when, and why (detail). Zero offsets
    (kind "offset") since 0001; memories, tools, probe records, settings, users, ... since 0004."""

    __tablename__ = "offset_audit"
    __table_args__ = (Index("ix_offset_audit_offset_id", "offset", "id"),
                      Index("ix_offset_audit_kind_id", "kind", "id"),
                      Index("ix_offset_audit_machine_id", "machine", "id"))

    id: Mapped[int] = mapped_column(primary_key=True)
    machine: Mapped[str] = machine_column()
    time: Mapped[str] = mapped_column(String(40))            # UTC ISO 8601
    offset: Mapped[str] = mapped_column(String(16))          # the item: G54, EV10, T9, WP1, settings ...
    before: Mapped[Any] = mapped_column(NullableJSON, nullable=True)   # None: the item did not exist
    after: Mapped[Any] = mapped_column(NullableJSON, nullable=True)    # None: the item was deleted
    source: Mapped[str] = mapped_column(String(64))
    detail: Mapped[dict[str, Any] | None] = mapped_column(NullableJSON)
    kind: Mapped[str] = mapped_column(String(16), default="offset", server_default="offset")
    who: Mapped[str | None] = mapped_column(String(80))      # "user:anna", "token:mes", "trainer", ...
    who_level: Mapped[int | None] = mapped_column(Integer)


class User(Base):
    """A person who signs in with a password; the password gives a protection level 1..3."""

    __tablename__ = "users"
    __table_args__ = (CheckConstraint("level BETWEEN 1 AND 3", name="ck_users_level"),)

    id: Mapped[int] = mapped_column(primary_key=True)
    name: Mapped[str] = mapped_column(String(64), unique=True)
    level: Mapped[int] = mapped_column(Integer)
    password_hash: Mapped[str] = mapped_column(String(255))   # argon2id (pwdlib), never the password
    created: Mapped[str] = mapped_column(String(40))


class ApiToken(Base):
    """An automation credential (``Authorization: Bearer``) with its own level; stored as a SHA-256
    of a 256-bit random secret (shown once by ``python -m app token add``)."""

    __tablename__ = "api_tokens"
    __table_args__ = (CheckConstraint("level BETWEEN 1 AND 7", name="ck_api_tokens_level"),)

    id: Mapped[int] = mapped_column(primary_key=True)
    name: Mapped[str] = mapped_column(String(64), unique=True)
    level: Mapped[int] = mapped_column(Integer)
    token_hash: Mapped[str] = mapped_column(String(64), unique=True)
    created: Mapped[str] = mapped_column(String(40))


class AuthSession(Base):
    """A signed-in browser: the cookie holds a random secret, this row its SHA-256. ``user_id`` NULL
    is the operator panel (its level is the keyswitch's, read on every request)."""

    __tablename__ = "auth_sessions"

    id: Mapped[str] = mapped_column(String(64), primary_key=True)
    machine: Mapped[str] = machine_column()                  # the HMI signed in at
    user_id: Mapped[int | None] = mapped_column(ForeignKey("users.id", ondelete="CASCADE"))
    created: Mapped[str] = mapped_column(String(40))
    expires: Mapped[str] = mapped_column(String(40))


class Tool(Base):
    """A tool edge: geometry and wear (tool type as SINUMERIK: 120 end mill, 710 3D probe)."""

    __tablename__ = "tools"
    __table_args__ = (CheckConstraint("t > 0", name="ck_tools_t_positive"),)

    machine: Mapped[str] = machine_key()
    t: Mapped[int] = mapped_column(Integer, primary_key=True, autoincrement=False)
    name: Mapped[str | None] = mapped_column(String(64))
    type: Mapped[int] = mapped_column(Integer, default=120)
    length: Mapped[float] = mapped_column(Float, default=0.0)
    radius: Mapped[float] = mapped_column(Float, default=0.0)
    wear_length: Mapped[float] = mapped_column(Float, default=0.0)
    wear_radius: Mapped[float] = mapped_column(Float, default=0.0)
    # lathe tools (turning.md §10.2): {"sl", "l1", "l2", "wear_l1", "wear_l2"}; NULL for milling tools
    lathe: Mapped[dict[str, Any] | None] = mapped_column(NullableJSON, nullable=True)


class _ProbeRecord:
    """Columns of a numbered probe record: a JSON document (schema owned by the app) + its number."""

    machine: Mapped[str] = machine_key()
    number: Mapped[int] = mapped_column(Integer, primary_key=True, autoincrement=False)
    calibrated_at: Mapped[str | None] = mapped_column(String(40))
    data: Mapped[dict[str, Any]] = mapped_column(Document)
    if TYPE_CHECKING:
        __tablename__: str              # set by each mapped subclass

    @declared_attr.directive
    def __table_args__(cls) -> tuple[CheckConstraint]:
        return (CheckConstraint(f"number BETWEEN 1 AND {MAX_PROBE_NUMBER}",
                                name=f"ck_{cls.__tablename__}_number"),)


class Probe(_ProbeRecord, Base):
    """Workpiece probe record _WP[number - 1]."""

    __tablename__ = "probes"


class ToolProbe(_ProbeRecord, Base):
    """Tool probe record _TP[number - 1]."""

    __tablename__ = "tool_probes"


class _KeyValue:
    machine: Mapped[str] = machine_key()
    key: Mapped[str] = mapped_column(String(64), primary_key=True)
    value: Mapped[Any] = mapped_column(Document, nullable=True)


class Setting(_KeyValue, Base):
    """One GUD-like setting (key -> JSON value)."""

    __tablename__ = "settings"


class MachineState(_KeyValue, Base):
    """Machine state the app keeps across restarts (active offset, tool in spindle)."""

    __tablename__ = "machine_state"


class MemoryValue(Base):
    """Empirical value (EV) and mean value (MV) memories _EV[n-1], _MV[n-1] (measuring-math §3.3)."""

    __tablename__ = "memory_values"
    __table_args__ = (
        CheckConstraint("kind IN ('EV', 'MV')", name="ck_memory_values_kind"),
        CheckConstraint("number >= 1", name="ck_memory_values_number"),
    )

    machine: Mapped[str] = machine_key()
    kind: Mapped[str] = mapped_column(String(2), primary_key=True)
    number: Mapped[int] = mapped_column(Integer, primary_key=True)     # memory number n = index + 1
    value: Mapped[float] = mapped_column(Float)


class MeasurementLog(Base):
    """One measurement: task, params, raw touches, stored points, result and correction."""

    __tablename__ = "measurement_log"
    __table_args__ = (Index("ix_measurement_log_task", "task"),
                      Index("ix_measurement_log_machine_id", "machine", "id"))

    id: Mapped[int] = mapped_column(primary_key=True)
    machine: Mapped[str] = machine_column()
    time: Mapped[str] = mapped_column(String(40))            # UTC ISO 8601
    task: Mapped[str] = mapped_column(String(32))
    target: Mapped[str | None] = mapped_column(String(16))
    measuring_wo: Mapped[str | None] = mapped_column(String(16))   # WO active while measuring
    status: Mapped[str | None] = mapped_column(String(32))
    probe: Mapped[Any] = mapped_column(NullableJSON, nullable=True)
    warnings: Mapped[Any] = mapped_column(NullableJSON, nullable=True)
    params: Mapped[Any] = mapped_column(NullableJSON, nullable=True)
    raw: Mapped[Any] = mapped_column(NullableJSON, nullable=True)
    points: Mapped[Any] = mapped_column(NullableJSON, nullable=True)
    result: Mapped[Any] = mapped_column(NullableJSON, nullable=True)
    correction: Mapped[Any] = mapped_column(NullableJSON, nullable=True)
    program: Mapped[str | None] = mapped_column(String(64), nullable=True)   # part program (NC cycle), else None
    block: Mapped[str | None] = mapped_column(String(200), nullable=True)    # the block that called the cycle
    part_id: Mapped[int | None] = mapped_column(ForeignKey("parts.id"), nullable=True)   # the job's part (§10.3)
    calibration_id: Mapped[int | None] = mapped_column(Integer, nullable=True)   # the probe's calibration (§10.4)


class ProbeEvent(Base):
    """What happened to a probe record (design.md §10.4): a calibration (its row id is the
    calibration id), a repeatability check, an event that invalidated the calibration."""

    __tablename__ = "probe_events"
    __table_args__ = (Index("ix_probe_events_record", "machine", "probe", "number", "id"),
                      CheckConstraint("probe IN ('workpiece', 'tool')", name="ck_probe_events_probe"))

    id: Mapped[int] = mapped_column(primary_key=True)
    machine: Mapped[str] = machine_column()
    probe: Mapped[str] = mapped_column(String(16))            # "workpiece" (_WP) | "tool" (_TP)
    number: Mapped[int] = mapped_column(Integer)
    time: Mapped[str] = mapped_column(String(40))             # UTC ISO 8601
    event: Mapped[str] = mapped_column(String(16))            # calibration | repeatability | invalidated
    calibration_id: Mapped[int | None] = mapped_column(Integer, nullable=True)
    data: Mapped[Any] = mapped_column(NullableJSON, nullable=True)


class Program(Base):
    """A stored part program (design.md §9.4): name, NC text, when it was last written."""

    __tablename__ = "programs"

    machine: Mapped[str] = machine_key()
    name: Mapped[str] = mapped_column(String(32), primary_key=True)
    text: Mapped[str] = mapped_column(String)
    created_at: Mapped[str] = mapped_column(String(40))      # UTC ISO 8601
    updated_at: Mapped[str] = mapped_column(String(40))


class Part(Base):
    """One measured part of a job (design.md §10.3): part number, order, serial, who, which program."""

    __tablename__ = "parts"
    __table_args__ = (Index("ix_parts_part_number_id", "part_number", "id"),
                      Index("ix_parts_machine_id", "machine", "id"))

    id: Mapped[int] = mapped_column(primary_key=True)
    machine: Mapped[str] = machine_column()
    part_number: Mapped[str] = mapped_column(String(64))
    order: Mapped[str | None] = mapped_column(String(64))
    serial: Mapped[str | None] = mapped_column(String(64))
    operator: Mapped[str | None] = mapped_column(String(64))
    program: Mapped[str | None] = mapped_column(String(64))
    started: Mapped[str] = mapped_column(String(40))                  # UTC ISO 8601


class Characteristic(Base):
    """One measured value of a part with its band and verdict (design.md §10.3)."""

    __tablename__ = "characteristics"
    __table_args__ = (Index("ix_characteristics_part_id", "part_id"),
                      Index("ix_characteristics_name", "name"),
                      CheckConstraint("verdict IN ('ok', 'rework', 'scrap', 'not_decidable')",
                                      name="ck_characteristics_verdict"))

    id: Mapped[int] = mapped_column(primary_key=True)
    part_id: Mapped[int] = mapped_column(ForeignKey("parts.id", ondelete="CASCADE"))
    log_id: Mapped[int | None] = mapped_column(ForeignKey("measurement_log.id"), nullable=True)
    time: Mapped[str] = mapped_column(String(40))
    name: Mapped[str] = mapped_column(String(80))
    nominal: Mapped[float | None] = mapped_column(Float)
    upper: Mapped[float | None] = mapped_column(Float)               # absolute limits (nominal + _TUL)
    lower: Mapped[float | None] = mapped_column(Float)
    actual: Mapped[float | None] = mapped_column(Float)
    deviation: Mapped[float | None] = mapped_column(Float)
    verdict: Mapped[str] = mapped_column(String(16))
    unit: Mapped[str] = mapped_column(String(8), default="mm")
    compensation: Mapped[float | None] = mapped_column(Float)         # the tool offset written after it, if any


class Machine(Base):
    """An HMI on the database (design.md §10.5): its name, when it was first and last seen, and its
    write count (``Database.generation``: raised by every writing unit, in its transaction)."""

    __tablename__ = "machines"

    name: Mapped[str] = mapped_column(String(MACHINE_NAME_LENGTH), primary_key=True)
    registered: Mapped[str] = mapped_column(String(40))                # UTC ISO 8601
    last_seen: Mapped[str] = mapped_column(String(40))
    writes: Mapped[int] = mapped_column(Integer, default=0)
    status: Mapped[Any] = mapped_column(NullableJSON, nullable=True)   # what the HMI last reported

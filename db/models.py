"""ORM models of the HMI's persistent data (design.md §6, spec/jog-measuring.md §4.5, §8).

The initial migration (``migrations/versions/0001_initial.py``) creates exactly these tables;
``tests/db`` checks that the two never drift apart.
"""

from __future__ import annotations

from typing import Any

from sqlalchemy import JSON, CheckConstraint, Float, Index, Integer, String, UniqueConstraint
from sqlalchemy.orm import DeclarativeBase, Mapped, declared_attr, mapped_column

GEOMETRY_AXES = ("X", "Y", "Z")
ROTARY_AXES = ("A", "B", "C")
AXES = GEOMETRY_AXES + ROTARY_AXES

# Frame kinds in the order of the frame chain, outside in (spec §4.5; no global basic frames here).
FRAME_KINDS = ("setframe", "chbasic", "settable")
MAX_PROBE_NUMBER = 99            # probe and tool-probe records 1..99

# JSON that stores Python None as SQL NULL (nullable document columns).
NullableJSON = JSON(none_as_null=True)


class Base(DeclarativeBase):
    pass


class FrameAxis(Base):
    """One axis of one frame: coarse and fine translation, rotation about it (geometry axes only)."""

    __tablename__ = "frames"
    __table_args__ = (
        UniqueConstraint("channel", "name", "axis", name="uq_frames_channel_name_axis"),
        CheckConstraint(f"kind IN {FRAME_KINDS}", name="ck_frames_kind"),
        CheckConstraint(f"axis IN {AXES}", name="ck_frames_axis"),
        CheckConstraint(f"rot IS NULL OR axis IN {GEOMETRY_AXES}", name="ck_frames_rot_geometry_only"),
        CheckConstraint("scale > 0", name="ck_frames_scale_positive"),
    )

    id: Mapped[int] = mapped_column(primary_key=True)
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


class OffsetAudit(Base):
    """Every zero-offset change: before/after frame, who (source), when, and why (detail)."""

    __tablename__ = "offset_audit"
    __table_args__ = (Index("ix_offset_audit_offset_id", "offset", "id"),)

    id: Mapped[int] = mapped_column(primary_key=True)
    time: Mapped[str] = mapped_column(String(40))            # UTC ISO 8601
    offset: Mapped[str] = mapped_column(String(16))
    before: Mapped[dict[str, Any]] = mapped_column(JSON)
    after: Mapped[dict[str, Any]] = mapped_column(JSON)
    source: Mapped[str] = mapped_column(String(64))
    detail: Mapped[dict[str, Any] | None] = mapped_column(NullableJSON)


class Tool(Base):
    """A tool edge: geometry and wear (tool type as SINUMERIK: 120 end mill, 710 3D probe)."""

    __tablename__ = "tools"
    __table_args__ = (CheckConstraint("t > 0", name="ck_tools_t_positive"),)

    t: Mapped[int] = mapped_column(Integer, primary_key=True, autoincrement=False)
    name: Mapped[str | None] = mapped_column(String(64))
    type: Mapped[int] = mapped_column(Integer, default=120)
    length: Mapped[float] = mapped_column(Float, default=0.0)
    radius: Mapped[float] = mapped_column(Float, default=0.0)
    wear_length: Mapped[float] = mapped_column(Float, default=0.0)
    wear_radius: Mapped[float] = mapped_column(Float, default=0.0)


class _ProbeRecord:
    """Columns of a numbered probe record: a JSON document (schema owned by the app) + its number."""

    number: Mapped[int] = mapped_column(Integer, primary_key=True, autoincrement=False)
    calibrated_at: Mapped[str | None] = mapped_column(String(40))
    data: Mapped[dict[str, Any]] = mapped_column(JSON)

    @declared_attr.directive
    def __table_args__(cls) -> tuple:
        return (CheckConstraint(f"number BETWEEN 1 AND {MAX_PROBE_NUMBER}",
                                name=f"ck_{cls.__tablename__}_number"),)


class Probe(_ProbeRecord, Base):
    """Workpiece probe record _WP[number - 1]."""

    __tablename__ = "probes"


class ToolProbe(_ProbeRecord, Base):
    """Tool probe record _TP[number - 1]."""

    __tablename__ = "tool_probes"


class _KeyValue:
    key: Mapped[str] = mapped_column(String(64), primary_key=True)
    value: Mapped[Any] = mapped_column(JSON, nullable=True)


class Setting(_KeyValue, Base):
    """One GUD-like setting (key -> JSON value)."""

    __tablename__ = "settings"


class MachineState(_KeyValue, Base):
    """Machine state the app keeps across restarts (active offset, tool in spindle)."""

    __tablename__ = "machine_state"


class MeasurementLog(Base):
    """One measurement: task, params, raw touches, stored points, result and correction."""

    __tablename__ = "measurement_log"
    __table_args__ = (Index("ix_measurement_log_task", "task"),)

    id: Mapped[int] = mapped_column(primary_key=True)
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

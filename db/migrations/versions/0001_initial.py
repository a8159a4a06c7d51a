"""initial schema: frames, offset audit, tools, probes, tool probes, settings, log, machine state

Revision ID: 0001
Revises:
Create Date: 2025-01-01
"""

from collections.abc import Sequence

import sqlalchemy as sa
from alembic import op

revision: str = "0001"
down_revision: str | None = None
branch_labels: str | Sequence[str] | None = None
depends_on: str | Sequence[str] | None = None


def upgrade() -> None:
    op.create_table(
        "frames",
        sa.Column("id", sa.Integer(), primary_key=True),
        sa.Column("channel", sa.Integer(), nullable=False),
        sa.Column("name", sa.String(16), nullable=False),
        sa.Column("kind", sa.String(16), nullable=False),
        sa.Column("frame_index", sa.Integer(), nullable=False),
        sa.Column("axis", sa.String(1), nullable=False),
        sa.Column("coarse", sa.Float(), nullable=False),
        sa.Column("fine", sa.Float(), nullable=False),
        sa.Column("rot", sa.Float(), nullable=True),
        sa.Column("mirror", sa.Boolean(), nullable=False),
        sa.Column("scale", sa.Float(), nullable=False),
        sa.UniqueConstraint("channel", "name", "axis", name="uq_frames_channel_name_axis"),
        sa.CheckConstraint("kind IN ('setframe', 'chbasic', 'settable')", name="ck_frames_kind"),
        sa.CheckConstraint("axis IN ('X', 'Y', 'Z', 'A', 'B', 'C')", name="ck_frames_axis"),
        sa.CheckConstraint("rot IS NULL OR axis IN ('X', 'Y', 'Z')", name="ck_frames_rot_geometry_only"),
        sa.CheckConstraint("scale > 0", name="ck_frames_scale_positive"),
    )
    op.create_table(
        "offset_audit",
        sa.Column("id", sa.Integer(), primary_key=True),
        sa.Column("time", sa.String(40), nullable=False),
        sa.Column("offset", sa.String(16), nullable=False),
        sa.Column("before", sa.JSON(), nullable=False),
        sa.Column("after", sa.JSON(), nullable=False),
        sa.Column("source", sa.String(64), nullable=False),
        sa.Column("detail", sa.JSON(), nullable=True),
    )
    op.create_index("ix_offset_audit_offset_id", "offset_audit", ["offset", "id"])
    op.create_table(
        "tools",
        sa.Column("t", sa.Integer(), primary_key=True, autoincrement=False),
        sa.Column("name", sa.String(64), nullable=True),
        sa.Column("type", sa.Integer(), nullable=False),
        sa.Column("length", sa.Float(), nullable=False),
        sa.Column("radius", sa.Float(), nullable=False),
        sa.Column("wear_length", sa.Float(), nullable=False),
        sa.Column("wear_radius", sa.Float(), nullable=False),
        sa.CheckConstraint("t > 0", name="ck_tools_t_positive"),
    )
    for table in ("probes", "tool_probes"):
        op.create_table(
            table,
            sa.Column("number", sa.Integer(), primary_key=True, autoincrement=False),
            sa.Column("calibrated_at", sa.String(40), nullable=True),
            sa.Column("data", sa.JSON(), nullable=False),
            sa.CheckConstraint("number BETWEEN 1 AND 99", name=f"ck_{table}_number"),
        )
    for table in ("settings", "machine_state"):
        op.create_table(
            table,
            sa.Column("key", sa.String(64), primary_key=True),
            sa.Column("value", sa.JSON(), nullable=True),
        )
    op.create_table(
        "measurement_log",
        sa.Column("id", sa.Integer(), primary_key=True),
        sa.Column("time", sa.String(40), nullable=False),
        sa.Column("task", sa.String(32), nullable=False),
        sa.Column("target", sa.String(16), nullable=True),
        sa.Column("status", sa.String(32), nullable=True),
        *(sa.Column(name, sa.JSON(), nullable=True)
          for name in ("probe", "params", "raw", "points", "result", "correction")),
    )
    op.create_index("ix_measurement_log_task", "measurement_log", ["task"])


def downgrade() -> None:
    op.drop_index("ix_measurement_log_task", table_name="measurement_log")
    op.drop_index("ix_offset_audit_offset_id", table_name="offset_audit")
    for table in ("measurement_log", "machine_state", "settings", "tool_probes", "probes", "tools",
                  "offset_audit", "frames"):
        op.drop_table(table)

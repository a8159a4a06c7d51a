"""probe health: the events of a probe record, the log entry's calibration (design.md §10.4)

Revision ID: 0009
Revises: 0008
Create Date: 2026-12-06
"""

from collections.abc import Sequence

import sqlalchemy as sa
from alembic import op
from sqlalchemy.dialects import postgresql

revision: str = "0009"
down_revision: str | None = "0008"
branch_labels: str | Sequence[str] | None = None
depends_on: str | Sequence[str] | None = None

JSON = sa.JSON(none_as_null=True).with_variant(postgresql.JSONB(none_as_null=True), "postgresql")


def upgrade() -> None:
    op.create_table(
        "probe_events",
        sa.Column("machine", sa.String(64), server_default="", nullable=False),
        sa.Column("id", sa.Integer(), primary_key=True),
        sa.Column("probe", sa.String(16), nullable=False),
        sa.Column("number", sa.Integer(), nullable=False),
        sa.Column("time", sa.String(40), nullable=False),
        sa.Column("event", sa.String(16), nullable=False),
        sa.Column("calibration_id", sa.Integer(), nullable=True),
        sa.Column("data", JSON, nullable=True),
        sa.CheckConstraint("probe IN ('workpiece', 'tool')", name="ck_probe_events_probe"),
    )
    op.create_index("ix_probe_events_record", "probe_events", ["machine", "probe", "number", "id"])
    with op.batch_alter_table("measurement_log") as batch:
        batch.add_column(sa.Column("calibration_id", sa.Integer(), nullable=True))


def downgrade() -> None:
    with op.batch_alter_table("measurement_log") as batch:
        batch.drop_column("calibration_id")
    op.drop_index("ix_probe_events_record", "probe_events")
    op.drop_table("probe_events")

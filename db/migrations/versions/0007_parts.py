"""parts and characteristics of a job, the log entry's part (design.md §10.3)

Revision ID: 0007
Revises: 0006
Create Date: 2026-12-06
"""

from collections.abc import Sequence

import sqlalchemy as sa
from alembic import op

revision: str = "0007"
down_revision: str | None = "0006"
branch_labels: str | Sequence[str] | None = None
depends_on: str | Sequence[str] | None = None


def upgrade() -> None:
    op.create_table(
        "parts",
        sa.Column("id", sa.Integer(), primary_key=True),
        sa.Column("part_number", sa.String(64), nullable=False),
        sa.Column("order", sa.String(64), nullable=True),
        sa.Column("serial", sa.String(64), nullable=True),
        sa.Column("operator", sa.String(64), nullable=True),
        sa.Column("program", sa.String(64), nullable=True),
        sa.Column("started", sa.String(40), nullable=False),
    )
    op.create_index("ix_parts_part_number_id", "parts", ["part_number", "id"])
    op.create_table(
        "characteristics",
        sa.Column("id", sa.Integer(), primary_key=True),
        sa.Column("part_id", sa.Integer(), sa.ForeignKey("parts.id", ondelete="CASCADE"), nullable=False),
        sa.Column("log_id", sa.Integer(), sa.ForeignKey("measurement_log.id"), nullable=True),
        sa.Column("time", sa.String(40), nullable=False),
        sa.Column("name", sa.String(80), nullable=False),
        sa.Column("nominal", sa.Float(), nullable=True),
        sa.Column("upper", sa.Float(), nullable=True),
        sa.Column("lower", sa.Float(), nullable=True),
        sa.Column("actual", sa.Float(), nullable=True),
        sa.Column("deviation", sa.Float(), nullable=True),
        sa.Column("verdict", sa.String(16), nullable=False),
        sa.Column("unit", sa.String(8), nullable=False),
        sa.Column("compensation", sa.Float(), nullable=True),
        sa.CheckConstraint("verdict IN ('ok', 'rework', 'scrap', 'not_decidable')",
                           name="ck_characteristics_verdict"),
    )
    op.create_index("ix_characteristics_part_id", "characteristics", ["part_id"])
    op.create_index("ix_characteristics_name", "characteristics", ["name"])
    with op.batch_alter_table("measurement_log") as batch:
        batch.add_column(sa.Column("part_id", sa.Integer(), nullable=True))
        batch.create_foreign_key("fk_measurement_log_part_id", "parts", ["part_id"], ["id"])


def downgrade() -> None:
    with op.batch_alter_table("measurement_log") as batch:
        batch.drop_constraint("fk_measurement_log_part_id", type_="foreignkey")
        batch.drop_column("part_id")
    op.drop_index("ix_characteristics_name", "characteristics")
    op.drop_index("ix_characteristics_part_id", "characteristics")
    op.drop_table("characteristics")
    op.drop_index("ix_parts_part_number_id", "parts")
    op.drop_table("parts")

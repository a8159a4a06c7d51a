"""empirical and mean value memories (EV, MV) of the tool-offset strategy

Revision ID: 0003
Revises: 0002
Create Date: 2026-12-01
"""

from collections.abc import Sequence

import sqlalchemy as sa
from alembic import op

revision: str = "0003"
down_revision: str | None = "0002"
branch_labels: str | Sequence[str] | None = None
depends_on: str | Sequence[str] | None = None


def upgrade() -> None:
    op.create_table(
        "memory_values",
        sa.Column("kind", sa.String(2), primary_key=True),
        sa.Column("number", sa.Integer(), primary_key=True),
        sa.Column("value", sa.Float(), nullable=False),
        sa.CheckConstraint("kind IN ('EV', 'MV')", name="ck_memory_values_kind"),
        sa.CheckConstraint("number >= 1", name="ck_memory_values_number"),
    )


def downgrade() -> None:
    op.drop_table("memory_values")

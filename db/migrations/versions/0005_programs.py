"""part programs (MDA/AUTOMATIC, design.md §9.4) and the program/block of program-driven measurements

Revision ID: 0005
Revises: 0004
Create Date: 2026-12-01
"""

from collections.abc import Sequence

import sqlalchemy as sa
from alembic import op

revision: str = "0005"
down_revision: str | None = "0004"
branch_labels: str | Sequence[str] | None = None
depends_on: str | Sequence[str] | None = None


def upgrade() -> None:
    op.create_table(
        "programs",
        sa.Column("name", sa.String(32), primary_key=True),
        sa.Column("text", sa.String(), nullable=False),
        sa.Column("created_at", sa.String(40), nullable=False),
        sa.Column("updated_at", sa.String(40), nullable=False),
    )
    with op.batch_alter_table("measurement_log") as batch:
        batch.add_column(sa.Column("program", sa.String(64), nullable=True))
        batch.add_column(sa.Column("block", sa.String(200), nullable=True))


def downgrade() -> None:
    with op.batch_alter_table("measurement_log") as batch:
        batch.drop_column("block")
        batch.drop_column("program")
    op.drop_table("programs")

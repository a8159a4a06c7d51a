"""tools: the lathe fields (cutting-edge position SL, lengths L1/L2 and their wear), turning.md §10.2

Revision ID: 0006
Revises: 0005
Create Date: 2026-12-03

One nullable JSON column: milling tools keep NULL and read exactly as before.
"""

from collections.abc import Sequence

import sqlalchemy as sa
from alembic import op

revision: str = "0006"
down_revision: str | None = "0005"
branch_labels: str | Sequence[str] | None = None
depends_on: str | Sequence[str] | None = None


def upgrade() -> None:
    with op.batch_alter_table("tools") as batch:
        batch.add_column(sa.Column("lathe", sa.JSON(), nullable=True))


def downgrade() -> None:
    with op.batch_alter_table("tools") as batch:
        batch.drop_column("lathe")

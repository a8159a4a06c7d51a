"""measurement log: the WO active while measuring and the warnings shown, as columns

Revision ID: 0002
Revises: 0001
Create Date: 2026-11-29
"""

from collections.abc import Sequence

import sqlalchemy as sa
from alembic import op

revision: str = "0002"
down_revision: str | None = "0001"
branch_labels: str | Sequence[str] | None = None
depends_on: str | Sequence[str] | None = None


def upgrade() -> None:
    with op.batch_alter_table("measurement_log") as batch:
        batch.add_column(sa.Column("measuring_wo", sa.String(16), nullable=True))
        batch.add_column(sa.Column("warnings", sa.JSON(), nullable=True))


def downgrade() -> None:
    with op.batch_alter_table("measurement_log") as batch:
        batch.drop_column("warnings")
        batch.drop_column("measuring_wo")

"""access: users, API tokens, sign-in sessions; the audit trail names who (and records every kind of data)

Revision ID: 0004
Revises: 0003
Create Date: 2026-12-02

Self-contained: it only adds tables and columns (and lets the audit's before/after be NULL for an item
created or deleted); rows written before it get kind "offset" (or "memory" for EV/MV) and no ``who``.
"""

from collections.abc import Sequence

import sqlalchemy as sa
from alembic import op

revision: str = "0004"
down_revision: str | None = "0003"
branch_labels: str | Sequence[str] | None = None
depends_on: str | Sequence[str] | None = None


def upgrade() -> None:
    op.create_table(
        "users",
        sa.Column("id", sa.Integer(), primary_key=True),
        sa.Column("name", sa.String(64), nullable=False, unique=True),
        sa.Column("level", sa.Integer(), nullable=False),
        sa.Column("password_hash", sa.String(255), nullable=False),
        sa.Column("created", sa.String(40), nullable=False),
        sa.CheckConstraint("level BETWEEN 1 AND 3", name="ck_users_level"),
    )
    op.create_table(
        "api_tokens",
        sa.Column("id", sa.Integer(), primary_key=True),
        sa.Column("name", sa.String(64), nullable=False, unique=True),
        sa.Column("level", sa.Integer(), nullable=False),
        sa.Column("token_hash", sa.String(64), nullable=False, unique=True),
        sa.Column("created", sa.String(40), nullable=False),
        sa.CheckConstraint("level BETWEEN 1 AND 7", name="ck_api_tokens_level"),
    )
    op.create_table(
        "auth_sessions",
        sa.Column("id", sa.String(64), primary_key=True),
        sa.Column("user_id", sa.Integer(), sa.ForeignKey("users.id", ondelete="CASCADE"), nullable=True),
        sa.Column("created", sa.String(40), nullable=False),
        sa.Column("expires", sa.String(40), nullable=False),
    )
    with op.batch_alter_table("offset_audit") as batch:
        batch.alter_column("before", existing_type=sa.JSON(), nullable=True)
        batch.alter_column("after", existing_type=sa.JSON(), nullable=True)
        batch.add_column(sa.Column("kind", sa.String(16), nullable=False, server_default="offset"))
        batch.add_column(sa.Column("who", sa.String(80), nullable=True))
        batch.add_column(sa.Column("who_level", sa.Integer(), nullable=True))
    # "offset" quoted: a reserved word in PostgreSQL
    op.execute("""UPDATE offset_audit SET kind = 'memory' WHERE "offset" LIKE 'EV%' OR "offset" LIKE 'MV%'""")
    op.create_index("ix_offset_audit_kind_id", "offset_audit", ["kind", "id"])


def downgrade() -> None:
    op.drop_index("ix_offset_audit_kind_id", table_name="offset_audit")
    op.execute("DELETE FROM offset_audit WHERE before IS NULL OR after IS NULL")
    with op.batch_alter_table("offset_audit") as batch:
        batch.drop_column("who_level")
        batch.drop_column("who")
        batch.drop_column("kind")
        batch.alter_column("after", existing_type=sa.JSON(), nullable=False)
        batch.alter_column("before", existing_type=sa.JSON(), nullable=False)
    op.drop_table("auth_sessions")
    op.drop_table("api_tokens")
    op.drop_table("users")

"""plant mode: the machine of every machine-owned row, the machines table (design.md §10.5)

Rows stored before are given the name of the HMI that migrates (``alembic_config(machine=)``).
Tables whose key gains the machine are rebuilt (create, copy, drop, rename: the same on SQLite and
PostgreSQL); the others gain the column. On PostgreSQL the JSON columns become JSONB.

Revision ID: 0008
Revises: 0007
Create Date: 2026-12-06
"""

from collections.abc import Sequence

import sqlalchemy as sa
from alembic import context, op
from sqlalchemy.dialects import postgresql
from sqlalchemy.schema import SchemaItem

revision: str = "0008"
down_revision: str | None = "0007"
branch_labels: str | Sequence[str] | None = None
depends_on: str | Sequence[str] | None = None

JSONB = sa.JSON().with_variant(postgresql.JSONB(), "postgresql")
MACHINE = 64
# tables that gain a machine column, not part of their key
COLUMN_TABLES = ("offset_audit", "measurement_log", "parts", "auth_sessions")
INDEXED = {"offset_audit": "ix_offset_audit_machine_id", "measurement_log": "ix_measurement_log_machine_id",
           "parts": "ix_parts_machine_id"}
# JSON columns of the tables that are not rebuilt (JSONB on PostgreSQL)
JSON_COLUMNS = {"offset_audit": ("before", "after", "detail"),
                "measurement_log": ("probe", "warnings", "params", "raw", "points", "result", "correction")}


def _machine() -> str:
    return str(context.config.attributes.get("machine") or "hmi")


def _postgresql() -> bool:
    return op.get_bind().dialect.name == "postgresql"


def _keyed_tables(with_machine: bool) -> dict[str, list[SchemaItem]]:
    """The rebuilt tables' columns and constraints, with or without the machine in the key."""
    key = [sa.Column("machine", sa.String(MACHINE), primary_key=True)] if with_machine else []
    json = JSONB if with_machine else sa.JSON()
    tables: dict[str, list[SchemaItem]] = {
        "tools": [*key, sa.Column("t", sa.Integer(), primary_key=True, autoincrement=False),
                  sa.Column("name", sa.String(64), nullable=True),
                  sa.Column("type", sa.Integer(), nullable=False),
                  sa.Column("length", sa.Float(), nullable=False),
                  sa.Column("radius", sa.Float(), nullable=False),
                  sa.Column("wear_length", sa.Float(), nullable=False),
                  sa.Column("wear_radius", sa.Float(), nullable=False),
                  sa.Column("lathe", json, nullable=True),
                  sa.CheckConstraint("t > 0", name="ck_tools_t_positive")],
        "memory_values": [*key, sa.Column("kind", sa.String(2), primary_key=True),
                          sa.Column("number", sa.Integer(), primary_key=True, autoincrement=False),
                          sa.Column("value", sa.Float(), nullable=False),
                          sa.CheckConstraint("kind IN ('EV', 'MV')", name="ck_memory_values_kind"),
                          sa.CheckConstraint("number >= 1", name="ck_memory_values_number")],
        "programs": [*key, sa.Column("name", sa.String(32), primary_key=True),
                     sa.Column("text", sa.String(), nullable=False),
                     sa.Column("created_at", sa.String(40), nullable=False),
                     sa.Column("updated_at", sa.String(40), nullable=False)],
        "frames": [sa.Column("id", sa.Integer(), primary_key=True),
                   *([sa.Column("machine", sa.String(MACHINE), nullable=False, server_default="")]
                     if with_machine else []),
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
                   sa.UniqueConstraint(*(["machine"] if with_machine else []), "channel", "name", "axis",
                                       name="uq_frames_machine_channel_name_axis" if with_machine
                                       else "uq_frames_channel_name_axis"),
                   sa.CheckConstraint("kind IN ('setframe', 'chbasic', 'settable')", name="ck_frames_kind"),
                   sa.CheckConstraint("axis IN ('X', 'Y', 'Z', 'A', 'B', 'C')", name="ck_frames_axis"),
                   sa.CheckConstraint("rot IS NULL OR axis IN ('X', 'Y', 'Z')", name="ck_frames_rot_geometry_only"),
                   sa.CheckConstraint("scale > 0", name="ck_frames_scale_positive")],
    }
    for table in ("probes", "tool_probes"):
        tables[table] = [*key, sa.Column("number", sa.Integer(), primary_key=True, autoincrement=False),
                         sa.Column("calibrated_at", sa.String(40), nullable=True),
                         sa.Column("data", json, nullable=False),
                         sa.CheckConstraint("number BETWEEN 1 AND 99", name=f"ck_{table}_number")]
    for table in ("settings", "machine_state"):
        tables[table] = [*key, sa.Column("key", sa.String(64), primary_key=True),
                         sa.Column("value", json, nullable=True)]
    return tables


def _rebuild(table: str, items: list[SchemaItem], machine: str | None) -> None:
    """Replaces ``table`` by one of ``items``, copying its rows (``machine``: the rows' machine
    when it is added; None: it is removed and only that machine's rows kept)."""
    new = f"{table}_new"
    op.create_table(new, *items)
    columns = [item.name for item in items if isinstance(item, sa.Column) and item.name != "machine"]
    names = ", ".join(f'"{name}"' for name in columns)
    if machine is not None:
        op.execute(sa.text(f'INSERT INTO {new} (machine, {names}) SELECT :machine, {names} FROM {table}')
                   .bindparams(machine=machine))
    else:
        op.execute(sa.text(f'INSERT INTO {new} ({names}) SELECT {names} FROM {table} WHERE machine = :machine')
                   .bindparams(machine=_machine()))
    op.drop_table(table)
    op.rename_table(new, table)
    if _postgresql() and "id" in columns:     # the copied ids: the sequence goes on after them
        op.execute(f"SELECT setval(pg_get_serial_sequence('{table}', 'id'), COALESCE(MAX(id), 0) + 1, false) "
                   f"FROM {table}")


def upgrade() -> None:
    machine = _machine()
    op.create_table(
        "machines",
        sa.Column("name", sa.String(MACHINE), primary_key=True),
        sa.Column("registered", sa.String(40), nullable=False),
        sa.Column("last_seen", sa.String(40), nullable=False),
        sa.Column("writes", sa.Integer(), nullable=False),
        sa.Column("status", JSONB, nullable=True),
    )
    for table, items in _keyed_tables(with_machine=True).items():
        _rebuild(table, items, machine)
    for table in COLUMN_TABLES:
        with op.batch_alter_table(table) as batch:
            batch.add_column(sa.Column("machine", sa.String(MACHINE), nullable=False, server_default=""))
        op.execute(sa.text(f"UPDATE {table} SET machine = :machine").bindparams(machine=machine))
        if table in INDEXED:
            op.create_index(INDEXED[table], table, ["machine", "id"])
    if _postgresql():
        for table, columns in JSON_COLUMNS.items():
            for column in columns:
                op.execute(f'ALTER TABLE {table} ALTER COLUMN "{column}" TYPE JSONB USING "{column}"::jsonb')


def downgrade() -> None:
    if _postgresql():
        for table, columns in JSON_COLUMNS.items():
            for column in columns:
                op.execute(f'ALTER TABLE {table} ALTER COLUMN "{column}" TYPE JSON USING "{column}"::json')
    for table in reversed(COLUMN_TABLES):
        if table in INDEXED:
            op.drop_index(INDEXED[table], table_name=table)
        with op.batch_alter_table(table) as batch:
            batch.drop_column("machine")
    for table, items in _keyed_tables(with_machine=False).items():
        _rebuild(table, items, None)
    op.drop_table("machines")

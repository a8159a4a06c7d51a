"""Alembic environment: runs online on the connection that ``db.database`` hands over.

There is no alembic.ini; ``db.database.alembic_config`` builds the configuration in code.
Offline (SQL script) mode is not supported: the database is always at hand.
"""

from alembic import context

from db.models import Base

connection = context.config.attributes.get("connection")
if connection is None:
    raise RuntimeError("run migrations through db.database (Config.attributes['connection'] is required)")

# render_as_batch: SQLite can only ALTER by copying a table; later migrations need it.
context.configure(connection=connection, target_metadata=Base.metadata, render_as_batch=True)
with context.begin_transaction():
    context.run_migrations()

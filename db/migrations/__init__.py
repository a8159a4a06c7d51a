"""Alembic migrations of the HMI database (applied by ``db.database.Database`` at start-up)."""

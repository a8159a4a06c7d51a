"""Persistence: SQLite (WAL) through SQLAlchemy 2, Alembic migrations, a unit-of-work API.

Usage::

    db = Database("data/hmi.db")
    with db.unit() as unit:          # one transaction
        before, after = unit.put_offset("G54", frame, source="edge.set")
        unit.add_log({"task": "edge.set", ...})

Imports nothing of ``app`` or ``engine`` (design.md §2).
"""

from db.database import Database, StorageUnavailable
from db.repository import Actor, OffsetSlot, Unit, acting_as, current_actor, identity_frame, offset_layout

__all__ = ["Actor", "Database", "OffsetSlot", "StorageUnavailable", "Unit", "acting_as", "current_actor", "identity_frame",
           "offset_layout"]

"""The measurement log (read side; the measuring workflow writes entries with its correction)."""

from __future__ import annotations

from app.errors import InvalidInput, NotFoundError
from db import Database


class LogService:
    def __init__(self, db: Database):
        self._db = db

    def list(self, limit: int = 100) -> list[dict]:
        """Newest first."""
        if isinstance(limit, bool) or not isinstance(limit, int) or not 1 <= limit <= 1000:
            raise InvalidInput("limit: must be 1..1000", field="limit")
        with self._db.unit(readonly=True) as unit:
            return unit.list_log(limit)

    def get(self, log_id: int) -> dict:
        if not 1 <= log_id < 2**63:          # SQLite integers are 64-bit; no such entry
            raise NotFoundError(f"no log entry {log_id}", field="log_id")
        with self._db.unit(readonly=True) as unit:
            entry = unit.get_log(log_id)
        if entry is None:
            raise NotFoundError(f"no log entry {log_id}")
        return entry

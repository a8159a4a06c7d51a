"""The measurement log (read side; the measuring workflow writes entries with its correction)."""

from __future__ import annotations

from collections.abc import Iterator

from app.errors import InvalidInput, NotFoundError
from db import Database


class LogService:
    def __init__(self, db: Database):
        self._db = db

    PAGE = 500

    def list(self, limit: int = 100, offset: int = 0, fields=None) -> list[dict]:
        """Newest first, ``limit`` entries after the newest ``offset``."""
        if isinstance(limit, bool) or not isinstance(limit, int) or not 1 <= limit <= 1000:
            raise InvalidInput("limit: must be 1..1000", field="limit")
        if isinstance(offset, bool) or not isinstance(offset, int) or not 0 <= offset < 2**62:
            raise InvalidInput("offset: must be 0 or more", field="offset")
        with self._db.unit(readonly=True) as unit:
            return unit.list_log(limit, offset, fields=fields)

    def count(self) -> int:
        with self._db.unit(readonly=True) as unit:
            return unit.count_log()

    def iterate(self, fields=None) -> Iterator[dict]:
        """Every entry, newest first, read page by page (exports stream them)."""
        before = None
        while True:
            with self._db.unit(readonly=True) as unit:
                page = unit.list_log(self.PAGE, before_id=before, fields=fields)
            yield from page
            if len(page) < self.PAGE:
                return
            before = page[-1]["id"]

    def get(self, log_id: int) -> dict:
        if not 1 <= log_id < 2**63:          # SQLite integers are 64-bit; no such entry
            raise NotFoundError(f"no log entry {log_id}", field="log_id")
        with self._db.unit(readonly=True) as unit:
            entry = unit.get_log(log_id)
        if entry is None:
            raise NotFoundError(f"no log entry {log_id}")
        return entry

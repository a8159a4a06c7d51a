"""SQLite engine set-up (WAL, foreign keys), migrations at start-up, default data, units of work."""

from __future__ import annotations

import functools
import sqlite3
import threading
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

from alembic import command
from alembic.config import Config
from alembic.runtime.migration import MigrationContext
from alembic.script import ScriptDirectory
from sqlalchemy import Connection, Engine, create_engine, event
from sqlalchemy.exc import DBAPIError, OperationalError
from sqlalchemy.orm import Session
from sqlalchemy.pool import ConnectionPoolEntry

from db.repository import Unit, offset_layout, seed_defaults

MIGRATIONS_DIR = Path(__file__).resolve().parent / "migrations"


class StorageUnavailable(Exception):
    """The database cannot be opened or written (disk full, read-only file, gone): nothing of the
    transaction was stored. ``str()`` names the file and the cause."""
BUSY_TIMEOUT_MS = 10_000


def alembic_config(connection: Connection | None = None) -> Config:
    """Alembic configuration built in code, valid from any cwd and from an installed package."""
    config = Config()
    config.set_main_option("script_location", str(MIGRATIONS_DIR))
    config.attributes["connection"] = connection
    return config


@functools.cache
def head_revision() -> str | None:
    """The newest migration; read once per process (it is start-up's only file scan)."""
    return ScriptDirectory.from_config(alembic_config()).get_current_head()


def upgrade_to_head(connection: Connection) -> None:
    """``alembic upgrade head`` on an open connection; skipped cheaply when already current."""
    if MigrationContext.configure(connection).get_current_revision() != head_revision():
        command.upgrade(alembic_config(connection), "head")


class Database:
    """One SQLite file: opens, migrates and seeds it; hands out units of work.

    Every unit is one transaction. Writing units take SQLite's write lock at BEGIN (``BEGIN
    IMMEDIATE``), so read-modify-write sequences of two processes cannot interleave; read-only
    units (``unit(readonly=True)``) start deferred and never block a writer in WAL mode.
    """

    def __init__(
        self,
        path: str | Path,
        extra_settable: int = 4,
        basic_frames: int = 2,
        rotary_axes: Sequence[str] = (),
    ):
        self.path = Path(path)
        self._layout = offset_layout(extra_settable, basic_frames)
        self._generation = 0                   # committed write units so far (see ``generation``)
        self._write_turn = threading.RLock()   # held by this process's writing unit
        self._rotary_axes = tuple(rotary_axes)
        # check_same_thread off: the pool hands connections to FastAPI's worker threads.
        self._engine = create_engine(f"sqlite:///{self.path}", connect_args={"check_same_thread": False})
        event.listen(self._engine, "connect", _configure_sqlite_connection)
        event.listen(self._engine, "begin", _begin_transaction)
        self._write_engine = self._engine.execution_options(sqlite_begin="BEGIN IMMEDIATE")
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            with self._write_engine.begin() as connection:
                upgrade_to_head(connection)
            with Session(self._write_engine) as session, session.begin():
                seed_defaults(session, self._layout, self._rotary_axes)
        except (OSError, DBAPIError) as exc:
            self._engine.dispose()
            raise StorageUnavailable(f"cannot open the database {self.path}: {_cause(exc)}") from exc

    @contextmanager
    def unit(self, readonly: bool = False) -> Iterator[Unit]:
        """One transaction: commits when the block ends normally, rolls back on an exception."""
        if readonly:
            with Session(self._engine) as session:  # closing rolls back
                event.listen(session, "before_flush", _refuse_write)
                unit = Unit(session, self._layout)
                try:
                    yield unit
                finally:
                    unit.detach()
            return
        # This process's writers take turns from BEGIN until the count is raised after the
        # commit: a writer never sees a committed change not yet counted, and a reader that
        # read the count before a commit sees it raised afterwards (see ``generation``).
        if not self._write_turn.acquire(timeout=BUSY_TIMEOUT_MS / 1000):
            raise StorageUnavailable(f"the database {self.path} cannot be written: another write "
                                     f"did not end within {BUSY_TIMEOUT_MS // 1000} s")
        try:
            with Session(self._write_engine, expire_on_commit=False) as session, session.begin():
                unit = Unit(session, self._layout)
                try:
                    yield unit
                finally:
                    unit.detach()
            self._generation += 1
        except OperationalError as exc:      # disk full, read-only file, I/O error: rolled back
            raise StorageUnavailable(f"the database {self.path} cannot be written: {_cause(exc)}") from exc
        finally:
            self._write_turn.release()

    @property
    def generation(self) -> int:
        """Counts this process's committed writes, raised after each commit: what a reader reads
        after reading the count is still the stored value while the count stays the same (this
        process is the database's only writer), so it may be cached under the count read."""
        return self._generation

    def offset_names(self) -> list[str]:
        """The configured frames in chain order (fixed when the database is opened)."""
        return [slot.name for slot in self._layout]

    @property
    def engine(self) -> Engine:
        """The SQLAlchemy engine (for db-level tools and tests; the app uses ``unit()``)."""
        return self._engine

    def close(self) -> None:
        self._engine.dispose()

    def __enter__(self) -> Database:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()


def _cause(exc: Exception) -> str:
    """The driver's own words (e.g. "database or disk is full"), without SQL and parameters."""
    original = getattr(exc, "orig", None) or exc
    return str(original).splitlines()[0] if str(original) else type(original).__name__


def _configure_sqlite_connection(dbapi_connection: sqlite3.Connection, _connection_record: ConnectionPoolEntry) -> None:
    # Take transaction control from pysqlite: SQLAlchemy's "begin" event emits BEGIN itself.
    dbapi_connection.isolation_level = None
    cursor = dbapi_connection.cursor()
    cursor.execute(f"PRAGMA busy_timeout={BUSY_TIMEOUT_MS}")  # first: switching to WAL may wait for a lock
    cursor.execute("PRAGMA journal_mode=WAL")
    cursor.execute("PRAGMA foreign_keys=ON")
    cursor.close()


def _refuse_write(*_args: object) -> None:
    raise RuntimeError("write attempted in a read-only unit")


def _begin_transaction(connection: Connection) -> None:
    connection.exec_driver_sql(connection.get_execution_options().get("sqlite_begin", "BEGIN"))

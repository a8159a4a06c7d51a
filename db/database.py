"""Engine set-up (SQLite file with WAL and foreign keys, or PostgreSQL through psycopg 3), migrations
at start-up, default data, units of work (design.md §10.5)."""

from __future__ import annotations

import functools
import logging
import re
import socket
import sqlite3
import threading
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any, cast

from alembic import command
from alembic.config import Config
from alembic.runtime.migration import MigrationContext
from alembic.script import ScriptDirectory
from sqlalchemy import (
    URL,
    Connection,
    Engine,
    Table,
    bindparam,
    create_engine,
    event,
    make_url,
    select,
    update,
)
from sqlalchemy.exc import DBAPIError, OperationalError
from sqlalchemy.orm import Session
from sqlalchemy.pool import ConnectionPoolEntry, NullPool

from db.models import Machine
from db.repository import Unit, offset_layout, seed_defaults, utc_now

MIGRATIONS_DIR = Path(__file__).resolve().parent / "migrations"
log = logging.getLogger(__name__)


class StorageUnavailable(Exception):
    """The database cannot be opened or written (disk full, read-only file, gone): nothing of the
    transaction was stored. ``str()`` names the cause; only the start-up's message (for the one who
    starts the HMI, never a client's answer) names the file."""
BUSY_TIMEOUT_MS = 10_000
MACHINE_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,63}")
# pg_advisory_xact_lock key of migrating and seeding: HMIs starting together take turns
MIGRATION_LOCK = 0x484D4931


def default_machine_name() -> str:
    """The host name (its first label), the machine name when none is given."""
    name = socket.gethostname().split(".")[0] or "hmi"
    return name if MACHINE_NAME.fullmatch(name) else "hmi"


def check_machine_name(name: str) -> str:
    if not isinstance(name, str) or not MACHINE_NAME.fullmatch(name):
        raise ValueError(f"machine name must be 1-64 letters, digits, '.', '_' or '-' (starting with a "
                         f"letter or digit), got {name!r}")
    return name


def database_url(target: str | Path) -> URL:
    """``--db`` as a SQLAlchemy URL: a ``postgresql://`` (driver psycopg 3) or ``sqlite://`` URL
    as given, anything else a SQLite file path."""
    text = str(target)
    if "://" not in text:
        return URL.create("sqlite", database=text)
    url = make_url(text)
    if url.get_backend_name() == "postgresql":
        return url.set(drivername="postgresql+psycopg")
    if url.get_backend_name() != "sqlite":
        raise ValueError(f"the database must be a SQLite file or a postgresql:// URL, got {url.get_backend_name()}://")
    return url


def alembic_config(connection: Connection | None = None, machine: str | None = None) -> Config:
    """Alembic configuration built in code, valid from any cwd and from an installed package.
    ``machine``: the name that rows stored before plant mode (0008) are given."""
    config = Config()
    config.set_main_option("script_location", str(MIGRATIONS_DIR))
    config.attributes["connection"] = connection
    config.attributes["machine"] = machine or default_machine_name()
    return config


@functools.cache
def head_revision() -> str | None:
    """The newest migration; read once per process (it is start-up's only file scan)."""
    return ScriptDirectory.from_config(alembic_config()).get_current_head()


def upgrade_to_head(connection: Connection, machine: str | None = None) -> None:
    """``alembic upgrade head`` on an open connection; skipped cheaply when already current."""
    if MigrationContext.configure(connection).get_current_revision() != head_revision():
        command.upgrade(alembic_config(connection, machine), "head")


class Database:
    """One database: a SQLite file or a PostgreSQL database shared by the HMIs of a plant. Opens,
    migrates and seeds it; hands out units of work on the rows of one machine (``machine``).

    Every unit is one transaction. A writing unit first raises its machine's write count
    (``machines.writes``): on PostgreSQL that row lock makes the writers of one machine take turns
    across processes until the commit; on SQLite the file's write lock, taken at BEGIN (``BEGIN
    IMMEDIATE``), does. So read-modify-write sequences of two processes cannot interleave.
    Read-only units (``unit(readonly=True)``) never block a writer.
    """

    def __init__(
        self,
        path: str | Path,
        extra_settable: int = 4,
        basic_frames: int = 2,
        rotary_axes: Sequence[str] = (),
        machine: str | None = None,
        stand_in: bool = False,
    ):
        self.url = database_url(path)
        self.is_sqlite = self.url.get_backend_name() == "sqlite"
        self.path: Path | None = Path(self.url.database or "") if self.is_sqlite else None
        self.where = str(self.path) if self.is_sqlite else self.url.render_as_string(hide_password=True)
        self.machine = check_machine_name(default_machine_name() if machine is None else machine)
        self._layout = offset_layout(extra_settable, basic_frames)
        self._write_turn = threading.RLock()   # held by this process's writing unit
        self._rotary_axes = tuple(rotary_axes)
        # SQLite: the write count is read over a plain connection of each thread (no pool, no
        # SQLAlchemy statement: a poll reads it several times; issue 30 item 2)
        self._count_readers = threading.local()
        self._count_connections: list[sqlite3.Connection] = []
        self._count_lock = threading.Lock()
        if self.is_sqlite:
            # check_same_thread off: the pool hands connections to FastAPI's worker threads.
            self._engine = create_engine(self.url, connect_args={"check_same_thread": False})
            event.listen(self._engine, "connect", _configure_sqlite_connection)
            event.listen(self._engine, "begin", _begin_transaction)
            self._write_engine: Engine = self._engine.execution_options(sqlite_begin="BEGIN IMMEDIATE")
        else:
            # a writer waits at most as long as on SQLite for another machine's turn to end
            self._engine = create_engine(self.url, pool_pre_ping=True, connect_args={
                "options": f"-c lock_timeout={BUSY_TIMEOUT_MS} -c timezone=UTC", "connect_timeout": 10})
            self._write_engine = self._engine
        if stand_in and not self.is_sqlite and not self._reachable():
            return
        try:
            file = self._sqlite_file()
            if file is not None:
                file.parent.mkdir(parents=True, exist_ok=True)
            with self._write_engine.begin() as connection:
                self._migration_turn(connection)
                upgrade_to_head(connection, self.machine)
            with Session(self._write_engine) as session, session.begin():
                self._migration_turn(session.connection())
                seed_defaults(session, self._layout, self._rotary_axes, self.machine)
        except (OSError, DBAPIError) as exc:
            self._engine.dispose()
            if not self._readable_file():
                raise StorageUnavailable(f"cannot open the database {self.where}: {_cause(exc)}") from exc
            self._open_read_only(exc)

    # --- a database that can be read but not written (design.md §10.8) ------------------------
    read_only: str | None = None       # why nothing can be written (None: it can)
    unreachable = False                # a PostgreSQL server that could not be reached: the stand-in serves

    def _reachable(self) -> bool:
        """PostgreSQL, opened with ``stand_in`` (the HMI server, not the command line's
        administration): True when a connection can be made; else a stand-in is opened: an
        in-memory SQLite database with this machine's default rows, which the start-up may fill
        (default tools, the spindle's tool) until :meth:`start_up_done` makes it read only (nothing
        stored can be shown; a write answers 503 as on a read-only file). Any error after
        connecting (permissions, a broken migration) still stops the start."""
        try:
            with self._engine.connect():
                return True
        except (OSError, DBAPIError) as exc:
            cause = exc
        self._engine.dispose()
        log.error("database %s cannot be reached: %s; serving read only with the default data",
                  self.where, str(getattr(cause, "orig", None) or cause).strip())
        self.is_sqlite, self.url, self.path = True, make_url("sqlite://"), None
        # a shared in-memory database: a connection per checkout (threads never share one), kept
        # alive by the keeper connection until close()
        name = f"file:hmi-stand-in-{id(self):x}?mode=memory&cache=shared"

        def connect() -> sqlite3.Connection:
            connection = sqlite3.connect(name, uri=True, check_same_thread=False, isolation_level=None)
            # readers take no table locks of the shared cache (a start-up write beside an open
            # reading unit would else fail with "database table is locked")
            connection.execute("PRAGMA read_uncommitted = 1")
            return connection

        self._stand_in_keeper = connect()
        self._engine = create_engine("sqlite://", creator=connect, poolclass=NullPool)
        event.listen(self._engine, "begin", _begin_transaction)
        self._write_engine = self._engine
        with self._engine.begin() as connection:
            upgrade_to_head(connection, self.machine)
        with Session(self._engine) as session, session.begin():
            seed_defaults(session, self._layout, self._rotary_axes, self.machine)
        self.unreachable = True
        return False

    def start_up_done(self) -> None:
        """The stand-in of an unreachable database is read only from now on (see ``_reachable``)."""
        if self.unreachable:
            # the driver's words name the server's address: the log has them, a client's answer not
            self.read_only = "the database cannot be reached"

    def _sqlite_file(self) -> Path | None:
        if not self.is_sqlite or self.path is None or str(self.path) in ("", ":memory:"):
            return None
        text = str(self.path)
        return Path(text[len("file:"):]) if text.startswith("file:") else self.path

    def _readable_file(self) -> bool:
        file = self._sqlite_file()
        return file is not None and file.is_file()

    def _read_only_connection(self) -> sqlite3.Connection:
        """A connection that never writes: ``mode=ro``, or ``immutable=1`` where even the WAL's
        shared-memory file cannot be made (a read-only folder or medium)."""
        last: sqlite3.Error | None = None
        for flags in ("mode=ro", "mode=ro&immutable=1"):
            try:
                connection = sqlite3.connect(f"file:{self._sqlite_file()}?{flags}", uri=True,
                                             check_same_thread=False, isolation_level=None)
                connection.execute("SELECT count(*) FROM sqlite_master").fetchone()
                return connection
            except sqlite3.Error as exc:
                last = exc
        raise StorageUnavailable(f"cannot read the database {self.where}: {last}")

    def _open_read_only(self, cause: Exception) -> None:
        """Serve what the file holds, read only: writing units raise StorageUnavailable at once. A
        file of another schema version or without this machine's rows cannot be served."""
        try:
            self._read_only_connection().close()      # readable at all?
        except StorageUnavailable:
            raise StorageUnavailable(f"cannot open the database {self.where}: {_cause(cause)}") from cause
        self._engine = create_engine("sqlite://", creator=self._read_only_connection)
        event.listen(self._engine, "begin", _begin_transaction)
        self._write_engine = self._engine
        with self._engine.connect() as connection:
            revision = MigrationContext.configure(connection).get_current_revision()
            known = revision == head_revision() and connection.scalar(
                select(Machine.name).where(Machine.name == self.machine)) is not None
        if not known:
            self._engine.dispose()
            raise StorageUnavailable(f"cannot open the database {self.where}: it cannot be written "
                                     f"({_cause(cause)}) and is not ready for this HMI to read")
        self.read_only = f"the database cannot be written: {_cause(cause)}"
        log.warning("database %s opened read only: %s", self.where, _cause(cause))

    def _migration_turn(self, connection: Connection) -> None:
        """PostgreSQL: HMIs starting at once migrate and seed one after the other (SQLite: BEGIN
        IMMEDIATE already did)."""
        if not self.is_sqlite:
            connection.exec_driver_sql(f"SELECT pg_advisory_xact_lock({MIGRATION_LOCK})")

    @contextmanager
    def unit(self, readonly: bool = False) -> Iterator[Unit]:
        """One transaction: commits when the block ends normally, rolls back on an exception."""
        if self.read_only and not readonly:
            raise StorageUnavailable(self.read_only)
        if readonly:
            with Session(self._engine) as session:  # closing rolls back
                event.listen(session, "before_flush", _refuse_write)
                unit = Unit(session, self._layout, self.machine)
                try:
                    yield unit
                finally:
                    unit.detach()
            return
        # This process's writers take turns (one connection, not a queue at the database); the
        # write count rises in the unit's own transaction, so it is raised exactly when the unit's
        # changes become visible, to every process (see ``generation``).
        if not self._write_turn.acquire(timeout=BUSY_TIMEOUT_MS / 1000):
            raise StorageUnavailable(f"the database cannot be written: another write "
                                     f"did not end within {BUSY_TIMEOUT_MS // 1000} s")
        try:
            with Session(self._write_engine, expire_on_commit=False) as session, session.begin():
                session.connection().execute(_COUNT_WRITE, {"machine": self.machine, "now": utc_now()})
                unit = Unit(session, self._layout, self.machine)
                try:
                    yield unit
                finally:
                    unit.detach()
        except OperationalError as exc:      # disk full, read-only file, I/O error, lock timeout: rolled back
            log.error("database %s cannot be written: %s", self.where, _cause(exc))
            raise StorageUnavailable(f"the database cannot be written: {_cause(exc)}") from exc
        finally:
            self._write_turn.release()

    @property
    def generation(self) -> int:
        """This machine's committed write units, of every process on the database (read from it):
        raised in the same transaction as the unit's changes, so what a reader reads after reading
        the count is still the stored value while the count stays the same and may be cached
        under the count read."""
        if self.is_sqlite and self.url.database not in (None, "", ":memory:"):
            return self._sqlite_generation()
        with self._engine.connect() as connection:
            count = connection.scalar(select(Machine.writes).where(Machine.name == self.machine))
        return int(count or 0)

    def _sqlite_generation(self) -> int:
        connection = getattr(self._count_readers, "connection", None)
        if connection is None and self.read_only:
            connection = self._read_only_connection()
            self._count_readers.connection = connection
            with self._count_lock:
                self._count_connections.append(connection)
        if connection is None:
            # autocommit: each read is its own transaction and sees every committed write
            connection = sqlite3.connect(str(self.path), isolation_level=None, check_same_thread=False)
            connection.execute(f"PRAGMA busy_timeout={BUSY_TIMEOUT_MS}")
            self._count_readers.connection = connection
            with self._count_lock:
                self._count_connections.append(connection)
        try:
            row = connection.execute(_WRITE_COUNT_SQL, (self.machine,)).fetchone()
        except sqlite3.Error as exc:
            raise StorageUnavailable(f"the database cannot be read: {_cause(exc)}") from exc
        return int(row[0] or 0) if row is not None else 0

    def report_status(self, status: dict[str, Any]) -> None:
        """This HMI is alive, with ``status`` (alarms, mode, ...) for the plant view: its machines
        row only, outside the write count (no cache need read again for it)."""
        if self.read_only:          # a read-only HMI reports nothing (its row keeps the last report)
            return
        try:
            with self._write_engine.begin() as connection:
                connection.execute(update(Machine).where(Machine.name == self.machine)
                                   .values(last_seen=utc_now(), status=status))
        except OperationalError as exc:
            raise StorageUnavailable(f"the database cannot be written: {_cause(exc)}") from exc

    def offset_names(self) -> list[str]:
        """The configured frames in chain order (fixed when the database is opened)."""
        return [slot.name for slot in self._layout]

    @property
    def engine(self) -> Engine:
        """The SQLAlchemy engine (for db-level tools and tests; the app uses ``unit()``)."""
        return self._engine

    def close(self) -> None:
        with self._count_lock:
            for connection in self._count_connections:
                connection.close()
            self._count_connections.clear()
        self._engine.dispose()
        keeper = getattr(self, "_stand_in_keeper", None)
        if keeper is not None:
            keeper.close()

    def __enter__(self) -> Database:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()


def _cause(exc: Exception) -> str:
    """The driver's own words (e.g. "database or disk is full"), without SQL, parameters and file
    paths (an answer to a client never shows where the server keeps its files)."""
    original = getattr(exc, "orig", None) or exc
    text = str(original).splitlines()[0] if str(original) else type(original).__name__
    return _PATH.sub("<path>", text)


_PATH = re.compile(r"(?:[A-Za-z]:)?(?:[\\/][^\s\\/:\"']+){2,}[\\/]?")


# a writing unit raises the write count (prepared once: Core, no ORM synchronisation)
_MACHINES = cast(Table, Machine.__table__)
_COUNT_WRITE = (update(_MACHINES).where(_MACHINES.c.name == bindparam("machine"))
                .values(writes=_MACHINES.c.writes + 1, last_seen=bindparam("now")))
_WRITE_COUNT_SQL = (f"SELECT {Machine.__table__.c.writes.name} FROM {Machine.__tablename__} "
                   f"WHERE {Machine.__table__.c.name.name} = ?")


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

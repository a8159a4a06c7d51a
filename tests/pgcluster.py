"""A private PostgreSQL cluster for tests and benchmarks (Debian's ``postgresql`` package).

``with PgCluster() as cluster: url = cluster.new_database()`` initialises a cluster in a fresh
temporary directory, serves it on a Unix socket there only (no TCP port, nothing shared with
other clusters), and stops it and removes the directory at the end: no server is left running.

PostgreSQL refuses to run as root; as root the cluster runs as the ``postgres`` user the Debian
package creates.
"""

from __future__ import annotations

import itertools
import os
import pwd
import shutil
import subprocess
import tempfile
from pathlib import Path

PG_ROOT = Path("/usr/lib/postgresql")


def pg_bin_dir() -> Path | None:
    """The newest installed server's bin directory (Debian: /usr/lib/postgresql/<major>/bin)."""
    if not PG_ROOT.is_dir():
        return None
    found = sorted((p for p in PG_ROOT.iterdir() if (p / "bin" / "initdb").exists()),
                   key=lambda p: int(p.name) if p.name.isdigit() else 0)
    return found[-1] / "bin" if found else None


def database_settings(target: str | Path) -> dict[str, str | Path]:
    """The ``app.config.Settings`` fields for a test's database: db_url for a URL, else db_path."""
    return {"db_url": target} if isinstance(target, str) else {"db_path": target}


def available() -> bool:
    return pg_bin_dir() is not None


class PgCluster:
    """initdb + pg_ctl in a temporary directory; ``url(name)`` is a SQLAlchemy URL (psycopg 3)."""

    def __init__(self) -> None:
        bin_dir = pg_bin_dir()
        if bin_dir is None:
            raise RuntimeError("PostgreSQL is not installed (Debian: apt-get install postgresql)")
        self._bin = bin_dir
        self._run_as = "postgres" if os.geteuid() == 0 else None
        self.dir = Path(tempfile.mkdtemp(prefix="hmi-pg-"))
        self.data = self.dir / "data"
        self._names = itertools.count(1)
        self._running = False

    def _command(self, *args: str) -> list[str]:
        command = [str(self._bin / args[0]), *args[1:]]
        return ["runuser", "-u", self._run_as, "--", *command] if self._run_as else command

    def start(self) -> PgCluster:
        if self._run_as:
            entry = pwd.getpwnam(self._run_as)
            os.chown(self.dir, entry.pw_uid, entry.pw_gid)
        subprocess.run(self._command("initdb", "-D", str(self.data), "-U", "postgres", "--auth=trust",
                                     "-E", "UTF8", "--locale=C.UTF-8"),
                       check=True, capture_output=True)
        # Unix socket in the private directory only; fsync off: a test cluster needs no durability
        options = f"-k {self.dir} -c listen_addresses='' -c fsync=off -c max_connections=200"
        subprocess.run(self._command("pg_ctl", "-D", str(self.data), "-l", str(self.dir / "log"), "-w",
                                     "-o", options, "start"), check=True, capture_output=True)
        self._running = True
        return self

    def url(self, database: str = "postgres") -> str:
        return f"postgresql+psycopg://postgres@/{database}?host={self.dir}"

    def new_database(self, name: str | None = None) -> str:
        """A new empty database; its URL."""
        import psycopg

        name = name or f"hmi_{next(self._names)}"
        with psycopg.connect(f"dbname=postgres user=postgres host={self.dir}", autocommit=True) as conn:
            conn.execute(f'CREATE DATABASE "{name}"')
        return self.url(name)

    def stop(self) -> None:
        if self._running:
            subprocess.run(self._command("pg_ctl", "-D", str(self.data), "-m", "immediate", "-w", "stop"),
                           check=False, capture_output=True)
            self._running = False
        shutil.rmtree(self.dir, ignore_errors=True)

    def __enter__(self) -> PgCluster:
        return self.start()

    def __exit__(self, *exc_info: object) -> None:
        self.stop()

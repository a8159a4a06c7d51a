from pathlib import Path

import pytest

from db import Database


@pytest.fixture
def db_path(database_target: Path | str) -> Path | str:
    """A SQLite file, or with --db-engine=postgresql a new database's URL (tests/conftest.py)."""
    return database_target


@pytest.fixture
def db(db_path: Path):
    database = Database(db_path)
    yield database
    database.close()

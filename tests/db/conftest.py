from pathlib import Path

import pytest

from db import Database


@pytest.fixture
def db_path(tmp_path: Path) -> Path:
    return tmp_path / "data" / "hmi.db"


@pytest.fixture
def db(db_path: Path):
    database = Database(db_path)
    yield database
    database.close()

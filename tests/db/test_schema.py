"""Migrations, SQLite settings, seeding and configuration of the frame layout."""

import sqlite3
from pathlib import Path

import pytest
from alembic import command
from alembic.autogenerate import compare_metadata
from alembic.runtime.migration import MigrationContext
from sqlalchemy import inspect, text
from sqlalchemy.exc import IntegrityError

from db import Database
from db.database import alembic_config, head_revision
from db.models import Base

TABLES = {"frames", "offset_audit", "tools", "probes", "tool_probes", "settings", "measurement_log",
          "machine_state"}


def raw_query(path: Path, sql: str, *params) -> list[tuple]:
    """Reads the file with the standard library's sqlite3: independent of SQLAlchemy."""
    connection = sqlite3.connect(path)
    try:
        return connection.execute(sql, params).fetchall()
    finally:
        connection.close()


@pytest.mark.sqlite_only
def test_migration_creates_all_tables_in_wal_mode(db, db_path):
    tables = {name for (name,) in raw_query(db_path, "SELECT name FROM sqlite_master WHERE type='table'")}
    assert TABLES | {"alembic_version"} <= tables
    assert raw_query(db_path, "PRAGMA journal_mode") == [("wal",)]
    assert raw_query(db_path, "SELECT version_num FROM alembic_version") == [(head_revision(),)]


@pytest.mark.sqlite_only
def test_connections_enforce_foreign_keys_and_wait_when_busy(db):
    with db.engine.connect() as connection:
        assert connection.exec_driver_sql("PRAGMA foreign_keys").scalar() == 1
        assert connection.exec_driver_sql("PRAGMA busy_timeout").scalar() >= 1000


def test_migration_matches_the_models(db):
    with db.engine.connect() as connection:
        assert compare_metadata(MigrationContext.configure(connection), Base.metadata) == []


def test_frames_table_refuses_a_rotation_about_a_rotary_axis(db):
    with pytest.raises(IntegrityError, match="ck_frames_rot_geometry_only"), db.engine.begin() as connection:
        connection.execute(text(
            "INSERT INTO frames (channel, name, kind, frame_index, axis, coarse, fine, rot, mirror, scale) "
            "VALUES (1, 'G54', 'settable', 1, 'C', 0, 0, 5.0, false, 1)"))


def test_seeding_gives_identity_frames_and_empty_probe_records(db):
    with db.unit() as unit:
        assert unit.offset_names() == ["BASIC_REF", "BASIC_0", "BASIC_1", "G54", "G55", "G56", "G57",
                                       "G505", "G506", "G507", "G508"]
        identity = {"trans": {"X": 0.0, "Y": 0.0, "Z": 0.0}, "fine": {"X": 0.0, "Y": 0.0, "Z": 0.0},
                    "rot": {"X": 0.0, "Y": 0.0, "Z": 0.0}}
        assert unit.list_offsets() == dict.fromkeys(unit.offset_names(), identity)
        assert unit.list_probes() == [{"number": 1}, {"number": 2}, {"number": 3}]
        assert unit.list_tool_probes() == [{"number": 1}, {"number": 2}, {"number": 3}]
        assert unit.list_tools() == []
        assert unit.get_settings() == {}
        assert unit.list_log() == [] and unit.audit() == []


@pytest.mark.sqlite_only
def test_seeding_is_idempotent_and_keeps_data(db, db_path):
    with db.unit() as unit:
        unit.put_offset("G55", {"trans": {"X": 12.5}}, source="test")
        unit.put_probe(1, {"effective_diameter": 3.998})
    db.close()
    counts = [raw_query(db_path, f"SELECT COUNT(*) FROM {table}")[0][0] for table in sorted(TABLES)]

    reopened = Database(db_path)
    try:
        assert [raw_query(db_path, f"SELECT COUNT(*) FROM {table}")[0][0] for table in sorted(TABLES)] == counts
        with reopened.unit() as unit:
            assert unit.get_offset("G55")["trans"]["X"] == 12.5
            assert unit.get_probe(1) == {"effective_diameter": 3.998, "number": 1}
    finally:
        reopened.close()
    assert raw_query(db_path, "SELECT COUNT(*) FROM frames")[0][0] == 11 * 3


def test_frame_layout_is_configurable(tmp_path):
    with Database(tmp_path / "a.db", extra_settable=0, basic_frames=1) as database, database.unit() as unit:
        assert unit.offset_names() == ["BASIC_REF", "BASIC_0", "G54", "G55", "G56", "G57"]
        with pytest.raises(KeyError):
            unit.put_offset("G505", {}, source="test")
    with Database(tmp_path / "b.db", extra_settable=95, basic_frames=0) as database, database.unit() as unit:
        names = unit.offset_names()
        assert names[:2] == ["BASIC_REF", "G54"] and names[-1] == "G599" and len(names) == 1 + 4 + 95


def test_frame_layout_rejects_impossible_counts(tmp_path):
    with pytest.raises(ValueError):
        Database(tmp_path / "a.db", extra_settable=96)
    with pytest.raises(ValueError):
        Database(tmp_path / "b.db", basic_frames=-1)


def test_growing_the_layout_adds_frames_and_keeps_the_rest(db_path):
    with Database(db_path, extra_settable=1) as database, database.unit() as unit:
        unit.put_offset("G505", {"trans": {"Y": -3.0}}, source="test")
    with Database(db_path, extra_settable=2, rotary_axes=("C",)) as database, database.unit() as unit:
        assert unit.offset_names()[-2:] == ["G505", "G506"]
        assert unit.get_offset("G505")["trans"] == {"X": 0.0, "Y": -3.0, "Z": 0.0, "C": 0.0}
        assert unit.get_offset("G506")["trans"] == {"X": 0.0, "Y": 0.0, "Z": 0.0, "C": 0.0}


def test_works_from_any_working_directory(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with Database("relative/hmi.db") as database, database.unit() as unit:
        assert unit.get_offset("G54") is not None
    assert (tmp_path / "relative" / "hmi.db").exists()


def test_opening_a_current_database_runs_no_migration(db_path, monkeypatch):
    Database(db_path).close()

    def no_upgrade(*_args, **_kwargs):
        raise AssertionError("a current schema needs no Alembic run")

    monkeypatch.setattr("db.database.command.upgrade", no_upgrade)
    with Database(db_path) as database, database.unit() as unit:
        assert unit.get_offset("G54") is not None


def test_migration_downgrades_to_an_empty_database_and_back(db, db_path):
    with db.engine.begin() as connection:
        command.downgrade(alembic_config(connection, db.machine), "base")
    assert not TABLES & set(inspect(db.engine).get_table_names())
    db.close()
    with Database(db_path) as again:
        assert TABLES <= set(inspect(again.engine).get_table_names())

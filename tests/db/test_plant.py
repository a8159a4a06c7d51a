"""Plant mode (design.md §10.5): many HMIs on one database, each with its own machine's rows, and a
write count every process sees. Runs on SQLite and, with --db-engine=postgresql, on PostgreSQL."""

from __future__ import annotations

import sqlite3

import pytest

from db import Database, acting_as
from db.database import alembic_config, database_url
from db.repository import Actor

G54_A = {"trans": {"X": 101.25, "Y": -20.5, "Z": 3.0}}
G54_B = {"trans": {"X": -7.75, "Y": 44.0, "Z": -1.5}}


@pytest.fixture
def two_machines(db_path):
    with Database(db_path, machine="mill-a") as a, Database(db_path, machine="mill-b") as b:
        yield a, b


def test_two_machines_never_see_each_others_rows(two_machines):
    a, b = two_machines
    with acting_as(Actor("user:anna", 3)), a.unit() as unit:
        unit.put_offset("G54", G54_A, source="test")
        unit.put_tool(1, {"length": 80.0, "radius": 4.0}, source="test")
        unit.put_probe(1, {"effective_diameter": 3.99})
        unit.put_memory("EV", 1, 0.25, source="test")
        unit.put_settings({"plane": 18})
        unit.set_state("tool", 1)
        unit.put_program("P1", "G0 X0\n")
        log_a = unit.add_log({"task": "edge.set", "target": "G54"})
        part_a = unit.add_part({"part_number": "PN-1"})
    with acting_as(Actor("user:bert", 3)), b.unit() as unit:
        unit.put_offset("G54", G54_B, source="test")
        unit.put_tool(1, {"length": 120.0}, source="test")
    with a.unit(readonly=True) as unit:
        assert unit.get_offset("G54")["trans"] == {"X": 101.25, "Y": -20.5, "Z": 3.0}
        assert unit.get_tool(1)["length"] == 80.0
    with b.unit(readonly=True) as unit:
        assert unit.get_offset("G54")["trans"] == {"X": -7.75, "Y": 44.0, "Z": -1.5}
        assert unit.get_tool(1)["length"] == 120.0 and unit.get_tool(1)["radius"] == 0.0
        assert unit.get_probe(1) == {"number": 1} and unit.get_memory("EV", 1) == 0.0
        assert unit.get_settings() == {} and unit.get_state("tool") is None
        assert unit.list_programs() == [] and unit.get_program("P1") is None
        assert unit.list_log() == [] and unit.get_log(log_a) is None
        assert unit.list_parts() == [] and unit.get_part(part_a["id"]) is None
        audit = unit.audit()
    assert [(row["machine"], row["who"], row["offset"]) for row in audit] == [
        ("mill-b", "user:bert", "T1"), ("mill-b", "user:bert", "G54")]


def test_the_write_count_is_the_databases_not_the_processes(db_path):
    """A second Database object on the same machine stands for a second HMI process: its commit
    raises the count the first one reads, so no cache keeps the old value."""
    with Database(db_path, machine="mill-a") as first, Database(db_path, machine="mill-a") as second, \
            Database(db_path, machine="mill-b") as other:
        seen = first.generation
        with second.unit() as unit:
            unit.put_offset("G54", G54_A, source="test")
        assert first.generation == seen + 1
        with other.unit() as unit:            # another machine's write: not this machine's data
            unit.put_offset("G54", G54_B, source="test")
        assert first.generation == seen + 1
        with first.unit(readonly=True) as unit:
            assert unit.get_offset("G54")["trans"]["X"] == 101.25


def test_machine_names_are_checked(db_path):
    for bad in ("", "a b", "../x", "x" * 65, "-lead"):
        with pytest.raises(ValueError, match="machine name"):
            Database(db_path, machine=bad)


def test_database_url_forms(tmp_path):
    assert database_url(tmp_path / "h.db").get_backend_name() == "sqlite"
    assert database_url("postgresql://hmi@db.plant/hmi").drivername == "postgresql+psycopg"
    assert database_url("postgresql+psycopg://hmi@db.plant/hmi").database == "hmi"
    with pytest.raises(ValueError, match="postgresql"):
        database_url("mysql://x@y/z")


@pytest.mark.sqlite_only
def test_a_single_machine_database_migrates_to_the_name_of_the_hmi_that_opens_it(tmp_path):
    """Rows stored before plant mode (revision 0007) become the migrating HMI's."""
    from alembic import command
    from sqlalchemy import create_engine

    path = tmp_path / "old.db"
    engine = create_engine(f"sqlite:///{path}")
    with engine.begin() as connection:
        command.upgrade(alembic_config(connection), "0007")
    engine.dispose()
    old = sqlite3.connect(path)
    old.execute("INSERT INTO tools (t, type, length, radius, wear_length, wear_radius) VALUES (5, 120, 90, 3, 0, 0)")
    old.execute("INSERT INTO frames (channel, name, kind, frame_index, axis, coarse, fine, rot, mirror, scale) "
                "VALUES (1, 'G54', 'settable', 1, 'X', 12.5, 0, 0, 0, 1)")
    old.execute("INSERT INTO settings (key, value) VALUES ('plane', '18')")
    old.commit()
    old.close()
    with Database(path, machine="mill-a") as db, db.unit(readonly=True) as unit:
        assert unit.get_tool(5)["length"] == 90.0
        assert unit.get_offset("G54")["trans"]["X"] == 12.5
        assert unit.get_settings() == {"plane": 18}
    with Database(path, machine="mill-b") as db, db.unit(readonly=True) as unit:
        assert unit.get_tool(5) is None and unit.get_offset("G54")["trans"]["X"] == 0.0

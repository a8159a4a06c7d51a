"""The unit-of-work API: offsets with audit, transactions, tools, probes, settings, log, state."""

import math
import sqlite3
import subprocess
import sys
import threading
from datetime import UTC, datetime, timedelta

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from sqlalchemy import event
from sqlalchemy.orm import Session

from db import Database

FRAME = {
    "trans": {"X": 0.1 + 0.2, "Y": -123.456789012, "Z": 1e-9},
    "fine": {"X": 0.001, "Y": 0.0, "Z": -0.0005},
    "rot": {"X": 0.4, "Y": -0.3, "Z": 12.5},
}
IDENTITY = {"trans": {"X": 0.0, "Y": 0.0, "Z": 0.0}, "fine": {"X": 0.0, "Y": 0.0, "Z": 0.0},
            "rot": {"X": 0.0, "Y": 0.0, "Z": 0.0}}


def test_offset_round_trips_exactly(db):
    with db.unit() as unit:
        unit.put_offset("G54", FRAME, source="test")
    with db.unit(readonly=True) as unit:
        stored = unit.get_offset("G54")
    assert stored == FRAME
    assert stored["trans"]["X"] == 0.30000000000000004 and stored["trans"]["Z"] == 1e-9


finite = st.floats(allow_nan=False, allow_infinity=False, width=64)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(x=finite, y=finite, z=finite, c=finite)
def test_any_finite_float_round_trips_bit_for_bit(db, x, y, z, c):
    frame = {"trans": {"X": x, "Y": y, "Z": z, "C": c}, "fine": {"X": z}, "rot": {"Z": y}}
    with db.unit() as unit:
        unit.put_offset("G56", frame, source="property")
    with db.unit(readonly=True) as unit:
        stored = unit.get_offset("G56")
    got = [stored["trans"][a] for a in "XYZC"] + [stored["fine"]["X"], stored["rot"]["Z"]]
    assert got == [x, y, z, c, z, y]  # float ==: exact to the last bit (only the sign of 0.0 may go)


def test_put_offset_returns_and_audits_before_and_after(db):
    with db.unit() as unit:
        before, after = unit.put_offset("G54", FRAME, source="edge.set", detail={"points": [1, 2]})
        assert (before, after) == (IDENTITY, FRAME)
        moved = {**FRAME, "trans": {**FRAME["trans"], "X": 5.0}}
        assert unit.put_offset("G54", moved, source="api") == (FRAME, moved)
        unit.put_offset("G55", FRAME, source="api")
    with db.unit(readonly=True) as unit:
        entries = unit.audit()
        assert [(e["offset"], e["source"]) for e in entries] == [("G55", "api"), ("G54", "api"), ("G54", "edge.set")]
        first = entries[-1]
        assert (first["before"], first["after"], first["detail"]) == (IDENTITY, FRAME, {"points": [1, 2]})
        assert entries[1]["before"] == FRAME and entries[1]["after"]["trans"]["X"] == 5.0
        assert [e["offset"] for e in unit.audit(name="G54")] == ["G54", "G54"]
        assert len(unit.audit(limit=1)) == 1
        time = datetime.fromisoformat(first["time"])
        assert time.tzinfo is not None and abs(datetime.now(UTC) - time) < timedelta(minutes=1)


def test_put_offset_replaces_the_whole_frame(db):
    with db.unit() as unit:
        unit.put_offset("G54", FRAME, source="test")
        _, after = unit.put_offset("G54", {"trans": {"X": 1.0, "Y": 2.0, "Z": 3.0}}, source="test")
    assert after == {**IDENTITY, "trans": {"X": 1.0, "Y": 2.0, "Z": 3.0}}


def test_rotary_axes_hold_a_translation_only(tmp_path):
    with Database(tmp_path / "hmi.db", rotary_axes=("C",)) as database, database.unit() as unit:
        assert unit.get_offset("G54")["trans"] == {"X": 0.0, "Y": 0.0, "Z": 0.0, "C": 0.0}
        _, after = unit.put_offset("G54", {"trans": {"X": 1.0, "C": 12.5}}, source="test")
        assert after["trans"] == {"X": 1.0, "Y": 0.0, "Z": 0.0, "C": 12.5}
        assert set(after["rot"]) == set(after["fine"]) == {"X", "Y", "Z"}
        with pytest.raises(ValueError):
            unit.put_offset("G54", {"rot": {"C": 1.0}}, source="test")


def test_unknown_offset_is_a_key_error(db):
    with db.unit() as unit:
        with pytest.raises(KeyError):
            unit.put_offset("G99", FRAME, source="test")
        assert unit.get_offset("G99") is None
        assert unit.get_offset("G500") is None


@pytest.mark.parametrize("frame", [
    {"trans": {"X": math.nan}},
    {"trans": {"X": math.inf}},
    {"trans": {"X": "1.0"}},
    {"trans": {"X": True}},
    {"trans": {"Q": 1.0}},
    {"scale": {"X": 1.0}},
    {"trans": [1.0, 2.0, 3.0]},
    "G54",
])
def test_malformed_frames_are_refused_and_change_nothing(db, frame):
    with db.unit() as unit, pytest.raises(ValueError):
        unit.put_offset("G54", frame, source="test")
    with db.unit(readonly=True) as unit:
        assert unit.get_offset("G54") == IDENTITY and unit.audit() == []


def test_exception_inside_a_unit_rolls_back_frame_audit_and_log(db):
    with pytest.raises(RuntimeError), db.unit() as unit:
        unit.put_offset("G54", FRAME, source="edge.set")
        unit.add_log({"task": "edge.set", "result": {"position": 1.0}})
        unit.set_state("active_offset", "G54")
        raise RuntimeError("crash between correction and activation")
    with db.unit(readonly=True) as unit:
        assert unit.get_offset("G54") == IDENTITY
        assert unit.audit() == [] and unit.list_log() == []
        assert unit.get_state("active_offset") is None


def test_readonly_unit_refuses_writes(db):
    with pytest.raises(RuntimeError, match="read-only"), db.unit(readonly=True) as unit:
        unit.set_state("tool", 9)
    with db.unit(readonly=True) as unit:
        assert unit.get_state("tool") is None


@pytest.mark.sqlite_only
def test_committed_data_is_seen_by_another_connection_and_process(db, db_path):
    other = Database(db_path)
    try:
        with db.unit() as unit:
            unit.put_offset("G54", FRAME, source="test")
            with other.unit(readonly=True) as reader:  # WAL: a reader is not blocked and sees no dirty data
                assert reader.get_offset("G54") == IDENTITY
        with other.unit(readonly=True) as reader:
            assert reader.get_offset("G54") == FRAME
    finally:
        other.close()
    script = ("import sqlite3, sys; c = sqlite3.connect(sys.argv[1]); "
              "print(repr(c.execute(\"SELECT coarse FROM frames WHERE name='G54' AND axis='X'\").fetchone()[0]))")
    output = subprocess.run([sys.executable, "-c", script, str(db_path)], capture_output=True, text=True,
                            check=True, timeout=30).stdout
    assert float(output) == 0.1 + 0.2


def test_tools_round_trip_merge_and_delete(db):
    with db.unit() as unit:
        probe = unit.put_tool(9, {"name": "3D probe", "type": 710, "length": 100.2, "radius": 2.0})
        assert probe == {"t": 9, "name": "3D probe", "type": 710, "length": 100.2, "radius": 2.0,
                         "wear": {"length": 0.0, "radius": 0.0}}
        unit.put_tool(1, {"length": 85.0, "radius": 5.0})
        updated = unit.put_tool(9, {"wear": {"length": -0.012}})
        assert updated == {**probe, "wear": {"length": -0.012, "radius": 0.0}}
    with db.unit() as unit:
        assert [tool["t"] for tool in unit.list_tools()] == [1, 9]
        assert unit.get_tool(1) == {"t": 1, "name": None, "type": 120, "length": 85.0, "radius": 5.0,
                                    "wear": {"length": 0.0, "radius": 0.0}}
        assert unit.get_tool(9) == updated
        unit.delete_tool(1)
        assert unit.get_tool(1) is None
        with pytest.raises(KeyError):
            unit.delete_tool(1)
        for bad_t, bad_data in [(0, {}), (2, {"length": math.nan}), (2, {"colour": "red"}), (2, {"t": 3})]:
            with pytest.raises(ValueError):
                unit.put_tool(bad_t, bad_data)


@pytest.mark.sqlite_only
def test_probe_records_round_trip_with_calibration_time(db, db_path):
    record = {"effective_diameter": 3.9912, "trigger": {"X-": 1.993, "X+": -1.994}, "skew": (0.01, -0.006),
              "calibrated_at": "2025-01-01T10:00:00+00:00", "calibration_feed": 300.0}
    with db.unit() as unit:
        stored = unit.put_probe(1, record)
        assert stored == {**record, "skew": [0.01, -0.006], "number": 1}  # as JSON gives it back
        unit.put_probe(4, {"effective_diameter": 6.0})
        unit.put_tool_probe(2, {"trigger": {"Z-": -200.0}, "type": 101})
        with pytest.raises(ValueError):
            unit.put_probe(100, {})
        with pytest.raises(ValueError):
            unit.put_probe(2, {"skew": {1, 2}})
    with db.unit(readonly=True) as unit:
        assert unit.get_probe(1) == stored
        assert [probe["number"] for probe in unit.list_probes()] == [1, 2, 3, 4]
        assert unit.get_tool_probe(2) == {"trigger": {"Z-": -200.0}, "type": 101, "number": 2}
        assert unit.get_tool_probe(1) == {"number": 1} and unit.get_tool_probe(7) is None
    connection = sqlite3.connect(db_path)
    assert connection.execute("SELECT calibrated_at FROM probes WHERE number = 1").fetchone() == (
        "2025-01-01T10:00:00+00:00",)
    connection.close()


def test_settings_merge_and_state_round_trip(db):
    with db.unit() as unit:
        assert unit.put_settings({"plane": 17, "measuring_wo": "G54", "feeds": {"E_MESS_FM": 300.0}}) == {
            "feeds": {"E_MESS_FM": 300.0}, "measuring_wo": "G54", "plane": 17}
        assert unit.get_state("tool", default=0) == 0
        unit.set_state("active_offset", "G55")
        unit.set_state("tool", 9)
    with db.unit() as unit:
        merged = unit.put_settings({"plane": 18, "inch": None})
        assert merged == {"feeds": {"E_MESS_FM": 300.0}, "measuring_wo": "G54", "plane": 18, "inch": None}
        assert unit.get_settings() == merged
        assert (unit.get_state("active_offset"), unit.get_state("tool")) == ("G55", 9)
        unit.set_state("tool", None)
        assert unit.get_state("tool", default=0) is None
        with pytest.raises(ValueError):
            unit.put_settings({"plane": math.nan})


def test_measurement_log_round_trip(db):
    entry = {"task": "edge.set", "params": {"axis": "X", "direction": "+", "setpoint": 0.0},
             "raw": [{"X": 250.004, "Y": 100.0, "Z": -125.0}], "points": [{"n": 1, "stored": True}],
             "result": {"position": 249.998}, "correction": {"target": "G54"}, "probe": 1,
             "target": "G54", "status": "ok"}
    with db.unit() as unit:
        first = unit.add_log(entry)
        second = unit.add_log({"task": "hole.1", "status": "error"})
        with pytest.raises(ValueError):
            unit.add_log({"task": "edge.set", "colour": "red"})
        with pytest.raises(ValueError):
            unit.add_log({"params": {}})
    with db.unit(readonly=True) as unit:
        logged = unit.get_log(first)
        assert {key: logged[key] for key in entry} == entry and logged["id"] == first
        assert datetime.fromisoformat(logged["time"]).utcoffset() == timedelta(0)
        assert [e["id"] for e in unit.list_log()] == [second, first]
        assert unit.list_log(limit=1)[0]["result"] is None
        assert unit.get_log(second + 1) is None


def test_a_unit_cannot_be_used_after_its_transaction(db):
    with db.unit() as unit:
        pass
    with pytest.raises(RuntimeError, match="ended"):
        unit.put_offset("G54", FRAME, source="late")


def test_log_keeps_the_measuring_wo_and_warnings_as_their_own_fields(tmp_path):
    from db import Database

    with Database(tmp_path / "log.db") as db:
        with db.unit() as unit:
            log_id = unit.add_log({"task": "edge.set", "params": {"axis": "X"}, "target": "G54",
                                   "measuring_wo": "G500", "warnings": ["Probe not calibrated"]})
        with db.unit(readonly=True) as unit:
            entry = unit.get_log(log_id)
    assert entry["measuring_wo"] == "G500" and entry["warnings"] == ["Probe not calibrated"]
    assert entry["params"] == {"axis": "X"}          # nothing smuggled into the params any more


def test_a_value_read_while_a_write_commits_is_not_cached_as_the_stored_one(db):
    """The generation contract the caches rely on: a reader reads the count, then the value.
    While the count stays the same the value must be the stored one; a reader that came in
    between another writer's last statement and its commit read the old value, so the count
    must move on afterwards (it was raised before the commit: the MTConnect table and the
    frame caches kept the old G54 until the next write)."""
    seen: dict[str, object] = {}

    def read_meanwhile(_connection) -> None:
        if seen:
            return
        seen["generation"] = db.generation
        with db.unit(readonly=True) as unit:
            seen["x"] = unit.get_offset("G54")["trans"]["X"]

    event.listen(db.engine, "commit", read_meanwhile)     # fires just before the commit
    try:
        with db.unit() as unit:
            unit.put_offset("G54", {"trans": {"X": 12.5}}, source="test")
    finally:
        event.remove(db.engine, "commit", read_meanwhile)
    assert seen["x"] == 0.0                                # the old value, read mid-commit
    assert db.generation != seen["generation"], "the old value would be taken for the stored one"


def test_a_writer_never_sees_a_commit_not_yet_counted(db):
    """A commit and the count's rise are one turn: another writer of this process that comes in
    right after the commit waits until the count is raised, so it never caches the new value
    under the old count (the measuring service's frame cache relies on this)."""
    before = db.generation
    seen: dict[str, object] = {}

    def other_writer() -> None:
        with db.unit() as unit:
            seen["generation"] = db.generation
            seen["x"] = unit.get_offset("G54")["trans"]["X"]

    other = threading.Thread(target=other_writer)

    def after_commit(_session) -> None:           # committed, the count not raised yet
        if not other.is_alive() and not seen:
            other.start()
            other.join(timeout=0.3)                # time enough to come in, were the turn free

    event.listen(Session, "after_commit", after_commit)
    try:
        with db.unit() as unit:
            unit.put_offset("G54", {"trans": {"X": 12.5}}, source="test")
    finally:
        event.remove(Session, "after_commit", after_commit)
    other.join(timeout=15)
    assert seen == {"generation": before + 1, "x": 12.5}

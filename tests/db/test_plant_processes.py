"""Writes right across processes (design.md §10.5): HMI processes of one machine change the same
tool and the same zero offset at once, each as a read-modify-write (add to the wear, shift G54).
No update may be lost, and the audit must chain: each row's "before" is the previous row's
"after". Runs on SQLite and, with --db-engine=postgresql, on PostgreSQL."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from db import Database

PROCESSES, ROUNDS = 3, 15
ROOT = Path(__file__).resolve().parents[2]

WRITER = """
import sys
from db import Database, acting_as
from db.repository import Actor

target, name, rounds = sys.argv[1], sys.argv[2], int(sys.argv[3])
with Database(target, machine="mill-a") as db, acting_as(Actor(f"user:{name}", 3)):
    sys.stdout.write("ready\\n"); sys.stdout.flush()
    sys.stdin.readline()                      # all start together
    for _ in range(rounds):
        with db.unit() as unit:
            tool = unit.get_tool(1)
            unit.put_tool(1, {"wear": {"length": tool["wear"]["length"] + 0.001}}, source="test")
        with db.unit() as unit:
            g54 = unit.get_offset("G54")
            unit.put_offset("G54", {"trans": {"X": g54["trans"]["X"] + 1.0}}, source="test")
"""


def test_concurrent_read_modify_writes_of_several_processes_lose_nothing(db_path):
    with Database(db_path, machine="mill-a") as db, db.unit() as unit:
        unit.put_tool(1, {"length": 100.0, "radius": 5.0})
    writers = [subprocess.Popen([sys.executable, "-c", WRITER, str(db_path), f"p{i}", str(ROUNDS)], cwd=ROOT,
                                stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
               for i in range(PROCESSES)]
    try:
        for writer in writers:
            assert writer.stdout is not None and writer.stdout.readline() == "ready\n"
        for writer in writers:
            assert writer.stdin is not None
            writer.stdin.write("go\n")
            writer.stdin.flush()
        for writer in writers:
            assert writer.wait(timeout=300) == 0
    finally:
        for writer in writers:
            if writer.poll() is None:
                writer.kill()
    total = PROCESSES * ROUNDS
    with Database(db_path, machine="mill-a") as db, db.unit(readonly=True) as unit:
        assert abs(unit.get_tool(1)["wear"]["length"] - total * 0.001) < 1e-9
        assert unit.get_offset("G54")["trans"]["X"] == float(total)
        audit = list(reversed(unit.audit(limit=10 * total)))
    for kind, item, value in (("tool", "T1", lambda r: r["wear"]["length"]),
                              ("offset", "G54", lambda r: r["trans"]["X"])):
        rows = [row for row in audit if row["kind"] == kind and row["offset"] == item]
        assert len(rows) == total
        assert all(value(row["after"]) > value(row["before"]) for row in rows)
        assert all(later["before"] == earlier["after"] for earlier, later in zip(rows, rows[1:], strict=False))
        assert {row["who"] for row in rows} == {f"user:p{i}" for i in range(PROCESSES)}
        assert {row["machine"] for row in rows} == {"mill-a"}

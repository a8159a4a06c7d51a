"""Two HMI processes on one database (design.md §10.5), as a plant runs them: ``python -m app --db
... --machine-name ...``. Each measures into its G54 on its own machine (different workpiece poses);
then two processes of one machine change the same tool at once, each a different field, while the
other machine changes its own T1. Checked against the truth: each G54 is its machine's, no update is
lost, every audit row names machine and acting identity, and the plant view lists both machines.
Runs on SQLite and, with --db-engine=postgresql, on PostgreSQL."""

from __future__ import annotations

import json
import subprocess
import sys
import threading
from pathlib import Path

import httpx
import pytest
from live import free_port
from waiting import wait_until

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "flows"))
from truthkit import TOP_Z, Operator, scenario  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
WRITES = 12


class Hmi:
    """One ``python -m app`` process; ``http`` talks to it."""

    def __init__(self, target, machine: str, scenario_path: Path, log: Path):
        self.machine = machine
        self.port = free_port()
        self._log = log.open("w")
        self.process = subprocess.Popen(
            [sys.executable, "-m", "app", "--db", str(target), "--machine-name", machine, "--port", str(self.port),
             "--scenario", str(scenario_path), "--time-scale", "0"],
            cwd=ROOT, stdout=self._log, stderr=subprocess.STDOUT)
        self.http = httpx.Client(base_url=f"http://127.0.0.1:{self.port}", timeout=30)

    def ready(self) -> bool:
        assert self.process.poll() is None, f"the HMI {self.machine} ended: {self._log.name}"
        try:
            return self.http.get("/api/machine").status_code == 200
        except httpx.TransportError:
            return False

    def stop(self) -> None:
        self.http.close()
        self.process.terminate()
        try:
            self.process.wait(timeout=20)
        except subprocess.TimeoutExpired:
            self.process.kill()
        self._log.close()


@pytest.fixture
def hmis(database_target, tmp_path):
    """mill-a (two processes: a1, a2) and mill-b on one database, each with its own workpiece pose."""
    poses = {"mill-a": (250.0, 150.0, TOP_Z), "mill-b": (300.0, 180.0, TOP_Z + 12.5)}
    started = {}
    try:
        for key, machine in (("a1", "mill-a"), ("a2", "mill-a"), ("b", "mill-b")):
            path = tmp_path / f"{key}.json"
            path.write_text(json.dumps(scenario(trans=poses[machine])))
            started[key] = Hmi(database_target, machine, path, tmp_path / f"{key}.log")
        for hmi in started.values():
            wait_until(hmi.ready, f"the HMI {hmi.machine} answers", 120)
        yield started, poses
    finally:
        for hmi in started.values():
            hmi.stop()


def test_two_machines_on_one_database_keep_their_own_offsets_and_lose_no_update(hmis):
    started, poses = hmis
    # each machine measures the top face into G54 (edge.set Z-, setpoint Z = -2)
    for key in ("a1", "b"):
        hmi = started[key]
        op = Operator(hmi.http, scenario(trans=poses[hmi.machine]))
        op.measure("edge.set", {"axis": "Z", "direction": "-", "setpoint": {"Z": -2.0}},
                   [op.part.mcs(60.0, 20.0, 8.0)], "G54")
    for key, machine in (("a1", "mill-a"), ("a2", "mill-a"), ("b", "mill-b")):
        g54 = started[key].http.get("/api/offsets/G54").json()
        assert g54["trans"]["Z"] == pytest.approx(poses[machine][2] + 2.0, abs=1e-6), (key, g54)

    # a1 changes T1's length, a2 its radius, b its own T1's wear: all at once
    for key in ("a1", "b"):
        assert started[key].http.put("/api/tools/1", json={"length": 50.0, "radius": 1.0}).status_code == 200
    go = threading.Barrier(3)
    failures: list[str] = []

    def writer(hmi: Hmi, values) -> None:
        go.wait()
        for i in range(WRITES):
            response = hmi.http.put("/api/tools/1", json=values(i))
            if response.status_code != 200:
                failures.append(response.text)

    threads = [threading.Thread(target=writer, args=(started["a1"], lambda i: {"length": 100.0 + i})),
               threading.Thread(target=writer, args=(started["a2"], lambda i: {"radius": 2.0 + i})),
               threading.Thread(target=writer, args=(started["b"], lambda i: {"wear": {"length": -0.001 * (i + 1)}}))]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert failures == []
    last = WRITES - 1
    for key in ("a1", "a2"):
        tool = started[key].http.get("/api/tools/1").json()
        assert (tool["length"], tool["radius"]) == (100.0 + last, 2.0 + last), (key, tool)
        assert tool["wear"]["length"] == 0.0
    tool_b = started["b"].http.get("/api/tools/1").json()
    assert (tool_b["length"], tool_b["radius"]) == (50.0, 1.0)
    assert tool_b["wear"]["length"] == pytest.approx(-0.001 * WRITES)

    # the audit: every change once, in a chain, naming its machine and who acted
    for key, machine, changes in (("a1", "mill-a", 2 * WRITES + 1), ("b", "mill-b", WRITES + 1)):
        rows = started[key].http.get("/api/audit", params={"kind": "tool", "limit": 1000}).json()
        rows = [r for r in rows if r["offset"] == "T1"][::-1]
        assert len(rows) == changes
        assert all(r["machine"] == machine and r["who"] for r in rows)
        assert all(later["before"] == earlier["after"] for earlier, later in zip(rows, rows[1:], strict=False))
        g54_rows = started[key].http.get("/api/audit", params={"name": "G54"}).json()
        assert g54_rows and all(r["machine"] == machine for r in g54_rows)

    # the plant view of either HMI lists both machines with their last measurement
    plant = started["b"].http.get("/api/plant").json()
    machines = {m["name"]: m for m in plant["machines"]}
    assert set(machines) == {"mill-a", "mill-b"}
    assert all(m["online"] and m["last_measurement"]["task"] == "edge.set" for m in machines.values())

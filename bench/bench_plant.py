"""Scale figures of the plant mode (issue 32 item 6, docs/plant.md).

1. Writers: N HMI processes on one database, each committing a measurement every second (the
   unit a measurement commits: its zero offset and its log entry) for S seconds: p50/p95/max write
   latency, errors, and whether every row arrived (no lost row). PostgreSQL with 10 processes
   (a private cluster, tests/pgcluster.py), SQLite with 2 for comparison.
2. The plant page: 20 machines × 10 000 results (measurement log rows and part characteristics)
   on PostgreSQL; time of ``GET /api/plant`` and ``GET /plant`` (median of 20).

Run: python bench/bench_plant.py [--seconds 60] [--writers 10]
"""

from __future__ import annotations

import argparse
import multiprocessing
import statistics
import sys
import tempfile
import time
from datetime import UTC, datetime
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

from sqlalchemy import insert, select  # noqa: E402

from db import Database, acting_as  # noqa: E402
from db.models import Characteristic, MeasurementLog, Part  # noqa: E402
from db.repository import Actor  # noqa: E402


def _writer(target: str, machine: str, seconds: float, ready, out) -> None:
    """One HMI: a measurement's commit (G54 and a log entry) once a second."""
    latencies, errors = [], []
    with Database(target, machine=machine) as db, acting_as(Actor(f"user:{machine}", 1)):
        ready.wait()                          # every writer connected: all start together
        start_at = time.time()
        k = 0
        while time.time() < start_at + seconds:
            t0 = time.perf_counter()
            try:
                with db.unit() as unit:
                    unit.put_offset("G54", {"trans": {"X": k * 1e-3}}, source="bench")
                    unit.add_log({"task": "hole.1", "target": "G54", "status": "ok", "result": {"k": k}})
                latencies.append(time.perf_counter() - t0)
            except Exception as exc:       # a bench counts what fails instead of stopping
                errors.append(repr(exc))
            k += 1
            next_tick = start_at + k
            time.sleep(max(0.0, next_tick - time.time()))
    out.put((machine, k, latencies, errors))


def writers(target: str, n: int, seconds: float) -> None:
    with Database(target, machine="bench-0"):
        pass                                  # migrate once before the writers start
    ctx = multiprocessing.get_context("spawn")
    out, ready = ctx.Queue(), ctx.Barrier(n)
    procs = [ctx.Process(target=_writer, args=(target, f"mill-{i}", seconds, ready, out)) for i in range(n)]
    for p in procs:
        p.start()
    results = [out.get(timeout=seconds + 120) for _ in procs]
    for p in procs:
        p.join()
    latencies = sorted(x for _, _, lat, _ in results for x in lat)
    errors = [e for _, _, _, errs in results for e in errs]
    with Database(target, machine="bench-0") as db, db.engine.connect() as connection:
        lost = 0
        for machine, _count, lat, _ in results:
            rows = connection.execute(select(MeasurementLog.id).where(MeasurementLog.machine == machine)).all()
            lost += len(lat) - len(rows)
    ms = [x * 1000.0 for x in latencies] or [float("nan")]
    p95 = ms[int(0.95 * (len(ms) - 1))]
    print(f"  {n} writers × {seconds:.0f} s: {len(latencies)} commits, p50 {statistics.median(ms):.1f} ms, "
          f"p95 {p95:.1f} ms, max {max(ms):.1f} ms, errors {len(errors)}, lost rows {lost}")
    for e in errors[:3]:
        print("   ", e)


def fill_plant(target: str, machines: int, results: int) -> None:
    """``machines`` machines with ``results`` log rows and ``results`` characteristics each (bulk)."""
    now = datetime.now(UTC).isoformat()
    for m in range(machines):
        name = f"cell-{m:02d}"
        with Database(target, machine=name) as db:
            db.report_status({"alarms": [], "active_offset": "G54", "mode": "JOG"})
            with db.engine.begin() as connection:
                connection.execute(insert(MeasurementLog), [
                    {"machine": name, "time": now, "task": "hole.1", "target": "G54", "status": "ok",
                     "result": {"diameter": 32.0}} for _ in range(results)])
                parts = results // 10
                connection.execute(insert(Part), [{"machine": name, "part_number": "PN-1", "serial": f"S{i}",
                                                   "started": now} for i in range(parts)])
                ids = connection.execute(select(Part.id).where(Part.machine == name)).scalars().all()
                connection.execute(insert(Characteristic), [
                    {"part_id": pid, "time": now, "name": f"D{j}", "nominal": 32.0, "upper": 32.02,
                     "lower": 31.98, "actual": 32.0, "deviation": 0.0, "verdict": "ok", "unit": "mm"}
                    for pid in ids for j in range(10)])
    with Database(target, machine="cell-00") as db, db.engine.connect() as connection:
        connection.execution_options(isolation_level="AUTOCOMMIT").exec_driver_sql("ANALYZE")  # as autovacuum would


def plant_page(target: str) -> None:
    from fastapi.testclient import TestClient

    from app.config import Settings
    from app.main import create_app

    app = create_app(Settings(db_url=target, machine_name="cell-00"))
    with TestClient(app) as client:
        for path in ("/api/plant", "/plant", "/api/plant/cell-07"):
            client.get(path)                       # warm
            times = []
            for _ in range(20):
                t0 = time.perf_counter()
                assert client.get(path).status_code == 200
                times.append((time.perf_counter() - t0) * 1000.0)
            print(f"  GET {path}: median {statistics.median(times):.1f} ms, max {max(times):.1f} ms")


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--writers", type=int, default=10)
    args = parser.parse_args()
    from pgcluster import PgCluster

    with PgCluster() as cluster:
        print("PostgreSQL (private cluster):")
        writers(cluster.new_database(), args.writers, args.seconds)
        with tempfile.TemporaryDirectory() as tmp:
            print("SQLite (one file):")
            writers(str(Path(tmp) / "hmi.db"), 2, args.seconds)
        print("plant page, 20 machines × 10 000 results (PostgreSQL):")
        target = cluster.new_database()
        fill_plant(target, 20, 10_000)
        plant_page(target)


if __name__ == "__main__":
    main()

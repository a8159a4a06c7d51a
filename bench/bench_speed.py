"""Server time of NC Start (JSON and screen) and of the measurement log with many entries.

Targets of issue [integrity] (design.md §9.1): every softkey interaction p95 <= 10 ms server time
at time_scale 0; the /log screen <= 50 ms with 10 000 entries in the database. In-process
(FastAPI TestClient; server time = request in -> response out inside the app), tmp db.

Uses only the contracts of design.md §4 and the db's ``add_log`` so that it runs unchanged on an
older checkout: ``python bench/bench_speed.py [runs] [log entries]`` from that checkout's root
compares releases on the same machine in the same hour.
"""

from __future__ import annotations

import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path.cwd()
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests" / "flows"))

from fastapi.testclient import TestClient  # noqa: E402
from truthkit import HOLE_D, HOLES, Operator, scenario  # noqa: E402

from app.config import Settings  # noqa: E402
from app.main import create_app  # noqa: E402

SOFTKEY_BAR_MS = 10.0
LOG_BAR_MS = 50.0


def _entry(i: int) -> dict:
    """A log entry as big as a real 4-point measurement's (raw latches, points, result)."""
    latch = {"triggered": True, "rec": [1.0 + i, 2.0, 3.0], "mcs": [101.0, 202.0, 303.0]}
    return {"task": "corner.right", "params": {"kind": "outside", "position": 1, "setpoint": {"X": 0, "Y": 0}},
            "target": "G54", "raw": {f"P{n}": [latch] * 3 for n in (1, 2, 3)},
            "points": {f"P{n}": {"surface": {"X": 1.0, "Y": 2.0, "Z": 3.0}} for n in (1, 2, 3)},
            "result": {"corner": {"X": 0.1 * i, "Y": 0.2}, "angle": 4.0},
            "correction": {"target": "G54", "before": {"trans": {"X": 0.0}}, "after": {"trans": {"X": 1.0}}},
            "status": "ok"}


def main(runs: int = 100, entries: int = 10_000) -> int:
    times: dict[str, list[float]] = {}
    server: list[float] = []

    def timed(name: str, call, *args, **kwargs):
        response = call(*args, **kwargs)
        times.setdefault(name, []).append(server[-1])
        assert response.status_code == 200, (name, response.status_code, response.text[:300])
        return response

    with tempfile.TemporaryDirectory() as tmp:
        scen = scenario()
        path = Path(tmp) / "scenario.json"
        path.write_text(json.dumps(scen))
        app = create_app(Settings(db_path=Path(tmp) / "hmi.db", scenario_path=path, time_scale=0.0))

        @app.middleware("http")
        async def server_time(request, call_next):
            t0 = time.perf_counter()
            response = await call_next(request)
            server.append(1e3 * (time.perf_counter() - t0))
            return response

        with TestClient(app) as client:
            op = Operator(client, scen)
            op.load()
            op.activate("G54")
            hole = op.part.mcs(HOLES[0][0] + 0.3, HOLES[0][1] - 0.2, -8.0)
            screen = "/measure/task/hole.1/start"
            form = {"target": "G54", "diameter": str(HOLE_D), "probe_angle": "0", "setpoint.X": "0",
                    "setpoint.Y": "0"}
            for _ in range(runs):
                op.ball_to(hole)
                s = timed("JSON create session", client.post, "/api/measure",
                          json={"task": "hole.1", "params": {"diameter": HOLE_D}, "target": "G54"}).json()
                timed("JSON NC Start (hole.1)", client.post, f"/api/measure/{s['id']}/start")
                timed("screen NC Start (hole.1)", client.post, screen, data=form, headers={"HX-Request": "true"})
                timed("JSON GET /api/machine", client.get, "/api/machine")
            db = app.state.services.db
            with db.unit() as unit:
                for i in range(entries):
                    unit.add_log(_entry(i))
            for _ in range(max(10, runs // 5)):
                timed(f"screen GET /log ({entries} entries)", client.get, "/log")
                timed("JSON GET /api/log (100 newest)", client.get, "/api/log")
    print(f"{'interaction':42s} {'n':>5s} {'p50 ms':>8s} {'p95 ms':>8s} {'max ms':>8s}")
    failed = False
    for name, values in times.items():
        v = np.array(values)
        p95 = float(np.percentile(v, 95))
        bar = LOG_BAR_MS if "/log" in name else SOFTKEY_BAR_MS
        failed |= p95 > bar
        print(f"{name:42s} {len(v):5d} {np.percentile(v, 50):8.2f} {p95:8.2f} {v.max():8.2f}"
              f"   bar {bar:g} ms{'' if p95 <= bar else '  ABOVE'}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(*(int(a) for a in sys.argv[1:3])))

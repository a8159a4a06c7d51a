"""Server time per softkey interaction of the measuring workflow (design.md §8: p95 < 50 ms).

In-process (FastAPI TestClient; server time = an app middleware's request-in to response-out,
without the test client's transport), time_scale 0, tmp db: create session, GET session, NC Start
(single-point hole.1: probing + evaluate + correction + db commit + activation), NC Start of a
multi-point point, invalidate, Calculate (hole.2), the screens' HTML GETs.
Run: python bench/bench_measure.py [runs]
"""

from __future__ import annotations

import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests" / "flows"))

from fastapi.testclient import TestClient  # noqa: E402
from truthkit import HOLE_D, HOLES, Operator, scenario  # noqa: E402

from app.config import Settings  # noqa: E402
from app.main import create_app  # noqa: E402

HTML = ("/measure/workpiece", "/measure/workpiece/pocket", "/measure/workpiece/pocket/hole1")
BAR_MS = 50.0


def main(runs: int = 300) -> int:
    times: dict[str, list[float]] = {}

    server: list[float] = []

    def timed(name: str, call, *args, **kwargs):
        response = call(*args, **kwargs)
        times.setdefault(name, []).append(server[-1])      # server time of this request
        assert response.status_code == 200, (name, response.text)
        return response.json() if "json" in response.headers.get("content-type", "") else None

    with tempfile.TemporaryDirectory() as tmp:
        scen = scenario()
        path = Path(tmp) / "scenario.json"
        path.write_text(json.dumps(scen))
        app = create_app(Settings(db_path=Path(tmp) / "hmi.db", scenario_path=path, time_scale=0.0))

        @app.middleware("http")
        async def server_time(request, call_next):      # request in -> response out, in the app
            t0 = time.perf_counter()
            response = await call_next(request)
            server.append(1e3 * (time.perf_counter() - t0))
            return response

        with TestClient(app) as client:
            op = Operator(client, scen)
            op.load()
            op.activate("G54")
            h1 = op.part.mcs(HOLES[0][0] + 0.3, HOLES[0][1] - 0.2, -8.0)
            h2 = op.part.mcs(HOLES[1][0] - 0.2, HOLES[1][1] + 0.4, -8.0)
            html = [u for u in HTML if client.get(u).status_code == 200]
            for _ in range(runs):
                op.ball_to(h1)
                s = timed("create session", client.post, "/api/measure",
                          json={"task": "hole.1", "params": {"diameter": HOLE_D}, "target": "G54"})
                timed("GET session", client.get, f"/api/measure/{s['id']}")
                timed("NC Start (hole.1, corrects)", client.post, f"/api/measure/{s['id']}/start")
                s = timed("create session", client.post, "/api/measure",
                          json={"task": "hole.2", "params": {"diameter": HOLE_D}, "target": "G55"})
                timed("NC Start (hole.2 P1)", client.post, f"/api/measure/{s['id']}/start")
                op.ball_to(h2)
                timed("NC Start (hole.2 P2)", client.post, f"/api/measure/{s['id']}/start")
                timed("invalidate P2", client.post, f"/api/measure/{s['id']}/points/2/invalidate")
                timed("NC Start (hole.2 P2)", client.post, f"/api/measure/{s['id']}/start")
                timed("Calculate (hole.2)", client.post, f"/api/measure/{s['id']}/calculate")
                timed("GET /api/machine", client.get, "/api/machine")
                for url in html:
                    timed(f"GET {url}", client.get, url)
    print(f"{'interaction':38s} {'n':>5s} {'p50 ms':>8s} {'p95 ms':>8s} {'max ms':>8s}")
    worst = 0.0
    for name, values in times.items():
        v = np.array(values)
        p95 = float(np.percentile(v, 95))
        worst = max(worst, p95)
        print(f"{name:38s} {len(v):5d} {np.percentile(v, 50):8.2f} {p95:8.2f} {v.max():8.2f}")
    print(f"worst p95 {worst:.2f} ms: {'OK' if worst < BAR_MS else 'ABOVE'} the {BAR_MS:g} ms bar")
    return 0 if worst < BAR_MS else 1


if __name__ == "__main__":
    sys.exit(main(int(sys.argv[1]) if len(sys.argv) > 1 else 300))

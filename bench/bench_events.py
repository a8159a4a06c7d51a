"""The live feed's rate (GET /api/events, design.md §9.9; issue 17 asks >= 10 states a second while
moving): a real uvicorn server, the test scenario at real speed, a held continuous jog; prints the
machine events a second while moving and at rest, and the gaps between them (p50/p95/max).
Run: python bench/bench_events.py [seconds]
"""

from __future__ import annotations

import json
import sys
import tempfile
import threading
import time
from pathlib import Path

import httpx
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

from hmi_testdata import test_scenario  # noqa: E402
from live import serve  # noqa: E402


def machine_events(http: httpx.Client, seconds: float) -> list[tuple[float, dict]]:
    events, name = [], None
    end = time.monotonic() + seconds
    with http.stream("GET", "/api/events") as response:
        for line in response.iter_lines():
            if line.startswith("event:"):
                name = line[6:].strip()
            elif line.startswith("data:") and name == "machine":
                events.append((time.monotonic(), json.loads(line[5:])))
            if time.monotonic() > end:
                break
    return events


def report(label: str, events: list[tuple[float, dict]]) -> None:
    if len(events) < 2:
        print(f"{label}: {len(events)} machine events (the server did not answer in time)")
        return
    times = np.array([t for t, _ in events])
    gaps = np.diff(times) * 1000.0
    span = times[-1] - times[0]
    print(f"{label}: {len(events)} machine events in {span:.2f} s = {(len(events) - 1) / span:.1f}/s; gap ms "
          f"p50 {np.percentile(gaps, 50):.0f}, p95 {np.percentile(gaps, 95):.0f}, max {gaps.max():.0f}")


def main(seconds: float = 2.0) -> None:
    scenario = test_scenario()
    scenario["machine"]["time_scale"] = 1.0
    with tempfile.TemporaryDirectory() as tmp, serve(Path(tmp), scenario) as url, \
            httpx.Client(base_url=url, timeout=5) as http:
        report("at rest", machine_events(http, seconds))
        holding = threading.Event()
        holding.set()

        def hold():
            with httpx.Client(base_url=url, timeout=5) as renew:
                while holding.is_set():
                    renew.post("/api/machine/jog/continuous", json={"axis": "Y", "direction": 1})
                    time.sleep(0.15)

        thread = threading.Thread(target=hold, daemon=True)
        thread.start()
        time.sleep(0.3)
        moving = [e for e in machine_events(http, seconds) if e[1]["busy"]]
        holding.clear()
        thread.join(timeout=2)
        report("moving ", moving)


if __name__ == "__main__":
    main(float(sys.argv[1]) if len(sys.argv) > 1 else 2.0)

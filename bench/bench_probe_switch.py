"""How soon the screens learn of a probe switch (issue 26 item 2: "switched" within 50 ms of the
event): a real uvicorn server, a live feed open; the operator's hand deflects and releases the
probe (``POST /api/sim/probe``) N times; prints the time from sending the request to the live
feed's machine event that carries the new state (p50/p95/max, ms). That event is what static/live.js
paints the lamp and the probe test's "switched" from.
Run: python bench/bench_probe_switch.py [N]
"""

from __future__ import annotations

import json
import queue
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


def main(n: int = 40) -> None:
    with tempfile.TemporaryDirectory() as tmp, serve(Path(tmp), test_scenario()) as url, \
            httpx.Client(base_url=url, timeout=5) as http:
        seen: queue.Queue[tuple[float, bool]] = queue.Queue()
        done = threading.Event()

        def listen() -> None:
            name = None
            with httpx.Client(base_url=url, timeout=None) as feed, feed.stream("GET", "/api/events") as response:
                for line in response.iter_lines():
                    if done.is_set():
                        return
                    if line.startswith("event:"):
                        name = line[6:].strip()
                    elif line.startswith("data:") and name == "machine":
                        seen.put((time.perf_counter(), bool(json.loads(line[5:])["probe"]["deflected"])))

        threading.Thread(target=listen, daemon=True).start()
        seen.get(timeout=5)                                  # the feed is open
        delays = []
        for k in range(n):
            deflect = k % 2 == 0
            sent = time.perf_counter()
            http.post("/api/sim/probe", json={"deflect": deflect})
            while True:
                at, deflected = seen.get(timeout=5)
                if deflected == deflect and at >= sent:
                    delays.append((at - sent) * 1000.0)
                    break
            time.sleep(0.1)
        done.set()
        d = np.array(delays)
        print(f"probe switch -> live feed event, {n} switches: p50 {np.percentile(d, 50):.1f} ms, "
              f"p95 {np.percentile(d, 95):.1f} ms, max {d.max():.1f} ms (issue 26: within 50 ms)")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 40)

"""Hold-to-run stop latencies (issue 24 §6): a real uvicorn server at real speed, Chromium started
as its own process holding the Cont jog key of Y (1000 mm/min); the browser is killed (SIGKILL),
or the key let go, once the axis moves. Prints the run-on after that moment (mm, and as time at
the jog feed) per round, idle and beside a core kept busy. Goals: ≤ 0.5 s after the browser dies,
≤ 50 ms server side after a release.
Run: python bench/bench_hold_to_run.py [rounds]
"""

from __future__ import annotations

import statistics
import sys
import tempfile
from contextlib import nullcontext
from pathlib import Path

import httpx

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

from hmi_testdata import test_scenario  # noqa: E402
from hold_kit import JOG_FEED, busy_core, hold_then, kill, killable_chromium, real_time  # noqa: E402
from live import serve  # noqa: E402
from playwright.sync_api import sync_playwright  # noqa: E402


def rounds(n: int, busy: bool, what: str) -> list[float]:
    run_on: list[float] = []
    with tempfile.TemporaryDirectory() as tmp, serve(Path(tmp) / "srv", test_scenario()) as url, \
            httpx.Client(base_url=url, timeout=10) as api, (busy_core() if busy else nullcontext()):
        for k in range(n):
            real_time(api, test_scenario())
            with killable_chromium(Path(tmp) / f"profile{k}") as (chromium, port), sync_playwright() as pw:
                act = (lambda page: kill(chromium)) if what == "kill" else (lambda page: page.mouse.up())
                at_act, at_rest, _ = hold_then(pw.chromium, port, url, api, act)
            run_on.append(at_rest - at_act)
    return run_on


def main() -> None:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    mm_per_s = JOG_FEED / 60.0
    for what in ("kill", "release"):
        for busy in (False, True):
            mm = rounds(n, busy, what)
            print(f"{what:8s} {'busy core' if busy else 'idle':9s} run-on mm: median {statistics.median(mm):.2f} "
                  f"max {max(mm):.2f}  = s: median {statistics.median(mm) / mm_per_s:.3f} "
                  f"max {max(mm) / mm_per_s:.3f}  ({', '.join(f'{v:.2f}' for v in mm)})")


if __name__ == "__main__":
    main()

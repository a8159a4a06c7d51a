"""Today's HMI side by side with an earlier release (default: the wave-2 release f2bcad4), in one run,
each as its own server process (issue 30 item 5). Prints server CPU (from /proc) and the ratio
today / release for: the live feed's fan-out (GET /api/events, design.md §9.9) to N subscribers at
rest and while the machine moves, the events each subscriber gets a second, a poll
(GET /api/machine, /ui/position) per request, NC Start of hole.1 at time scale 0 (JSON and the
screen's form) per start, and the start-up (process CPU until /api/health answers).

The release is checked out into a temporary git worktree (``git worktree add --detach``) and served
by the same interpreter with its tree first on the path; the worktree is removed afterwards.
Both are driven only through design.md's contracts (tests/flows/truthkit.py's scenario).

Run: python bench/bench_release.py [--base f2bcad4] [--subscribers 50,100,200] [--window 3]
     [--polls 400] [--starts 20] [--only sse,poll,nc,startup]
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import httpx

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "flows"))
sys.path.insert(0, str(ROOT / "tests"))

from live import free_port  # noqa: E402
from truthkit import HOLE_D, HOLES, Operator, scenario  # noqa: E402

TICK_S = 1.0 / os.sysconf("SC_CLK_TCK")


# --- process CPU ------------------------------------------------------------------------------
def cpu_s(pid: int) -> float:
    """utime + stime of the process (all its threads, live and ended) from /proc/<pid>/stat."""
    fields = Path(f"/proc/{pid}/stat").read_text().rpartition(")")[2].split()
    return (int(fields[11]) + int(fields[12])) * TICK_S


def cpu_fine_s(pid: int) -> float:
    """The same with nanosecond resolution: the sum of the live threads' schedstat run times (for
    one request at a time, where /proc/<pid>/stat's 10 ms ticks are too coarse)."""
    total = 0
    for task in Path(f"/proc/{pid}/task").iterdir():
        try:
            total += int((task / "schedstat").read_text().split()[0])
        except (FileNotFoundError, ProcessLookupError):
            pass
    return total * 1e-9


# --- servers ----------------------------------------------------------------------------------
class Server:
    def __init__(self, name: str, tree: Path, tmp: Path, scen: dict, time_scale: float):
        self.name = name
        tmp.mkdir(parents=True, exist_ok=True)
        (tmp / "scenario.json").write_text(json.dumps(scen))
        self.port = free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        env = {**os.environ, "PYTHONPATH": str(tree)}
        env.pop("HMI_DB_URL", None)
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "app", "--port", str(self.port), "--db", str(tmp / "hmi.db"),
             "--scenario", str(tmp / "scenario.json"), "--time-scale", str(time_scale)],
            cwd=tree, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        self.startup_cpu = self._wait_up()

    def _wait_up(self, timeout_s: float = 300.0) -> float:
        end = time.monotonic() + timeout_s
        while time.monotonic() < end:
            if self.proc.poll() is not None:
                raise RuntimeError(f"{self.name} did not start: {self.proc.stderr.read().decode()[-2000:]}")
            try:
                if httpx.get(f"{self.url}/api/health", timeout=1).status_code == 200:
                    return cpu_s(self.proc.pid)
            except httpx.TransportError:
                pass
            time.sleep(0.02)
        raise RuntimeError(f"{self.name} did not answer within {timeout_s} s")

    @property
    def cpu(self) -> float:
        return cpu_s(self.proc.pid)

    @property
    def cpu_fine(self) -> float:
        return cpu_fine_s(self.proc.pid)

    def stop(self) -> None:
        self.proc.terminate()
        try:
            self.proc.wait(10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()


@contextmanager
def served(name: str, tree: Path, scen: dict, time_scale: float) -> Iterator[Server]:
    with tempfile.TemporaryDirectory(prefix="bench-release-") as tmp:
        server = Server(name, tree, Path(tmp), scen, time_scale)
        try:
            yield server
        finally:
            server.stop()


@contextmanager
def release_tree(commit: str) -> Iterator[Path]:
    path = Path(tempfile.mkdtemp(prefix=f"bench-{commit[:8]}-"))
    path.rmdir()
    subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", "-q", str(path), commit], check=True)
    try:
        yield path
    finally:
        subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(path)], check=False)


# --- the live feed ----------------------------------------------------------------------------
class Subscribers:
    """N raw HTTP/1.1 connections reading GET /api/events, counting ``machine`` events (no parsing
    beyond that, so that the bench's own CPU stays small)."""

    MARK = b"event: machine"

    def __init__(self, port: int, n: int):
        self.port, self.n = port, n
        self.counts = [0] * n
        self.loop = asyncio.new_event_loop()
        self.thread = threading.Thread(target=self.loop.run_forever, daemon=True)
        self.tasks: list[asyncio.Task] = []

    async def _read(self, i: int) -> None:
        reader, writer = await asyncio.open_connection("127.0.0.1", self.port, limit=1 << 20)
        writer.write(f"GET /api/events HTTP/1.1\r\nHost: 127.0.0.1:{self.port}\r\n\r\n".encode())
        await writer.drain()
        tail = b""
        try:
            while True:
                chunk = await reader.read(65536)
                if not chunk:
                    return
                data = tail + chunk
                self.counts[i] += data.count(self.MARK) - tail.count(self.MARK)
                tail = data[-len(self.MARK):]
        finally:
            writer.close()

    def __enter__(self) -> Subscribers:
        self.thread.start()
        asyncio.run_coroutine_threadsafe(self._start(), self.loop).result()
        end = time.monotonic() + 30
        while min(self.counts, default=1) == 0 and time.monotonic() < end:
            time.sleep(0.05)
        return self

    async def _start(self) -> None:
        self.tasks = [asyncio.create_task(self._read(i)) for i in range(self.n)]

    async def _close(self) -> None:
        for task in self.tasks:
            task.cancel()
        await asyncio.gather(*self.tasks, return_exceptions=True)

    def snapshot(self) -> list[int]:
        return list(self.counts)

    def __exit__(self, *exc) -> None:
        asyncio.run_coroutine_threadsafe(self._close(), self.loop).result(timeout=30)
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(timeout=5)
        self.loop.close()


def sse_window(server: Server, n: int, window_s: float, moving: bool) -> dict:
    """Server CPU (share of one core) and machine events per subscriber a second over ``window_s``."""
    mover = None
    if moving:
        # a long move in the air above the part (truthkit's start is X100 Y100 Z0); blocks until it ends
        x = 100.0 if httpx.get(f"{server.url}/api/machine").json()["mcs"]["X"] > 130 else 160.0
        body = {"X": x, "Y": 100.0, "Z": 0.0, "coords": "MCS", "feed": 60.0 * 60.0 / (window_s + 3.0)}
        mover = threading.Thread(target=lambda: httpx.post(f"{server.url}/api/machine/goto", json=body,
                                                           timeout=window_s + 30), daemon=True)
    with Subscribers(server.port, n) as subs:
        if mover is not None:
            mover.start()
        time.sleep(1.0)                         # connected, first events sent, the move under way
        c0, e0, t0 = server.cpu, subs.snapshot(), time.monotonic()
        time.sleep(window_s)
        c1, e1, t1 = server.cpu, subs.snapshot(), time.monotonic()
    if mover is not None:
        mover.join(timeout=window_s + 30)
    rates = [(b - a) / (t1 - t0) for a, b in zip(e0, e1, strict=True)]
    return {"core": (c1 - c0) / (t1 - t0), "min_rate": min(rates, default=0.0),
            "median_rate": statistics.median(rates) if rates else 0.0}


# --- requests ---------------------------------------------------------------------------------
def per_request_cpu(server: Server, call: Callable[[httpx.Client], httpx.Response], n: int) -> float:
    """CPU ms per request over ``n`` requests on one keep-alive connection (after 20 warm-up ones)."""
    with httpx.Client(base_url=server.url, timeout=30) as http:
        for _ in range(20):
            call(http).raise_for_status()
        c0 = server.cpu
        for _ in range(n):
            call(http)
        return 1e3 * (server.cpu - c0) / n


def nc_start_cpu(servers: list[Server], scen: dict, runs: int) -> list[dict[str, float]]:
    """CPU ms of one NC Start of hole.1 (JSON, and the screen's form) on each server, median of
    ``runs`` each; the servers take turns start by start, so that a change of the machine's load
    during the run weighs on both alike."""
    form = {"target": "G54", "diameter": str(HOLE_D), "probe_angle": "0", "setpoint.X": "0", "setpoint.Y": "0"}
    clients = [httpx.Client(base_url=server.url, timeout=60) for server in servers]
    try:
        ops = []
        for http in clients:
            op = Operator(http, scen)
            op.activate("G54")
            ops.append(op)
        hole = ops[0].part.mcs(HOLES[0][0] + 0.3, HOLES[0][1] - 0.2, -8.0)
        out: list[dict[str, list[float]]] = [{"json": [], "screen": []} for _ in servers]
        for _ in range(runs + 2):
            for server, http, op, got in zip(servers, clients, ops, out, strict=True):
                op.ball_to(hole)
                sid = op.create("hole.1", {"diameter": HOLE_D}, "G54")["id"]
                c0 = server.cpu_fine
                op.start(sid)
                got["json"].append(1e3 * (server.cpu_fine - c0))
                op.ball_to(hole)
                c0 = server.cpu_fine
                r = http.post("/measure/task/hole.1/start", data=form, headers={"HX-Request": "true"})
                got["screen"].append(1e3 * (server.cpu_fine - c0))
                assert r.status_code == 200, r.text[:300]
    finally:
        for http in clients:
            http.close()
    return [{k: statistics.median(v[2:]) for k, v in got.items()} for got in out]


# --- report -----------------------------------------------------------------------------------
def row(label: str, base: float, today: float, unit: str, goal: float | None = None) -> None:
    ratio = today / base if base > 0 else float("nan")
    bar = "" if goal is None else f"  goal <= {goal:g}x {'ok' if ratio <= goal else 'MISSED'}"
    print(f"{label:46s} {base:10.3f} {today:10.3f} {unit:10s} {ratio:6.2f}x{bar}", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--base", default="f2bcad4")
    parser.add_argument("--subscribers", default="50,100,200")
    parser.add_argument("--window", type=float, default=3.0)
    parser.add_argument("--polls", type=int, default=400)
    parser.add_argument("--starts", type=int, default=20)
    parser.add_argument("--startups", type=int, default=3)
    parser.add_argument("--only", default="sse,poll,nc,startup")
    args = parser.parse_args()
    only = set(args.only.split(","))
    scen = scenario()
    with release_tree(args.base) as base_tree:
        trees = {args.base: base_tree, "today": ROOT}
        print(f"{'':46s} {args.base:>10s} {'today':>10s} {'':10s} {'ratio':>7s}")
        if "startup" in only:
            ups = {name: statistics.median(_startup(name, tree, scen) for _ in range(args.startups))
                   for name, tree in trees.items()}
            row("start-up (CPU until /api/health)", ups[args.base], ups["today"], "s", 1.0)
        if "sse" in only or "poll" in only:
            with served(args.base, base_tree, scen, 1.0) as base, served("today", ROOT, scen, 1.0) as today:
                if "poll" in only:
                    for path in ("/api/machine", "/ui/position"):
                        got = [per_request_cpu(s, lambda h, p=path: h.get(p), args.polls) for s in (base, today)]
                        row(f"poll GET {path} CPU per request", *got, "ms", 0.7)
                if "sse" in only:
                    for moving in (False, True):
                        for n in [int(v) for v in args.subscribers.split(",")]:
                            got = [sse_window(s, n, args.window, moving) for s in (base, today)]
                            state = "moving" if moving else "at rest"
                            row(f"SSE {n} subscribers {state}: CPU share of a core", got[0]["core"],
                                got[1]["core"], "core", 0.2 if not moving else None)
                            row(f"SSE {n} subscribers {state}: min events/s each", got[0]["min_rate"],
                                got[1]["min_rate"], "1/s")
        if "nc" in only:
            with served(args.base, base_tree, scen, 0.0) as base, served("today", ROOT, scen, 0.0) as today:
                got = nc_start_cpu([base, today], scen, args.starts)
                row("NC Start hole.1 JSON CPU per start", got[0]["json"], got[1]["json"], "ms", 0.7)
                row("NC Start hole.1 screen CPU per start", got[0]["screen"], got[1]["screen"], "ms")
                print(f"{'screen / JSON (today; goal <= 1.2)':46s} {got[1]['screen'] / got[1]['json']:10.2f}")


def _startup(name: str, tree: Path, scen: dict) -> float:
    with served(name, tree, scen, 0.0) as server:
        return server.startup_cpu


if __name__ == "__main__":
    main()

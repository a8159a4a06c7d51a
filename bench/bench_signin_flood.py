"""A flood of wrong sign-ins against a real HMI process (issue 25 item 1): 200 parallel
``POST /api/session`` with wrong passwords, once from one address and once from 200 addresses
(127.0.1.x: the whole 127/8 is loopback on Linux, so a per-address throttle does not help), while a
token client reads ``/api/machine`` every 20 ms. Prints the latency of those reads (p50, p99, max),
the server's resident memory (before, peak, after) and the answers' status codes.
Goals (issue 25): /api/machine p99 <= 100 ms, RSS growth <= 50 MB.

Run: python bench/bench_signin_flood.py [--tree DIR] [--flood N]
``--tree`` runs another checkout of the product (e.g. ``git archive <commit> | tar -x -C DIR``) to
print the figures side by side with an earlier release.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from pathlib import Path

import httpx

ROOT = Path(__file__).resolve().parents[1]
PASSWORD = "anna-right-pw"


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def rss_mb(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return float("nan")


def cli(tree: Path, db: Path, *args: str, stdin: str = "") -> str:
    done = subprocess.run([sys.executable, "-m", "app", "--db", str(db), *args], cwd=tree, input=stdin,
                          capture_output=True, text=True, check=True, env={**os.environ, "PYTHONPATH": str(tree)})
    return done.stdout


class Sampler(threading.Thread):
    """Reads /api/machine and the server's RSS every 20 ms until stopped."""

    def __init__(self, url: str, token: str, pid: int):
        super().__init__(daemon=True)
        self.url, self.headers, self.pid = url, {"Authorization": f"Bearer {token}"}, pid
        self.latencies: list[float] = []
        self.rss: list[float] = []
        self.stop = threading.Event()

    def run(self) -> None:
        with httpx.Client(base_url=self.url, headers=self.headers, timeout=60) as client:
            while not self.stop.is_set():
                started = time.perf_counter()
                assert client.get("/api/machine").status_code == 200
                self.latencies.append(time.perf_counter() - started)
                self.rss.append(rss_mb(self.pid))
                self.stop.wait(0.02)


async def flood(port: int, n: int, many_addresses: bool, health: bool = False) -> Counter:
    """Plain HTTP/1.1 over asyncio streams: the client's own cost stays small beside the server's.
    ``health``: GET /api/health instead (what any 200 requests at once cost the server)."""

    async def one(k: int) -> str:
        address = f"127.0.1.{k % 250 + 1}" if many_addresses else "127.0.0.1"
        reader, writer = await asyncio.open_connection("127.0.0.1", port, local_addr=(address, 0))
        body = json.dumps({"user": "anna", "password": f"wrong-{k}"}).encode()
        line = b"GET /api/health" if health else b"POST /api/session"
        writer.write(line + b" HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nContent-Type: application/json\r\n"
                     b"Content-Length: %d\r\nConnection: close\r\n\r\n%s" % (port, len(body), body))
        answer = await reader.read()
        writer.close()
        head, _, payload = answer.partition(b"\r\n\r\n")
        status = head.split()[1].decode()
        code = json.loads(payload).get("error", {}).get("code", "") if payload.startswith(b"{") else ""
        return f"{status} {code}".strip()

    return Counter(await asyncio.gather(*(one(k) for k in range(n))))


def percentile(values: list[float], p: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(round(p / 100 * (len(ordered) - 1))))]


def round_(tree: Path, n: int, many_addresses: bool, health: bool = False) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        db = Path(tmp) / "hmi.db"
        cli(tree, db, "user", "add", "anna", "--level", "3", stdin=PASSWORD + "\n")
        token = cli(tree, db, "token", "add", "bench", "--level", "1").strip().split()[-1]
        port = free_port()
        server = subprocess.Popen([sys.executable, "-m", "app", "--db", str(db), "--port", str(port)], cwd=tree,
                                  env={**os.environ, "PYTHONPATH": str(tree)},
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        url = f"http://127.0.0.1:{port}"
        try:
            with httpx.Client(base_url=url) as probe:
                for _ in range(600):
                    try:
                        if probe.get("/api/health").status_code == 200:
                            break
                    except httpx.TransportError:
                        pass
                    time.sleep(0.1)
            sampler = Sampler(url, token, server.pid)
            sampler.start()
            time.sleep(1.0)                     # a baseline of reads before the flood
            before = statistics.median(sampler.rss)
            quiet = list(sampler.latencies)
            started = time.perf_counter()
            answers = asyncio.run(flood(port, n, many_addresses, health))
            took = time.perf_counter() - started
            during = sampler.latencies[len(quiet):]
            time.sleep(1.0)
            sampler.stop.set()
            sampler.join()
            after = sampler.rss[-1]
        finally:
            server.terminate()
            server.wait(timeout=30)
    lat = [v * 1000 for v in during] or [float("nan")]
    what = "health, reference" if health else ("200 addresses" if many_addresses else "one address")
    print(f"{what:17s} flood of {n} took {took:6.2f} s; "
          f"/api/machine during it: n {len(lat)} p50 {statistics.median(lat):7.1f} ms "
          f"p99 {percentile(lat, 99):7.1f} ms max {max(lat):7.1f} ms (quiet p50 "
          f"{statistics.median(quiet) * 1000:.1f} ms); RSS MB before {before:.0f} peak {max(sampler.rss):.0f} "
          f"(+{max(sampler.rss) - before:.0f}) after {after:.0f}; answers {json.dumps(dict(answers))}")


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--tree", type=Path, default=ROOT, help="the checkout to run (default: this one)")
    parser.add_argument("--flood", type=int, default=200)
    args = parser.parse_args()
    print(f"tree {args.tree}")
    round_(args.tree.resolve(), args.flood, False, health=True)
    for many in (False, True):
        round_(args.tree.resolve(), args.flood, many)


if __name__ == "__main__":
    main()

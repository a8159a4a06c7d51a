"""OPC UA figures (run: python bench/bench_opcua.py): read round-trip, the delay from a jog's
answer to the subscription's data change (design.md §9.7 target: within 200 ms) over N jogs, and
the CPU the idle process uses with and without the endpoint (its 20 Hz polling).

Starts the HMI with the demo scenario and ``--opcua`` in this process (uvicorn in a thread, as the
tests do), jogs over HTTP and listens with an asyncua client.
"""

from __future__ import annotations

import asyncio
import resource
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "tests")]

import httpx  # noqa: E402
from asyncua import Client  # noqa: E402
from hmi_testdata import TEST_SCENARIO  # noqa: E402
from live import free_port, serve  # noqa: E402

JOGS, READS, IDLE_S = 20, 200, 5.0


def idle_cpu(settings: dict) -> float:
    """Per cent of one core the whole process uses over IDLE_S with a served HMI and no client."""
    with tempfile.TemporaryDirectory() as root, serve(Path(root), TEST_SCENARIO, start_timeout_s=90, settings=settings):
        time.sleep(1.0)
        before = resource.getrusage(resource.RUSAGE_SELF)
        time.sleep(IDLE_S)
        after = resource.getrusage(resource.RUSAGE_SELF)
    used = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return 100 * used / IDLE_S


async def measure(url: str, http: httpx.Client) -> tuple[list[float], list[float]]:
    async with Client(url, timeout=10) as client:
        idx = await client.get_namespace_index("urn:jog-measure-hmi")
        leaf = await client.nodes.objects.get_child([f"{idx}:JogMeasure", f"{idx}:Machine", f"{idx}:MCS", f"{idx}:X"])
        reads = []
        for _ in range(READS):
            started = time.perf_counter()
            await leaf.read_value()
            reads.append(time.perf_counter() - started)
        heard: list[tuple[float, float]] = []

        class Handler:
            def datachange_notification(self, _node, value, _data):
                heard.append((time.perf_counter(), value))

        subscription = await client.create_subscription(50, Handler())
        await subscription.subscribe_data_change(leaf)
        while not heard:
            await asyncio.sleep(0.01)
        delays = []
        for i in range(JOGS):
            distance = 1.0 if i % 2 == 0 else -1.0
            answer = await asyncio.to_thread(http.post, "/api/machine/jog", json={"axis": "X", "distance": distance})
            answered = time.perf_counter()
            target = answer.json()["mcs"]["X"]
            while not heard or heard[-1][1] != target:
                await asyncio.sleep(0.002)
            delays.append(heard[-1][0] - answered)
        return reads, delays


def main() -> None:
    port = free_port()
    with tempfile.TemporaryDirectory() as root, \
            serve(Path(root), TEST_SCENARIO, start_timeout_s=90, settings={"opcua_port": port}) as base:
        with httpx.Client(base_url=base, timeout=10) as http:
            reads, delays = asyncio.run(measure(f"opc.tcp://127.0.0.1:{port}", http))
    ms = [1000 * r for r in reads]
    print(f"read round-trip over {READS} reads: median {statistics.median(ms):.2f} ms, max {max(ms):.2f} ms")
    ms = sorted(1000 * max(d, 0.0) for d in delays)
    print(f"jog answer -> data change over {JOGS} jogs: median {statistics.median(ms):.0f} ms, "
          f"max {ms[-1]:.0f} ms (target 200 ms)")
    without, with_endpoint = idle_cpu({}), idle_cpu({"opcua_port": free_port()})
    print(f"idle CPU over {IDLE_S:.0f} s: {without:.1f} % of a core without OPC UA, {with_endpoint:.1f} % with it")


if __name__ == "__main__":
    main()

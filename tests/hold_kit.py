"""Hold a jog key in a Chromium that can be killed, beside a core kept busy (issue 24 §6).

Playwright's own browser cannot be killed from outside without losing its driver, so Chromium is
started here as a process of its own (remote debugging on a free port) and Playwright attaches
to it over CDP (``browser_type``: Playwright's chromium). ``hold_then`` holds the Cont jog key of axis Y on /jog until the axis has moved
a little, then runs ``act(page, chromium)`` (kill the browser, or let go of the key) and reports
the axis position at that moment and where it came to rest.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import httpx
from live import CHROMIUM_ARGS, free_port
from waiting import wait_until

JOG_FEED = 1000.0         # mm/min: the test scenario's jog feed


@contextmanager
def busy_core() -> Iterator[subprocess.Popen]:
    """A process that keeps one core busy while the block runs."""
    spinner = subprocess.Popen([sys.executable, "-c", "while True: pass"])
    try:
        yield spinner
    finally:
        spinner.kill()
        spinner.wait()


@contextmanager
def killable_chromium(profile: Path) -> Iterator[tuple[subprocess.Popen, int]]:
    port = free_port()
    chromium = subprocess.Popen(["/usr/bin/chromium", *CHROMIUM_ARGS, f"--remote-debugging-port={port}",
                                 f"--user-data-dir={profile}", "about:blank"],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)

    def listening() -> bool:
        try:
            return httpx.get(f"http://127.0.0.1:{port}/json/version", timeout=1).status_code == 200
        except httpx.HTTPError:
            return False

    try:
        wait_until(listening, "Chromium answers on its debugging port", 20)
        yield chromium, port
    finally:
        kill(chromium)


def kill(chromium: subprocess.Popen) -> None:
    """SIGKILL to Chromium and every process it started (renderers, network service)."""
    if chromium.poll() is None:
        try:
            os.killpg(chromium.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        chromium.wait()


def real_time(api: httpx.Client, scenario: dict) -> None:
    scenario = {**scenario, "machine": {**scenario["machine"], "time_scale": 1.0}}
    assert api.post("/api/sim/scenario", json={**scenario, "reset_data": True}).status_code == 200


def hold_then(browser_type, port: int, base_url: str, api: httpx.Client,
              act: Callable[[object], None]) -> tuple[float, float, float]:
    """(Y when ``act`` ran, Y at rest, seconds from ``act`` until the API reported the axis at rest)."""
    browser = browser_type.connect_over_cdp(f"http://127.0.0.1:{port}")
    page = browser.contexts[0].new_page()
    page.set_default_timeout(10_000)
    page.goto(base_url + "/jog")
    page.locator('#mcp button[data-axis="Y"]').click()
    page.wait_for_selector('#mcp[data-axis="Y"]')
    page.locator('#mcp button[data-increment="cont"]').click()
    page.wait_for_selector('#mcp[data-increment="cont"]')
    y0 = api.get("/api/machine").json()["mcs"]["Y"]
    page.locator('#mcp button[data-jog="+"]').hover()
    page.mouse.down()
    wait_until(lambda: api.get("/api/machine").json()["mcs"]["Y"] > y0 + 3.0, "the held key moves Y", 10)
    at_act = api.get("/api/machine").json()["mcs"]["Y"]
    acted = time.monotonic()
    act(page)
    state: dict = {}

    def at_rest() -> bool:
        state.update(api.get("/api/machine").json())
        return not state["busy"]

    wait_until(at_rest, "the axis stops", 10)
    return at_act, state["mcs"]["Y"], time.monotonic() - acted

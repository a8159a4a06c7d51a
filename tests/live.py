"""A real HMI served by uvicorn in a thread, for the Playwright tests (one helper, many fixtures)."""

from __future__ import annotations

import json
import socket
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from waiting import wait_until

MIN_WAIT_MS = 15000     # the shortest ceiling of a Playwright wait (page loads, locators, expect)
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync"]


def wait_for_requests(page, held, count: int = 1, timeout_s: float = MIN_WAIT_MS / 1000) -> None:
    """Until a route handler has held ``count`` requests (``held``: its list or dict). Waits with
    the page's own timer, so that Playwright runs the route handlers meanwhile; the ceiling is a
    Playwright wait's (5 s was too short beside a busy core: a page's first live event came later)."""
    for _ in range(int(timeout_s * 10)):
        if len(held) >= count:
            return
        page.wait_for_timeout(100)
    raise AssertionError(f"{len(held)} of {count} requests held within {timeout_s} s")


@contextmanager
def browser_tab(browser, base_url: str, width: int = 1280, height: int = 720, timeout_ms: int = 15000):
    """A page in a fresh browser context on ``base_url``; the context is closed afterwards. Waits end
    as soon as their state shows; the ceiling is at least 15 s, as the suite runs on two workers beside
    other load (a page load took over 5 s at load 14)."""
    context = browser.new_context(viewport={"width": width, "height": height}, base_url=base_url)
    context.set_default_timeout(max(timeout_ms, MIN_WAIT_MS))
    try:
        yield context.new_page()
    finally:
        context.close()


def watch_offline(page, base_url: str) -> dict:
    """Block and record every request of ``page`` outside the HMI at ``base_url`` (the machine has no
    internet), and record the console's errors, uncaught page errors and answers >= 400; returns
    that record, {"outside": [...], "errors": [...]}, also as ``page.seen``."""
    seen: dict[str, list[str]] = {"outside": [], "errors": []}

    def only_local(route):
        if route.request.url.startswith(base_url):
            if route.request.url.endswith("/favicon.ico"):     # the HMI has no icon: not the page's error
                return route.fulfill(status=204)
            return route.continue_()
        seen["outside"].append(route.request.url)
        return route.abort()

    page.route("**/*", only_local)
    page.on("console", lambda m: m.type == "error" and seen["errors"].append(m.text))
    page.on("pageerror", lambda e: seen["errors"].append(str(e)))
    page.on("response", lambda r: r.status >= 400 and seen["errors"].append(f"{r.status} {r.url}"))
    page.seen = seen
    return seen


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


@contextmanager
def serve(root: Path, scenario: dict, start_timeout_s: float = 15.0, settings: dict | None = None,
          prepare=None) -> Iterator[str]:
    """Serve the app on a free loopback port with a fresh db under ``root``; yields the base URL.
    ``settings``: more ``Settings`` fields; ``prepare(app)`` runs before the start (users, ...)."""
    import uvicorn

    from app.config import Settings
    from app.main import create_app

    root.mkdir(parents=True, exist_ok=True)
    scenario_path = root / "scenario.json"
    scenario_path.write_text(json.dumps(scenario))
    port = free_port()
    app = create_app(Settings(db_path=root / "hmi.db", scenario_path=scenario_path, port=port, **(settings or {})))
    if prepare is not None:
        prepare(app)
    server = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=port, log_level="warning"))
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    wait_until(lambda: server.started, "the live server starts", start_timeout_s)
    try:
        yield f"http://127.0.0.1:{port}"
    finally:
        server.should_exit = True
        thread.join(timeout=5)


@contextmanager
def hmi_process(db: str, scenario_file: Path, what: str) -> Iterator[str]:
    """``python -m app --db <db>`` as its own process on a free port until it answers /api/health;
    yields its base URL and ends it afterwards (``what``: the wait's description)."""
    import subprocess
    import sys

    import httpx

    port = free_port()
    server = subprocess.Popen([sys.executable, "-m", "app", "--db", db, "--port", str(port),
                               "--scenario", str(scenario_file)], stdout=subprocess.DEVNULL,
                              stderr=subprocess.PIPE, text=True)
    url = f"http://127.0.0.1:{port}"

    def healthy() -> bool:
        if server.poll() is not None:
            raise AssertionError(f"the HMI ended: {server.stderr.read() if server.stderr else ''}")
        try:
            return httpx.get(f"{url}/api/health").status_code == 200
        except httpx.TransportError:
            return False

    try:
        wait_until(healthy, what, 60)
        yield url
    finally:
        server.terminate()
        server.wait(timeout=30)


"""Helpers of the OPC UA tests: users of each level, the ``Live`` server handle and an asyncua
client (a module of its own: ``conftest`` is a name every test folder has)."""

from __future__ import annotations

import asyncio
import threading
import time
from contextlib import asynccontextmanager
from dataclasses import dataclass

import httpx

# serv (level 2) may write zero offsets once the module sets the level to 2; anna (3) may not
USERS = {"serv": ("service-pw", 2), "anna": ("user-pw-3", 3)}
OFFSETS_LEVEL = 2


@dataclass
class Live:
    http: httpx.Client           # signed in with a level-1 token (sign-in is on: users exist)
    opc_url: str
    app: object


def add_users(app) -> str:
    """The users above, the offsets level, and a level-1 API token for the HTTP side (returned)."""
    access = app.state.access
    for name, (password, level) in USERS.items():
        access.add_user(name, level, password)
    secret, _record = access.add_token("tests", 1)
    app.state.services.settings.put({"level_offsets": OFFSETS_LEVEL}, source="tests")
    return secret


@asynccontextmanager
async def opc_client(url: str, user: str | None = None, password: str | None = None):
    """An asyncua client session (anonymous without ``user``); yields (client, namespace index)."""
    from asyncua import Client

    client = Client(url, timeout=10)
    if user is not None:
        client.set_user(user)
        client.set_password(password)
    async with client:
        yield client, await client.get_namespace_index("urn:jog-measure-hmi")


async def node(client, idx: int, *path: str):
    return await client.nodes.objects.get_child([f"{idx}:JogMeasure", *(f"{idx}:{p}" for p in path)])


def run(coro):
    """The client coroutine in a thread of its own: in the whole suite Playwright's sync API
    keeps an event loop running in the main thread, where asyncio.run() is refused."""
    result: dict = {}

    def target() -> None:
        try:
            result["value"] = asyncio.run(coro)
        except BaseException as exc:  # noqa: BLE001  (re-raised in the test's thread)
            result["error"] = exc

    thread = threading.Thread(target=target, name="opcua-test-client")
    thread.start()
    thread.join()
    if "error" in result:
        raise result["error"]
    return result["value"]


async def wait_for(predicate, timeout_s: float = 2.0, period_s: float = 0.02):
    """Polls ``predicate()`` (sync) until true; returns the seconds it took, or fails."""
    started = time.monotonic()
    while not predicate():
        if time.monotonic() - started > timeout_s:
            raise AssertionError(f"not within {timeout_s} s")
        await asyncio.sleep(period_s)
    return time.monotonic() - started

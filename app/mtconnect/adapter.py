"""An MTConnect SHDR adapter in the HMI's process (``--mtconnect PORT``): an MTConnect agent
connects over TCP and receives the data items of ``items.py``, first all of them, then every
change within one period (``PERIOD_S``). The agent's heartbeat ``* PING`` is answered with
``* PONG <ms>`` (MTConnect adapter protocol), so the agent notices a dead HMI. Read only.

One thread runs a ``selectors`` loop over the listening socket and the agents' sockets.
"""

from __future__ import annotations

import logging
import selectors
import socket
import threading
import time

from app import ports
from app.services import Services

from .items import UNAVAILABLE, conditions, offsets_table, samples, timestamp

log = logging.getLogger(__name__)
PERIOD_S = 0.05
HEARTBEAT_MS = 10_000
MAX_AGENTS = 8


class MtConnectStartError(RuntimeError):
    """The adapter could not start (the message is one line for the operator)."""


def port_problem(host: str, port: int) -> str | None:
    return ports.port_problem(host, port, "MTConnect", "--mtconnect")


class ShdrAdapter:
    def __init__(self, services: Services, host: str, port: int):
        self._services = services
        self._host, self._port = host, port
        self._thread: threading.Thread | None = None
        self._stop = threading.Event()
        self._agents: dict[socket.socket, bytearray] = {}       # socket -> bytes received, not yet a line
        self._waiting: set[socket.socket] = set()     # connected before the first whole state was read
        self._items: dict[str, str] = {}
        self._table = ""
        self._alarms: set[tuple[int, str]] | None = None
        self._generation: int | None = None

    # --- life --------------------------------------------------------------------------------
    def start(self) -> None:
        problem = port_problem(self._host, self._port)
        if problem:
            raise MtConnectStartError(problem)
        try:
            listener = socket.create_server((self._host, self._port), reuse_port=False)
        except OSError as exc:
            raise MtConnectStartError(f"MTConnect port {self._port} on {self._host} cannot be opened "
                                      f"({exc.strerror or exc})") from exc
        listener.setblocking(False)
        self._thread = threading.Thread(target=self._run, args=(listener,), name="mtconnect", daemon=True)
        self._thread.start()
        log.info("MTConnect SHDR adapter on %s:%d", self._host, self._port)

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=5)
            self._thread = None

    # --- the loop ------------------------------------------------------------------------------
    def _run(self, listener: socket.socket) -> None:
        selector = selectors.DefaultSelector()
        selector.register(listener, selectors.EVENT_READ)
        next_read = 0.0
        try:
            while not self._stop.is_set():
                for key, _events in selector.select(timeout=PERIOD_S):
                    if key.fileobj is listener:
                        self._accept(selector, listener)
                    elif isinstance(key.fileobj, socket.socket):      # an agent's
                        self._receive(selector, key.fileobj)
                if time.monotonic() >= next_read:
                    next_read = time.monotonic() + PERIOD_S
                    self._update(selector)
        finally:
            for agent in list(self._agents):
                self._drop(selector, agent)
            selector.close()
            listener.close()

    def _accept(self, selector, listener: socket.socket) -> None:
        try:
            agent, address = listener.accept()
        except BlockingIOError:
            return
        if len(self._agents) >= MAX_AGENTS:
            agent.close()
            return
        agent.setblocking(False)
        selector.register(agent, selectors.EVENT_READ)
        self._agents[agent] = bytearray()
        log.info("MTConnect agent %s connected", address[0])
        if self._alarms is None:           # nothing read yet: the whole state follows the first read
            self._waiting.add(agent)
        else:
            self._send(selector, agent, self._snapshot())

    def _receive(self, selector, agent: socket.socket) -> None:
        try:
            data = agent.recv(4096)
        except (BlockingIOError, InterruptedError):
            return
        except OSError:
            data = b""
        if not data:
            self._drop(selector, agent)
            return
        pending = self._agents[agent]
        pending += data
        while b"\n" in pending:
            line, _, rest = bytes(pending).partition(b"\n")
            pending[:] = rest
            if line.strip().startswith(b"* PING"):
                self._send(selector, agent, f"* PONG {HEARTBEAT_MS}\n")
        if len(pending) > 4096:                 # not an agent
            self._drop(selector, agent)

    def _drop(self, selector, agent: socket.socket) -> None:
        self._agents.pop(agent, None)
        self._waiting.discard(agent)
        try:
            selector.unregister(agent)
        except (KeyError, ValueError):
            pass
        agent.close()

    def _send(self, selector, agent: socket.socket, text: str) -> None:
        try:
            agent.sendall(text.encode())      # small lines; a stuck agent is dropped, not waited for
        except OSError:
            self._drop(selector, agent)

    # --- what to send --------------------------------------------------------------------------
    def _snapshot(self) -> str:
        now = timestamp()
        lines = [now + "|" + "|".join(f"{k}|{v}" for k, v in self._items.items())]
        lines += [f"{now}|{line}" for line in conditions(self._alarms or set(), None)]
        lines.append(f"{now}|woffsets|{self._table}")
        return "\n".join(lines) + "\n"

    def _update(self, selector) -> None:
        try:
            changes = self._read()
        except Exception as exc:          # a controller or database hiccup must not end the adapter
            log.warning("MTConnect update failed: %s", exc, exc_info=True)
            return
        waiting, self._waiting = self._waiting, set()
        for agent in waiting:
            self._send(selector, agent, self._snapshot())
        if changes:
            for agent in [a for a in self._agents if a not in waiting]:
                self._send(selector, agent, changes)

    def _read(self) -> str:
        """Reads the services and returns the SHDR lines of what changed ('' for nothing). Everything
        is read before anything is kept, so a failed read leaves the last whole state as it was."""
        status = self._services.machine.status()
        items = samples(status)
        alarms = {(int(a["code"]), str(a["text"])) for a in status["alarms"]}
        generation = self._services.db.generation
        table = self._table
        if generation != self._generation:
            table = offsets_table(self._services.offsets.list())
        now = timestamp()
        changed = {k: v for k, v in items.items() if self._items.get(k) != v}
        changed |= {k: UNAVAILABLE for k in self._items if k not in items}    # an axis the machine lost
        lines = [now + "|" + "|".join(f"{k}|{v}" for k, v in changed.items())] if changed else []
        if self._alarms is not None and alarms != self._alarms:
            lines += [f"{now}|{line}" for line in conditions(alarms, self._alarms)]
        if table != self._table:
            lines.append(f"{now}|woffsets|{table}")
        self._items, self._alarms, self._generation, self._table = items, alarms, generation, table
        return "\n".join(lines) + "\n" if lines else ""

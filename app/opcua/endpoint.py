"""The OPC UA server's life in the HMI's process: its own thread and asyncio loop (HTTP keeps its
loop to itself), started by the app's lifespan and stopped before the services close.

Live values: a task reads the machine status 20 times a second (``PERIOD_S``) and the stored
offsets and the newest log entry whenever the database's write counter moved
(``Database.generation``), and writes only what changed, so a subscription hears of a change
within one period plus its publishing interval.
"""

from __future__ import annotations

import asyncio
import logging
import socket
import threading
import time
from pathlib import Path
from typing import TYPE_CHECKING

from asyncua import Server

from app import ports
from app.access.service import AccessService
from app.services import Services

from . import security
from .alarms import AlarmEvents
from .results import ResultManagement
from .space import JogMeasureSpace
from .users import HmiUserManager, count_sign_ins_per_client
from .values import alarm_keys, machine_values, measurement_value, offset_values
from .writes import GuardedAttributeService

if TYPE_CHECKING:
    from .umati import MachineToolInstance  # imported at run time by _load_umati only

log = logging.getLogger(__name__)
NAMESPACE = "urn:jog-measure-hmi"
PERIOD_S = 0.05
START_TIMEOUT_S = 30.0


class OpcUaStartError(RuntimeError):
    """The endpoint could not start (the message is one line for the operator)."""


def port_problem(host: str, port: int) -> str | None:
    return ports.port_problem(host, port, "OPC UA", "--opcua")


class OpcUaEndpoint:
    def __init__(self, services: Services, access: AccessService, host: str, port: int, data_dir: Path,
                 umati: bool = False):
        self._services, self._access = services, access
        self._host, self._port, self._data_dir = host, port, data_dir
        self._umati = umati
        self._thread: threading.Thread | None = None
        self._loop: asyncio.AbstractEventLoop | None = None
        self._stop: asyncio.Event | None = None
        self._ready = threading.Event()
        self._error: str | None = None
        self.security_policies: list[str] = []
        self.umati_state = "off" if not umati else "loading"     # "loaded", "failed: ..." later

    @property
    def url(self) -> str:
        host = f"[{self._host}]" if ":" in self._host else self._host
        return f"opc.tcp://{host}:{self._port}"

    # --- life --------------------------------------------------------------------------------
    def start(self) -> None:
        """Serve, or raise OpcUaStartError; returns once clients can connect."""
        problem = port_problem(self._host, self._port)
        if problem:
            raise OpcUaStartError(problem)
        self._thread = threading.Thread(target=self._run, name="opcua", daemon=True)
        self._thread.start()
        if not self._ready.wait(START_TIMEOUT_S):
            raise OpcUaStartError(f"OPC UA did not start within {START_TIMEOUT_S:.0f} s")
        if self._error:
            self._thread.join(timeout=5)
            raise OpcUaStartError(self._error)

    def stop(self) -> None:
        if self._thread is None:
            return
        if self._loop is not None and self._stop is not None:
            self._loop.call_soon_threadsafe(self._stop.set)
        self._thread.join(timeout=10)
        self._thread = None

    def _run(self) -> None:
        try:
            asyncio.run(self._main())
        except Exception as exc:         # start-up failures are reported by start(); this is the rest
            log.exception("OPC UA endpoint stopped: %s", exc)
        finally:
            self._ready.set()

    async def _main(self) -> None:
        self._loop = asyncio.get_running_loop()
        self._stop = asyncio.Event()
        try:
            server, updates = await self._serve()
        except OSError as exc:
            self._error = f"OPC UA port {self._port} on {self._host} cannot be opened ({exc.strerror or exc})"
            return
        except Exception as exc:
            self._error = f"OPC UA did not start: {exc}"
            log.exception("OPC UA start")
            return
        log.info("OPC UA at %s (%s)", self.url, ", ".join(self.security_policies))
        self._ready.set()
        tasks = [asyncio.create_task(updates.run(self._stop), name="opcua-updates")]
        if self._umati:
            tasks.append(asyncio.create_task(self._load_umati(server, updates), name="opcua-umati"))
        try:
            await self._stop.wait()
        finally:
            for task in tasks:
                task.cancel()
            await asyncio.gather(*tasks, return_exceptions=True)
            await server.stop()

    async def _serve(self) -> tuple[Server, Updates]:
        server = Server(user_manager=HmiUserManager(self._access))
        await server.init()
        server.set_endpoint(self.url)
        server.set_server_name("JOG Measure HMI")
        server.allow_remote_admin(False)
        app_uri = f"urn:{socket.gethostname()}:jog-measure-hmi"
        await server.set_application_uri(app_uri)
        self.security_policies = await security.configure(server, self._data_dir, app_uri)
        idx = await server.register_namespace(NAMESPACE)
        space = JogMeasureSpace(server, idx)
        await space.build()
        updates = Updates(self._services, space)
        await updates.step()                       # every node exists before the first client
        updates.alarms = AlarmEvents()
        await updates.alarms.setup(server, idx, space.node(("Machine",)))
        await updates.step()                       # the alarms of the start are the baseline
        updates.results = ResultManagement(server, idx, self._services)      # OPC 40001-101 (design.md §10.3)
        await updates.results.setup(space.node(()))
        iserver = server.iserver
        count_sign_ins_per_client(iserver)
        iserver.attribute_service = GuardedAttributeService(
            iserver.aspace, self._services, self._access, space.writable, updates.show_offset)
        await server.start()
        return server, updates

    async def _load_umati(self, server: Server, updates: Updates) -> None:
        from .umati import MachineToolInstance

        started = time.perf_counter()
        try:
            idx = await server.get_namespace_index(NAMESPACE)
            status = await asyncio.to_thread(self._services.machine.status)
            instance = MachineToolInstance(server, idx, status["controller"])
            await instance.load()
        except Exception as exc:
            self.umati_state = f"failed: {exc}"
            log.exception("umati MachineTool instance")
            return
        updates.umati = instance
        self.umati_state = "loaded"
        log.info("OPC UA: umati MachineTool instance loaded in %.1f s", time.perf_counter() - started)


class Updates:
    """Reads the services in a worker thread and shows what changed."""

    def __init__(self, services: Services, space: JogMeasureSpace):
        self._services = services
        self._space = space
        self.alarms: AlarmEvents | None = None
        self._generation: int | None = None
        self.umati: MachineToolInstance | None = None
        self.results: ResultManagement | None = None

    def _read(self) -> tuple[dict, dict | None, list | None]:
        status = self._services.machine.status()
        generation = self._services.db.generation      # before the reads: a later commit reads again
        if generation == self._generation:
            return status, None, None
        offsets = self._services.offsets.list()
        newest = self._services.log.list(limit=1)
        self._generation = generation
        return status, offsets, newest

    async def step(self) -> None:
        status, offsets, newest = await asyncio.to_thread(self._read)
        values = machine_values(status)
        await self._space.prune(values, (("Machine", "MCS"), ("Machine", "WCS")))
        if offsets is not None:
            stored = offset_values(offsets, self._services.machine.rotary_axes)
            await self._space.prune(stored, (("ZeroOffsets",),))
            values |= stored | measurement_value(newest[0] if newest else None)
            if self.results is not None:
                await self.results.notify(newest[0] if newest else None)
        await self._space.show(values)
        if self.alarms is not None:
            await self.alarms.show(alarm_keys(status))
        if self.umati is not None:
            await self.umati.show(status)

    async def show_offset(self, name: str, frame: dict) -> None:
        """After a write through OPC UA: its nodes show the stored frame at once."""
        await self._space.show(offset_values({name: frame}, self._services.machine.rotary_axes))

    async def run(self, stop: asyncio.Event) -> None:
        failing = False
        while not stop.is_set():
            try:
                await self.step()
                failing = False
            except Exception as exc:         # a controller or database hiccup must not end the endpoint
                if not failing:
                    log.warning("OPC UA update failed: %s", exc, exc_info=True)
                failing = True
            try:
                await asyncio.wait_for(stop.wait(), timeout=PERIOD_S)
            except TimeoutError:
                pass


__all__ = ["NAMESPACE", "OpcUaEndpoint", "OpcUaStartError", "port_problem"]

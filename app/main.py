"""``create_app(settings)``: wires db, machine (by the registry), services, routers, templates and static files."""

from __future__ import annotations

import asyncio
import gc
from contextlib import asynccontextmanager
from pathlib import Path
from typing import Protocol

from asgi_csrf import asgi_csrf
from fastapi import FastAPI
from starlette.routing import Mount, Route

from app import openapi_doc, route_cache
from app.access.deps import PUBLIC_ROUTES
from app.access.handlers import install_access_handlers
from app.access.middleware import (
    LOOPBACK_NAMES,
    AccessGuard,
    HostGuard,
    SecurityHeaders,
    csrf_exempt,
    csrf_failed,
    is_loopback_host,
)
from app.access.service import CSRF_COOKIE, AccessService
from app.api import api_router
from app.config import Settings
from app.errors import install_handlers
from app.http_limits import BodySizeLimit
from app.machine.lathe_scenario import LatheScenario
from app.machine.registry import build_machine
from app.machine.scenario import Scenario
from app.services import (
    LogService,
    MachineService,
    MemoryService,
    NcService,
    OffsetService,
    ProbeService,
    ProgramService,
    QualityService,
    ResultsService,
    Services,
    SettingsService,
    ToolProbeService,
    ToolService,
)
from app.services.measuring import MeasuringEnv
from app.services.plant import PlantService
from app.services.plc import PlcSimulator
from app.services.probe_health import ProbeHealthService
from app.services.probe_test import ProbeTestService
from app.services.scenarios import read_scenario
from app.web import web_router
from app.web.fast_reads import CachedReads
from app.web.language import LanguageMiddleware
from app.web.static_files import STATIC_DIR, VersionedStaticFiles
from app.workflow.service import WorkflowService
from db import Database

ROOT = Path(__file__).resolve().parent.parent


def machine_options(settings: Settings) -> dict:
    """The controller's own start-up options (design.md §10.7): LinuxCNC's configuration folder
    follows ``--db``; ``--linuxcnc-ini`` runs the machine's own configuration."""
    if settings.machine != "linuxcnc":
        return {}
    options: dict = {"db_path": None if settings.db_url else settings.db_path}
    if settings.linuxcnc_ini is not None:
        options["ini"] = settings.linuxcnc_ini
    return options


def build_services(settings: Settings, scenario: Scenario | LatheScenario) -> Services:
    options = machine_options(settings)
    controller = build_machine(settings.machine, scenario, options)   # an unknown name fails before the db is touched
    db = Database(settings.database, rotary_axes=tuple(a for a in scenario.axes if a not in "XYZ"),
                  machine=settings.machine_name, stand_in=True)   # unreachable: read only (§10.8)
    gud = SettingsService(db)
    machine = MachineService(db, controller, scenario, gud,
                             rebuild=lambda other: build_machine(settings.machine, other, options))   # lathe <-> mill
    services = Services(
        db=db, settings=gud, machine=machine,
        offsets=OffsetService(db, machine), tools=ToolService(db, machine),
        probes=ProbeService(db, gud), tool_probes=ToolProbeService(db, gud), log=LogService(db),
    )
    services.memories = MemoryService(db)
    env = MeasuringEnv(db, machine, gud)
    services.results = env.results = ResultsService(db, gud, getattr(settings, "machine_name", None))
    services.quality = QualityService(db, services.results)
    services.workflow = WorkflowService(env)
    services.nc = NcService(db, machine, env, gud)
    services.programs = ProgramService(db, services.nc)
    machine.mode_source = lambda: services.nc.mode
    machine.on_discard(services.workflow.discard_points)
    machine.on_reset(services.workflow.abort, services.workflow.wait_idle)   # one Reset (issue 24 §3)
    machine.add_interlock(services.workflow.interlock)
    machine.lock_source = lambda: services.nc.lock() or services.workflow.lock()
    services.plc = PlcSimulator(lambda: services.workflow)
    services.plant = PlantService(db, machine.status)
    services.probe_test = ProbeTestService(machine)
    services.probe_health = ProbeHealthService(db, machine, gud)
    db.start_up_done()
    return services


def trusted_hosts(settings: Settings) -> list[str]:
    """The Host names the HMI answers to: the loopback names, the bind address when it is a name or
    an address of its own (not 0.0.0.0/::), and ``settings.trusted_hosts``."""
    names = [*LOOPBACK_NAMES, *settings.trusted_hosts]
    if settings.host not in ("0.0.0.0", "::", "") and not is_loopback_host(settings.host):
        names.append(f"[{settings.host}]" if ":" in settings.host else settings.host)
    return list(dict.fromkeys(name.lower() for name in names))


def _flat_routes(app: FastAPI) -> list:
    """Every route, the ones of lazily included routers too (FastAPI >= 0.16x keeps those apart)."""
    import fastapi.routing

    flatten = getattr(fastapi.routing, "iter_route_contexts", None)
    return list(flatten(app.routes)) if flatten else list(app.routes)


def create_app(settings: Settings | None = None) -> FastAPI:
    settings = settings or Settings()
    scenario = read_scenario(settings)
    services = build_services(settings, scenario)

    @asynccontextmanager
    async def lifespan(_app: FastAPI):
        # the start-up objects (numpy, SQLAlchemy, templates) never become garbage: keep the
        # collector from walking them on every full collection (100-460 ms pauses otherwise)
        gc.collect()
        gc.freeze()
        endpoints = _app.state.endpoints
        for endpoint in endpoints:              # OPC UA, MTConnect: a start error stops the HMI's start
            await asyncio.to_thread(endpoint.start)
        plant = services.plant
        if plant is not None:                   # the plant view's heartbeat (design.md §10.5)
            await asyncio.to_thread(plant.start)
        yield
        if plant is not None:
            plant.stop()
        for endpoint in reversed(endpoints):    # before the services they read close
            await asyncio.to_thread(endpoint.stop)
        if services.nc is not None:             # build_services made it
            services.nc.close()
        services.machine.close()
        services.db.close()

    # /docs and /redoc are app/web/docs.py: vendored Swagger UI / ReDoc, offline, under the CSP
    app = FastAPI(title="Measure-in-JOG HMI", version="0.1.0", lifespan=lifespan, docs_url=None, redoc_url=None)
    app.state.settings = settings
    app.state.services = services
    access = app.state.access = AccessService(services.db, settings.session_hours)
    install_handlers(app)
    install_access_handlers(app)
    # request checks, outermost last (app/access/middleware.py explains each and the CSRF rule)
    app.add_middleware(asgi_csrf, cookie_name=CSRF_COOKIE, http_header="x-csrftoken",
                       signing_secret=access.csrf_secret(), skip_if_scope=csrf_exempt, cookie_samesite="Strict",
                       send_csrf_failed=csrf_failed)
    app.add_middleware(CachedReads)                 # the polls from their cached bytes (app/web/fast_reads.py)
    app.add_middleware(AccessGuard, access=access)
    app.add_middleware(BodySizeLimit)
    app.add_middleware(HostGuard, allowed_hosts=trusted_hosts(settings))
    app.add_middleware(SecurityHeaders)
    app.add_middleware(LanguageMiddleware)          # the screens' language (app/web/language.py)
    app.include_router(api_router)
    app.include_router(web_router)
    route_cache.install()                           # the routes' matches kept per path (app/route_cache.py)
    app.mount("/static", VersionedStaticFiles(directory=STATIC_DIR), name="static")
    openapi_doc.install(app, public_paths={r.path for r in _flat_routes(app)
                                            if isinstance(r.route if hasattr(r, "original_route") else r, Route | Mount)
                                            and r.name in PUBLIC_ROUTES})
    app.state.endpoints = shop_floor_endpoints(settings, services, access)
    return app


class ShopFloorEndpoint(Protocol):
    """What the lifespan does with an endpoint (OPC UA, MTConnect): start it, stop it."""

    def start(self) -> None: ...

    def stop(self) -> None: ...


def shop_floor_endpoints(settings: Settings, services: Services, access: AccessService) -> list[ShopFloorEndpoint]:
    """The OPC UA endpoint (design.md §9.7) and the MTConnect adapter when asked for; started and
    stopped by the lifespan."""
    endpoints: list[ShopFloorEndpoint] = []
    if settings.opcua_port is not None:
        from app.opcua import OpcUaEndpoint  # asyncua is imported only when OPC UA is on

        endpoints.append(OpcUaEndpoint(services, access, settings.host, settings.opcua_port,
                                       settings.db_path.parent, umati=settings.opcua_umati))
    if settings.mtconnect_port is not None:
        from app.mtconnect import ShdrAdapter

        endpoints.append(ShdrAdapter(services, settings.host, settings.mtconnect_port))
    return endpoints

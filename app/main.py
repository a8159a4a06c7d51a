"""``create_app(settings)``: wires db, simulated machine, services, routers, templates and static files."""

from __future__ import annotations

from contextlib import asynccontextmanager
from pathlib import Path

from fastapi import FastAPI
from fastapi.staticfiles import StaticFiles

from app.api import api_router
from app.config import Settings
from app.errors import install_handlers
from app.machine.scenario import Scenario
from app.machine.sim import SimulatedMachine
from app.services import (
    LogService,
    MachineService,
    OffsetService,
    ProbeService,
    Services,
    SettingsService,
    ToolProbeService,
    ToolService,
)
from app.services.measuring import MeasuringEnv
from app.services.plc import PlcSimulator
from app.services.scenarios import read_scenario
from app.web import web_router
from app.workflow.registry import build_workflow
from db import Database

ROOT = Path(__file__).resolve().parent.parent
STATIC_DIR = ROOT / "static"


def build_services(settings: Settings, scenario: Scenario) -> Services:
    db = Database(settings.db_path, rotary_axes=tuple(a for a in scenario.axes if a not in "XYZ"))
    gud = SettingsService(db)
    machine = MachineService(db, SimulatedMachine(scenario), scenario, gud)
    services = Services(
        db=db, settings=gud, machine=machine,
        offsets=OffsetService(db, machine), tools=ToolService(db, machine),
        probes=ProbeService(db), tool_probes=ToolProbeService(db), log=LogService(db),
    )
    services.workflow = build_workflow(MeasuringEnv(db, machine, gud))
    services.plc = PlcSimulator(lambda: services.workflow)
    return services


def create_app(settings: Settings | None = None) -> FastAPI:
    settings = settings or Settings()
    scenario = read_scenario(settings)
    services = build_services(settings, scenario)

    @asynccontextmanager
    async def lifespan(_app: FastAPI):
        yield
        services.machine.machine.stop()
        services.db.close()

    app = FastAPI(title="Measure-in-JOG HMI", version="0.1.0", lifespan=lifespan)
    app.state.settings = settings
    app.state.services = services
    install_handlers(app)
    app.include_router(api_router)
    app.include_router(web_router)
    app.mount("/static", StaticFiles(directory=STATIC_DIR), name="static")
    return app

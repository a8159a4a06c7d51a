"""Services: orchestrate the machine, the engine and the db. Routers stay thin and call these.

``Services`` is the container the app builds once (``app.state.services``); routers get the
parts through the ``Annotated`` dependencies in ``app.deps``.
"""

from __future__ import annotations

from dataclasses import dataclass

from app.workflow.service import WorkflowService
from db import Database

from .log import LogService
from .machine_service import MachineService
from .memories import MemoryService
from .nc import NcService, ProgramService
from .offsets import OffsetService
from .plant import PlantService
from .plc import PlcSimulator
from .probe_health import ProbeHealthService
from .probe_test import ProbeTestService
from .probes import ProbeService, ToolProbeService
from .quality import QualityService
from .results import ResultsService
from .settings import SettingsService
from .tools import ToolService


@dataclass
class Services:
    db: Database
    settings: SettingsService
    machine: MachineService
    offsets: OffsetService
    tools: ToolService
    probes: ProbeService
    tool_probes: ToolProbeService
    log: LogService
    memories: MemoryService | None = None
    workflow: WorkflowService | None = None
    plc: PlcSimulator | None = None
    nc: NcService | None = None
    programs: ProgramService | None = None
    probe_test: ProbeTestService | None = None
    probe_health: ProbeHealthService | None = None
    results: ResultsService | None = None
    quality: QualityService | None = None
    plant: PlantService | None = None


__all__ = ["LogService", "MachineService", "MemoryService", "NcService", "OffsetService", "ProbeService", "ProgramService", "QualityService", "ResultsService",
           "Services", "ToolProbeService", "SettingsService", "ToolService"]

"""``Annotated`` dependencies: routers declare ``machine: MachineDep`` and get the service."""

from __future__ import annotations

from typing import Annotated

from fastapi import Depends, Request

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
from app.services.plant import PlantService
from app.services.plc import PlcSimulator
from app.services.probe_health import ProbeHealthService
from app.services.probe_test import ProbeTestService
from app.workflow.service import WorkflowService


async def get_services(request: Request) -> Services:
    # async: an attribute read needs no worker thread (a sync dependency costs one hop per request)
    return request.app.state.services


ServicesDep = Annotated[Services, Depends(get_services)]


def _part(name: str):
    """``Depends`` on one part of the ``Services`` container."""
    async def get(services: ServicesDep):
        return getattr(services, name)
    return Depends(get)


MachineDep = Annotated[MachineService, _part("machine")]
OffsetsDep = Annotated[OffsetService, _part("offsets")]
ToolsDep = Annotated[ToolService, _part("tools")]
ProbesDep = Annotated[ProbeService, _part("probes")]
ToolProbesDep = Annotated[ToolProbeService, _part("tool_probes")]
SettingsDep = Annotated[SettingsService, _part("settings")]
LogDep = Annotated[LogService, _part("log")]
MemoriesDep = Annotated[MemoryService, _part("memories")]
WorkflowDep = Annotated[WorkflowService, _part("workflow")]
NcDep = Annotated[NcService, _part("nc")]
ProgramsDep = Annotated[ProgramService, _part("programs")]
PlcDep = Annotated[PlcSimulator, _part("plc")]
ProbeTestDep = Annotated[ProbeTestService, _part("probe_test")]
ProbeHealthDep = Annotated[ProbeHealthService, _part("probe_health")]
ResultsDep = Annotated[ResultsService, _part("results")]
QualityDep = Annotated[QualityService, _part("quality")]
PlantDep = Annotated[PlantService, _part("plant")]

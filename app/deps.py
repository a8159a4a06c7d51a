"""``Annotated`` dependencies: routers declare ``machine: MachineDep`` and get the service."""

from __future__ import annotations

from typing import Annotated

from fastapi import Depends, Request

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
from app.workflow.service import WorkflowService


def get_services(request: Request) -> Services:
    return request.app.state.services


ServicesDep = Annotated[Services, Depends(get_services)]


def _machine(services: ServicesDep) -> MachineService:
    return services.machine


def _offsets(services: ServicesDep) -> OffsetService:
    return services.offsets


def _tools(services: ServicesDep) -> ToolService:
    return services.tools


def _probes(services: ServicesDep) -> ProbeService:
    return services.probes


def _tool_probes(services: ServicesDep) -> ToolProbeService:
    return services.tool_probes


def _log(services: ServicesDep) -> LogService:
    return services.log


def _settings(services: ServicesDep) -> SettingsService:
    return services.settings


MachineDep = Annotated[MachineService, Depends(_machine)]
OffsetsDep = Annotated[OffsetService, Depends(_offsets)]
ToolsDep = Annotated[ToolService, Depends(_tools)]
ProbesDep = Annotated[ProbeService, Depends(_probes)]
ToolProbesDep = Annotated[ToolProbeService, Depends(_tool_probes)]
SettingsDep = Annotated[SettingsService, Depends(_settings)]
LogDep = Annotated[LogService, Depends(_log)]


def _workflow(services: ServicesDep) -> WorkflowService:
    return services.workflow


WorkflowDep = Annotated[WorkflowService, Depends(_workflow)]

"""Stored data: zero offsets, tools, probes, tool probes, settings, log, audit trail."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Body, Path, Query

from app.deps import LogDep, OffsetsDep, ProbesDep, SettingsDep, ToolProbesDep, ToolsDep

router = APIRouter(tags=["data"])
JsonObject = Annotated[dict, Body()]


@router.get("/offsets")
def list_offsets(offsets: OffsetsDep) -> dict:
    """{name: frame} in chain order."""
    return offsets.list()


@router.get("/offsets/{name}")
def get_offset(name: str, offsets: OffsetsDep) -> dict:
    return offsets.get(name)


@router.put("/offsets/{name}")
def put_offset(name: str, body: JsonObject, offsets: OffsetsDep) -> dict:
    """Merges the given components onto the stored frame; audited with source "api"."""
    return offsets.put(name, body, source="api")


@router.get("/audit")
def audit(offsets: OffsetsDep, limit: Annotated[int, Query(ge=1, le=1000)] = 50,
          name: str | None = None) -> list[dict]:
    return offsets.audit(limit, name)


@router.get("/tools")
def list_tools(tools: ToolsDep) -> list[dict]:
    return tools.list()


@router.get("/tools/{t}")
def get_tool(t: int, tools: ToolsDep) -> dict:
    return tools.get(t)


@router.put("/tools/{t}")
def put_tool(t: int, body: JsonObject, tools: ToolsDep) -> dict:
    """Creates or updates tool ``t`` (fields not given keep their value)."""
    return tools.put(t, body)


@router.delete("/tools/{t}", status_code=204)
def delete_tool(t: int, tools: ToolsDep) -> None:
    tools.delete(t)


@router.get("/probes")
def list_probes(probes: ProbesDep) -> list[dict]:
    return probes.list()


@router.get("/probes/{n}")
def get_probe(n: int, probes: ProbesDep) -> dict:
    return probes.get(n)


@router.put("/probes/{n}")
def put_probe(n: int, body: JsonObject, probes: ProbesDep) -> dict:
    return probes.put(n, body)


@router.get("/tool-probes")
def list_tool_probes(tool_probes: ToolProbesDep) -> list[dict]:
    return tool_probes.list()


@router.get("/tool-probes/{n}")
def get_tool_probe(n: int, tool_probes: ToolProbesDep) -> dict:
    return tool_probes.get(n)


@router.put("/tool-probes/{n}")
def put_tool_probe(n: int, body: JsonObject, tool_probes: ToolProbesDep) -> dict:
    return tool_probes.put(n, body)


@router.get("/settings")
def get_settings(settings: SettingsDep) -> dict:
    return settings.get().model_dump()


@router.put("/settings")
def put_settings(body: JsonObject, settings: SettingsDep) -> dict:
    """Partial update: keys not given keep their value; the whole result is validated."""
    return settings.put(body).model_dump()


@router.get("/log")
def list_log(log: LogDep, limit: Annotated[int, Query(ge=1, le=1000)] = 100) -> list[dict]:
    """The measurement log, newest first."""
    return log.list(limit)


@router.get("/log/{log_id}")
def get_log(log_id: Annotated[int, Path(ge=1, le=2**63 - 1)], log: LogDep) -> dict:
    return log.get(log_id)

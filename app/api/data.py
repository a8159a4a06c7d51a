"""Stored data: zero offsets, tools, probes, tool probes, settings, log, audit trail."""

from __future__ import annotations

from typing import Annotated, Literal

from fastapi import APIRouter, Body, Path, Query, Request
from pydantic import BaseModel, ConfigDict, Field, StrictBool, StrictFloat

from app.access.deps import needs, require
from app.deps import (
    LogDep,
    MemoriesDep,
    OffsetsDep,
    ProbesDep,
    ServicesDep,
    SettingsDep,
    ToolProbesDep,
    ToolsDep,
)
from app.records import MAX_PROBE, MAX_TOOL
from app.services.memories import MAX_VALUE as MEMORY_MAX
from app.services.memories import WRITE_FUNCTION as MEMORY_WRITE
from app.services.undo import UNDO_FUNCTION, undo

router = APIRouter(tags=["data"])
JsonObject = Annotated[dict, Body()]
# the numbers a path names, as the services check them (the schema says so: issue 25 item 7)
ToolNumber = Annotated[int, Path(ge=1, le=MAX_TOOL, description=f"tool number T, 1..{MAX_TOOL}")]
OffsetName = Annotated[str, Path(min_length=1, max_length=32, description="G54.., G505.., BASIC_REF, BASIC_n")]
ProbeNumber = Annotated[int, Path(ge=1, le=MAX_PROBE, description=f"probe record number, 1..{MAX_PROBE}")]


@router.get("/offsets", name="api_offsets")
def list_offsets(offsets: OffsetsDep) -> dict:
    """{name: frame} in chain order."""
    return offsets.list()


@router.get("/offsets/{name}", name="api_offset_get")
def get_offset(name: OffsetName, offsets: OffsetsDep) -> dict:
    return offsets.get(name)


@router.put("/offsets/{name}", name="api_offset_put", dependencies=[needs("offsets")])
def put_offset(name: OffsetName, body: JsonObject, offsets: OffsetsDep) -> dict:
    """Merges the given components onto the stored frame; audited with source "api"."""
    return offsets.put(name, body, source="api")


@router.get("/audit", name="api_audit")
def audit(offsets: OffsetsDep, limit: Annotated[int, Query(ge=1, le=1000)] = 50,
          name: Annotated[str | None, Query(max_length=64)] = None,
          kind: Annotated[str | None, Query(max_length=64)] = None) -> list[dict]:
    """Changes of stored data, newest first: ``kind`` (offset, tool, probe, tool_probe, memory,
    settings, scenario, user, token, keyswitch), ``offset`` the item, ``who`` and ``level``: the user
    or token that wrote it and its access level."""
    return offsets.audit(limit, name, kind)


class UndoBody(BaseModel):
    model_config = ConfigDict(extra="forbid", json_schema_extra={"examples": [{}, {"force": True}]})
    force: StrictBool = Field(False, description="restore even though the item changed since")


@router.post("/audit/{audit_id}/undo", name="api_audit_undo", dependencies=[needs("view")])
def undo_change(request: Request, audit_id: Annotated[int, Path(ge=1, le=2**63 - 1)], services: ServicesDep,
                body: Annotated[UndoBody | None, Body()] = None) -> dict:
    """Restore the value before that change, as a new audited write (source "undo"). 409
    ``changed_since`` when the item changed after it (unless ``force``); needs the level of writing
    that kind of data (a zero offset: ``offsets``)."""
    entry = services.offsets.audit_entry(audit_id)
    require(request, UNDO_FUNCTION.get(entry["kind"], "settings"))
    return undo(services, entry, force=(body or UndoBody()).force)


@router.get("/tools", name="api_tools")
def list_tools(tools: ToolsDep) -> list[dict]:
    return tools.list()


@router.get("/tools/{t}", name="api_tool_get")
def get_tool(t: ToolNumber, tools: ToolsDep) -> dict:
    return tools.get(t)


@router.put("/tools/{t}", name="api_tool_put", dependencies=[needs("tools")])
def put_tool(t: ToolNumber, body: JsonObject, tools: ToolsDep) -> dict:
    """Creates or updates tool ``t`` (fields not given keep their value)."""
    return tools.put(t, body)


@router.delete("/tools/{t}", status_code=204, name="api_tool_delete", dependencies=[needs("tools")])
def delete_tool(t: ToolNumber, tools: ToolsDep) -> None:
    tools.delete(t)


@router.get("/probes", name="api_probes")
def list_probes(probes: ProbesDep) -> list[dict]:
    return probes.list()


@router.get("/probes/{n}", name="api_probe_get")
def get_probe(n: ProbeNumber, probes: ProbesDep) -> dict:
    return probes.get(n)


@router.put("/probes/{n}", name="api_probe_put", dependencies=[needs("probe_data")])
def put_probe(n: ProbeNumber, body: JsonObject, probes: ProbesDep) -> dict:
    return probes.put(n, body)


@router.get("/tool-probes", name="api_tool_probes")
def list_tool_probes(tool_probes: ToolProbesDep) -> list[dict]:
    return tool_probes.list()


@router.get("/tool-probes/{n}", name="api_tool_probe_get")
def get_tool_probe(n: ProbeNumber, tool_probes: ToolProbesDep) -> dict:
    return tool_probes.get(n)


@router.put("/tool-probes/{n}", name="api_tool_probe_put", dependencies=[needs("probe_data")])
def put_tool_probe(n: ProbeNumber, body: JsonObject, tool_probes: ToolProbesDep) -> dict:
    return tool_probes.put(n, body)


@router.get("/settings", name="api_settings_get")
def get_settings(settings: SettingsDep) -> dict:
    return settings.get().model_dump()


@router.put("/settings", name="api_settings_put", dependencies=[needs("settings")])
def put_settings(request: Request, body: JsonObject, settings: SettingsDep) -> dict:
    """Partial update: keys not given keep their value; the whole result is validated. Changing a
    ``level_*`` key (the access-level table) needs the ``users`` level."""
    if settings.changes_levels(body):
        require(request, "users")
    return settings.put(body, source="api").model_dump()


@router.get("/log", name="api_log")
def list_log(log: LogDep, limit: Annotated[int, Query(ge=1, le=1000)] = 100,
             offset: Annotated[int, Query(ge=0, le=2**62 - 1)] = 0) -> list[dict]:
    """The measurement log, newest first: ``limit`` entries after the newest ``offset``."""
    return log.list(limit, offset)


@router.get("/log/{log_id}", name="api_log_entry")
def get_log(log_id: Annotated[int, Path(ge=1, le=2**63 - 1)], log: LogDep) -> dict:
    return log.get(log_id)


MemoryKind = Annotated[Literal["ev", "mv"], Path(description="ev: empirical values _EV, mv: mean values _MV")]
MemoryNumber = Annotated[int, Path(ge=1, le=20, description="memory number n of _EVNUM (n = 10 is _EV[9])")]


class MemoryBody(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, json_schema_extra={"examples": [{"value": 0.004}]})
    # the range is the service's (app/services/memories.py, 422 naming "value"): stated in the schema
    value: StrictFloat = Field(json_schema_extra={"minimum": -MEMORY_MAX, "maximum": MEMORY_MAX},
                               description=f"mm, within ±{MEMORY_MAX:g}")


@router.get("/memories", name="api_memories")
def list_memories(memories: MemoriesDep) -> dict:
    """Every EV and MV memory (design.md §9.3)."""
    return memories.list()


@router.get("/memories/{kind}/{n}", name="api_memory_get")
def get_memory(kind: MemoryKind, n: MemoryNumber, memories: MemoriesDep) -> dict:
    return memories.get(kind, n)


@router.put("/memories/{kind}/{n}", name="api_memory_put", dependencies=[needs(MEMORY_WRITE)])
def put_memory(kind: MemoryKind, n: MemoryNumber, body: MemoryBody, memories: MemoriesDep) -> dict:
    """Writes the memory (audited)."""
    return memories.put(kind, n, body.value)

"""Jobs, parts with their characteristics and verdicts (design.md §10.3, docs/results.md)."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Body, Path, Query
from fastapi.responses import PlainTextResponse, Response

from app.access.deps import needs
from app.deps import NcDep, QualityDep, ResultsDep
from app.services.quality import DFQ_ENCODING

router = APIRouter(tags=["results"])
JsonObject = Annotated[dict, Body()]


@router.get("/job", name="api_job_get")
def get_job(results: ResultsDep) -> dict:
    """The job the next measurements belong to (``active`` false: none) and its open part."""
    return results.job()


@router.put("/job", name="api_job_put", dependencies=[needs("measure")])
def put_job(body: JsonObject, results: ResultsDep) -> dict:
    """``{"part_number", "order", "serial" (or "auto"), "operator", "program", "characteristics":
    {name: {"nominal", "lower", "upper"}}}``: a new job; its first part starts now."""
    return results.put_job(body)


@router.delete("/job", status_code=204, name="api_job_delete", dependencies=[needs("measure")])
def delete_job(results: ResultsDep) -> None:
    """Ends the job: measurements no longer belong to a part."""
    results.delete_job()


@router.post("/job/next-part", name="api_job_next_part", dependencies=[needs("measure")])
def next_part(results: ResultsDep, body: Annotated[dict | None, Body()] = None) -> dict:
    """The next part of the job (the next serial, or ``{"serial": ...}``)."""
    return results.next_part(body)


@router.get("/parts", name="api_parts")
def list_parts(results: ResultsDep, part_number: Annotated[str | None, Query(max_length=64)] = None,
               limit: Annotated[int, Query(ge=1, le=1000)] = 100,
               offset: Annotated[int, Query(ge=0, le=2**62)] = 0) -> list[dict]:
    """Parts, newest first, each with its characteristics and verdict (the worst of them)."""
    return results.parts(part_number, limit, offset)


@router.get("/parts/export.dfq", name="api_parts_dfq", response_class=Response,
            responses={200: {"content": {"text/plain": {}}, "description": "AQDEF (DFQ) text, Windows-1252"}})
def export_dfq(quality: QualityDep, part_number: Annotated[str, Query(
        min_length=1, max_length=64, description="the part number of the series")]) -> Response:
    """Q-DAS AQDEF (DFQ) of every part of ``part_number``: K1001/K1002 part, K1053 order,
    K2001/K2002 characteristic, K2101 nominal, K2110/K2111 limits, K2142 unit, K2022 decimals,
    per value K0001 value, K0004 date/time, K0006 serial, K0008 operator, K0012 gauge (the probe)."""
    text = quality.dfq(part_number)
    return Response(text.encode(DFQ_ENCODING, errors="replace"), media_type=f"text/plain; charset={DFQ_ENCODING}",
                    headers={"Content-Disposition": f'attachment; filename="{_file_name(part_number or "")}.dfq"'})


def _file_name(text: str) -> str:
    return "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in text) or "parts"


@router.get("/spc", name="api_spc")
def spc(quality: QualityDep,
        part_number: Annotated[str, Query(min_length=1, max_length=64, description="the part number of the series")],
        characteristic: Annotated[str, Query(min_length=1, max_length=80, description="the name of a characteristic")]
        ) -> dict:
    """One characteristic over the parts of ``part_number``: ``{"n", "values", "mean", "sigma",
    "ucl", "lcl", "cp", "cpk", ...}`` (individuals chart; docs/results.md) and the points of the
    run chart with the tool-offset compensations."""
    return quality.spc(part_number, characteristic)


@router.get("/parts/{part_id}", name="api_part")
def get_part(part_id: Annotated[int, Path(ge=1, le=2**63 - 1)], results: ResultsDep) -> dict:
    return results.part(part_id)


@router.get("/protocols", name="api_protocols")
def list_protocols(nc: NcDep) -> list[dict]:
    """The protocol files of CYCLE100…CYCLE106 (manual §7.1): ``{"name", "program", "updated",
    "size", "lines"}``."""
    return nc.protocol_files.list()


@router.get("/protocols/{name}", name="api_protocol", response_class=PlainTextResponse)
def get_protocol(name: Annotated[str, Path(max_length=40)], nc: NcDep, download: bool = False) -> PlainTextResponse:
    """The protocol file as text (``download=true``: as an attachment ``<name>.MPF``)."""
    headers = {"Content-Disposition": f'attachment; filename="{name}.MPF"'} if download else None
    return PlainTextResponse(nc.protocol_files.text(name), headers=headers)

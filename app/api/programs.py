"""Stored part programs (design.md §9.4): list, create, read, replace, delete."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Path, Response
from pydantic import BaseModel, ConfigDict, Field, StrictStr

from app.access.deps import needs
from app.deps import ProgramsDep
from app.services.nc import PROGRAM_NAME

ProgramName = Annotated[str, Path(pattern=PROGRAM_NAME.pattern, description="1..32 letters, digits or _, starting with a letter")]

router = APIRouter(prefix="/programs", tags=["programs"])


class ProgramBody(BaseModel):
    model_config = ConfigDict(extra="forbid", json_schema_extra={"examples": [
        {"name": "BORE1", "text": "N10 G54 G0 X0 Y0\nN20 _MVAR=101 _SETVAL=20 _KNUM=1\nN30 CYCLE977\nN40 M30"}]})
    name: StrictStr = Field(description="letters, digits and _, starting with a letter (1..32)",
                            json_schema_extra={"pattern": PROGRAM_NAME.pattern})
    text: StrictStr = Field(description="the program text, at most 1 MiB (413 above)")


class TextBody(BaseModel):
    model_config = ConfigDict(extra="forbid")
    text: StrictStr = Field(description="the program text, at most 1 MiB (413 above)")


@router.get("", name="api_programs")
def list_programs(programs: ProgramsDep) -> list[dict]:
    """Name, size, lines, created/updated times (no texts)."""
    return programs.list()


@router.post("", status_code=201, name="api_program_create", dependencies=[needs("measure")])
def create_program(body: ProgramBody, programs: ProgramsDep) -> dict:
    """A new program (409 if the name exists); ``syntax`` is null or the first error (line, column)."""
    return programs.create(body.name, body.text)


@router.get("/{name}", name="api_program_get")
def get_program(name: ProgramName, programs: ProgramsDep) -> dict:
    return programs.get(name)


@router.put("/{name}", name="api_program_put", dependencies=[needs("measure")],
            responses={201: {"description": "created: the program did not exist"}})
def put_program(name: ProgramName, body: TextBody, programs: ProgramsDep, response: Response) -> dict:
    """Replace (or create: 201) the program's text; refused while it runs in the channel."""
    program, created = programs.put(name, body.text)
    if created:
        response.status_code = 201
    return program


@router.delete("/{name}", status_code=204, name="api_program_delete", dependencies=[needs("measure")])
def delete_program(name: ProgramName, programs: ProgramsDep) -> None:
    programs.delete(name)

"""Cycle support of the program editor (design.md §10.2): the forms, the text a form writes into
the program, and the form's values read back from a program text (round trip exact)."""

from __future__ import annotations

from typing import Any

from fastapi import APIRouter
from pydantic import BaseModel, ConfigDict, Field, StrictStr

from app.access.deps import needs
from app.deps import MachineDep
from app.errors import InvalidInput
from app.i18n import gettext
from app.nc import cycle_forms

router = APIRouter(prefix="/cycles", tags=["programs"])


class RenderBody(BaseModel):
    model_config = ConfigDict(extra="forbid", json_schema_extra={"examples": [
        {"cycle": "CYCLE977", "params": {"_MVAR": 101, "_SETVAL": 20.0, "_KNUM": 1}}]})
    cycle: StrictStr = Field(description="CYCLE976, CYCLE977, CYCLE978, CYCLE979, CYCLE998, CYCLE961, CYCLE997, CYCLE971; "
                                         "on a lathe CYCLE982, CYCLE973, CYCLE974, CYCLE994")
    params: dict[str, Any] = Field(description="the manual's parameter names with their values")


class ReadBody(BaseModel):
    model_config = ConfigDict(extra="forbid")
    text: StrictStr = Field(description="program text holding a cycle call (the last one is read)")


def _refused(exc: cycle_forms.CycleFormError) -> InvalidInput:
    return InvalidInput(exc.message, field=exc.field)


@router.get("", name="api_cycles")
def list_cycles(machine: MachineDep) -> dict:
    """Every measuring cycle the editor offers on this machine (a lathe: the lathe's), with its
    form (the manual's parameter names)."""
    return {"cycles": [{"cycle": name, "fields": [f.to_api(gettext) for f in fields]}
                       for name, fields in cycle_forms.cycles_for(machine.is_lathe).items()]}


@router.post("/render", name="api_cycles_render", dependencies=[needs("measure")])
def render_cycle(body: RenderBody, machine: MachineDep) -> dict:
    """The parameter assignments and the call, as the editor inserts them at the cursor."""
    try:
        return {"text": cycle_forms.render(body.cycle, body.params, machine.is_lathe)}
    except cycle_forms.CycleFormError as exc:
        raise _refused(exc) from None


@router.post("/read", name="api_cycles_read", dependencies=[needs("measure")])
def read_cycle(body: ReadBody, machine: MachineDep) -> dict:
    """The cycle a text calls and its parameters' values (what opening the call shows in the form)."""
    try:
        cycle, params = cycle_forms.read(body.text, machine.is_lathe)
    except cycle_forms.CycleFormError as exc:
        raise _refused(exc) from None
    return {"cycle": cycle, "params": params}

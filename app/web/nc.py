"""The MDA / AUTOMATIC screen and the program manager (design.md §9.4).

MDA: an editor with line numbers, NC Start (the MCP key or the button: the form is the screen's
``data-ncstart`` element), single block, NC Stop, Reset; the loaded program as a listing with
the current block highlighted and an alarm shown at its line and column; the cycle results
(``_OVR``/``_OVI``). The channel part is an htmx partial that polls while the program runs.
With a program selected for AUTOMATIC the same screen shows that program (read-only: it is
edited in the program manager).
"""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Form, Request

from app.access.deps import needs
from app.api.nc import authorizer
from app.deps import NcDep, ProgramsDep
from app.errors import HmiError
from app.i18n import _
from app.nc import cycle_forms
from app.services.nc import MDA, NcSyntaxInput

from . import nc_results
from .templating import render_block, render_screen, url_path

router = APIRouter()


def _listing(text: str, status: dict) -> list[dict]:
    """The loaded program's lines: number, text, current, alarm (message and column)."""
    block = status.get("block") or {}
    alarm = status.get("alarm") or {}
    current = block.get("line") if status.get("state") not in ("idle",) else None
    rows = []
    for n, line in enumerate(text.splitlines() or [""], start=1):
        row = {"n": n, "text": line, "current": n == current, "alarm": None}
        if alarm and alarm.get("line") == n:
            row["alarm"] = {"message": alarm.get("message") or alarm.get("text"), "column": alarm.get("column"),
                            "code": alarm.get("code")}
        rows.append(row)
    return rows


def _results(nc) -> tuple[list[dict], str]:
    """The non-zero _OVR/_OVI elements of the last cycle of this run, each with its meaning
    (app/web/nc_results.py), and the cycle's name. A new run starts without results
    (app/services/nc.py clears them when it loads a program)."""
    values = nc.read_variables(["_OVR", "_OVI"])
    return nc_results.results(values), nc_results.cycle_name(values)


def has_blocks(text: str) -> bool:
    """Whether ``text`` holds anything to run: a line with more than blanks or a comment (;)."""
    return any(line.split(";", 1)[0].strip() for line in (text or "").splitlines())


def channel_context(nc, error: dict | None = None, text: str | None = None) -> dict:
    status = nc.status()
    if error is not None and text is not None:
        loaded = text                       # the typed text with its error, not the program in the channel
    else:
        loaded = nc.loaded_text if status["program"] else (text if text is not None else nc.mda_text)
    shown = {**status, "alarm": error, "block": None} if error else status
    rows = _listing(loaded, shown)
    if error:
        status = {**status, "alarm": error}
    results, cycle = _results(nc)
    return {"nc": status, "rows": rows, "results": results, "results_cycle": cycle, "syntax_error": error,
            "auto": status["program"] not in (None, MDA)}


def _screen(request: Request, nc, error: dict | None = None, text: str | None = None, status_code: int = 200):
    ctx = channel_context(nc, error, text)
    editor = text if text is not None else nc.mda_text
    return render_screen(request, "mda.html", {"screen": "mda", "editor": editor,
                                               "lines": max(1, len(editor.splitlines()) + 1), **ctx},
                         status_code=status_code)


def _channel(request: Request, nc, error: dict | None = None, text: str | None = None, message: str = "",
             level: str = "info"):
    ctx = channel_context(nc, error, text)
    return render_block(request, "mda.html", "channel", {**ctx, "message": message, "level": level})


@router.get("/mda", name="mda_screen")
def mda_screen(request: Request, nc: NcDep):
    return _screen(request, nc)


@router.get("/mda/channel", name="mda_channel")
def mda_channel(request: Request, nc: NcDep):
    return _channel(request, nc)


@router.post("/mda/start", name="mda_start", dependencies=[needs("measure")])
def mda_start(request: Request, nc: NcDep, text: Annotated[str, Form()] = "",
              single_block: Annotated[str | None, Form()] = None):
    """NC Start: the MDA text (loaded anew when it changed or the run has ended) or the program
    selected for AUTOMATIC; single block as the toggle says."""
    single = single_block is not None
    status = nc.status()
    auto = status["program"] not in (None, MDA)
    if not has_blocks(nc.loaded_text if auto else text):      # nothing would run: say so, change nothing
        return _channel(request, nc, text=None if auto else text,
                        message=_("The program is empty: nothing to run."), level="info")
    try:
        if status["program"] not in (None, MDA):
            nc.start(wait=False, single_block=single, authorize=authorizer(request))
        elif status["program"] == MDA and text == nc.mda_text and status["state"] in ("stopped", "ready"):
            nc.start(wait=False, single_block=single, authorize=authorizer(request))
        else:
            nc.run(mda=text, wait=False, single_block=single, authorize=authorizer(request))
    except NcSyntaxInput as exc:
        nc.mda_text = text
        return _channel(request, nc, error=exc.detail, text=text)
    except HmiError as exc:
        return _channel(request, nc, text=text, message=exc.message, level="error")
    return _channel(request, nc)


@router.post("/mda/stop", name="mda_stop", dependencies=[needs("jog")])
def mda_stop(request: Request, nc: NcDep):
    nc.stop()
    return _channel(request, nc)


@router.post("/mda/reset", name="mda_reset", dependencies=[needs("jog")])
def mda_reset(request: Request, nc: NcDep):
    try:
        nc.reset()
    except HmiError as exc:
        return _channel(request, nc, message=exc.message, level="error")
    return _channel(request, nc)


@router.post("/mda/single-block", name="mda_single_block", dependencies=[needs("measure")])
def mda_single_block(request: Request, nc: NcDep, single_block: Annotated[str | None, Form()] = None):
    nc.set_single_block(single_block is not None)
    return _channel(request, nc)


# --- the program manager -----------------------------------------------------------------------------

def _lathe(request: Request) -> bool:
    return bool(request.app.state.services.machine.is_lathe)


def _programs(request: Request, programs, nc, extra: dict | None = None, status_code: int = 200):
    cycle_names = list(cycle_forms.cycles_for(_lathe(request)))
    return render_screen(request, "programs.html", {"screen": "programs", "programs": programs.list(),
                                                    "selected": nc.status()["program"], "cycle_names": cycle_names,
                                                    "cycle": None, "cycle_fields": None, "cycle_values": {}, "cursor": None,
                                                    **(extra or {})},
                         status_code=status_code)


def _line_bounds(text: str, cursor: int) -> tuple[int, int]:
    """Start and end of the line the cursor stands in."""
    cursor = max(0, min(cursor, len(text)))
    start = text.rfind("\n", 0, cursor) + 1
    end = text.find("\n", cursor)
    return start, (len(text) if end < 0 else end)


def _typed(field: cycle_forms.CycleField, typed: str) -> int | float:
    value = float(typed.replace(",", "."))
    return int(value) if field.kind == "int" and value == int(value) else value


@router.post("/programs/{name}/cycle", name="programs_cycle", dependencies=[needs("measure")])
async def programs_cycle(request: Request, name: str, programs: ProgramsDep, nc: NcDep):
    """Cycle support (design.md §10.2, manual §7.2–7.3): ``action`` "form" shows the cycle's input
    screen, "insert" writes the call with its parameters at the start of the cursor's line,
    "read" fills the screen from the last call up to the cursor's line. Nothing is saved."""
    form = await request.form()
    text, action = str(form.get("text", "")), str(form.get("action", "form"))
    lathe = _lathe(request)
    offered = cycle_forms.cycles_for(lathe)
    cycle = str(form.get("cycle", next(iter(offered))))
    try:
        cursor = int(str(form.get("cursor", len(text))) or len(text))
    except ValueError:
        cursor = len(text)
    start, end = _line_bounds(text, cursor)
    editing = {"name": name, "text": text, "syntax": None}
    values: dict = {}
    error = None
    try:
        fields = cycle_forms.fields_of(cycle, lathe)
        if action == "read":
            cycle, values = cycle_forms.read(text[:end], lathe)
            fields = cycle_forms.fields_of(cycle, lathe)
        elif action == "insert":
            typed = {k[2:]: str(v).strip() for k, v in form.items() if k.startswith("p:") and str(v).strip()}
            try:
                values = {k: _typed(fields[k], v) for k, v in typed.items() if k in fields}
            except ValueError:
                values = typed
                raise cycle_forms.CycleFormError("params", _("Enter numbers in the cycle's fields")) from None
            block = cycle_forms.render(cycle, values, lathe) + "\n"
            editing["text"] = text[:start] + block + text[start:]
            cursor = start + len(block)
    except cycle_forms.CycleFormError as exc:
        error = exc.translated(_)
    return _programs(request, programs, nc, {"editing": editing, "cycle": cycle, "cursor": cursor,
                                             "cycle_fields": [f.to_api(_) for f in offered[cycle]]
                                             if cycle in offered else None,
                                             "cycle_values": values, "cycle_error": error})


@router.get("/programs", name="programs_screen")
def programs_screen(request: Request, programs: ProgramsDep, nc: NcDep):
    return _programs(request, programs, nc)


@router.post("/programs/new", name="programs_new", dependencies=[needs("measure")])
def programs_new(request: Request, programs: ProgramsDep, nc: NcDep, name: Annotated[str, Form()] = ""):
    try:
        program = programs.create(name.strip(), "")
    except HmiError as exc:
        return _programs(request, programs, nc, {"new_error": exc.message, "new_text": name})
    return _programs(request, programs, nc, {"editing": program})


@router.get("/programs/{name}/edit", name="programs_edit")
def programs_edit(request: Request, name: str, programs: ProgramsDep, nc: NcDep):
    try:
        program = programs.get(name)
    except HmiError as exc:
        return _programs(request, programs, nc, {"message": exc.message})
    return _programs(request, programs, nc, {"editing": program})


@router.post("/programs/{name}/save", name="programs_save", dependencies=[needs("measure")])
def programs_save(request: Request, name: str, programs: ProgramsDep, nc: NcDep, text: Annotated[str, Form()] = ""):
    try:
        program, _ = programs.put(name, text)
    except HmiError as exc:
        return _programs(request, programs, nc, {"editing": {"name": name, "text": text, "syntax": None},
                                                 "message": exc.message})
    return _programs(request, programs, nc, {"editing": program, "saved": True})


@router.post("/programs/{name}/delete", name="programs_delete", dependencies=[needs("measure")])
def programs_delete(request: Request, name: str, programs: ProgramsDep, nc: NcDep):
    try:
        programs.delete(name)
    except HmiError as exc:
        return _programs(request, programs, nc, {"message": exc.message})
    return _programs(request, programs, nc, {"message": f"Program {name} deleted"})


@router.post("/programs/{name}/select", name="programs_select", dependencies=[needs("measure")])
def programs_select(request: Request, name: str, programs: ProgramsDep, nc: NcDep):
    """Select for AUTOMATIC: the program is loaded into the channel; the screen changes to it."""
    try:
        nc.select(name)
    except NcSyntaxInput as exc:
        return _programs(request, programs, nc, {"editing": programs.get(name), "message": exc.message})
    except HmiError as exc:
        return _programs(request, programs, nc, {"message": exc.message})
    response = _screen(request, nc)
    response.headers["HX-Push-Url"] = url_path(request, "mda_screen")
    return response

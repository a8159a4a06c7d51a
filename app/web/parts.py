"""Parts screens (design.md §10.3, docs/results.md): the job form and the parts with their
verdicts, the printable per-part protocol, and the run chart of a characteristic (server-drawn
SVG)."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Form, Path, Query, Request

from app.access.deps import needs
from app.deps import NcDep, ProbesDep, QualityDep, ResultsDep
from app.errors import HmiError
from app.i18n import _

from .templating import render_screen, templates

router = APIRouter()
JOB_FIELDS = ("part_number", "order", "serial", "operator", "program")
VIOLATION_MARK = "#"            # _PROTSYM[1]'s default (manual §7.1.4): a tolerance violation


def _screen(request: Request, results, nc, extra: dict | None = None):
    job = results.job()
    context = {"screen": "log", "job": job, "parts": results.parts(limit=50), "errors": {}, "texts": {},
               "protocols": nc.protocol_files.list(), **(extra or {})}
    return render_screen(request, "parts.html", context)


@router.get("/parts", name="parts_screen")
def parts_screen(request: Request, results: ResultsDep, nc: NcDep):
    return _screen(request, results, nc)


@router.post("/parts/job", name="parts_job", dependencies=[needs("measure")])
def set_job(request: Request, results: ResultsDep, nc: NcDep, part_number: Annotated[str, Form()] = "",
            order: Annotated[str, Form()] = "", serial: Annotated[str, Form()] = "",
            operator: Annotated[str, Form()] = "", program: Annotated[str, Form()] = ""):
    texts = {"part_number": part_number, "order": order, "serial": serial, "operator": operator, "program": program}
    try:
        results.put_job({k: v.strip() for k, v in texts.items() if v.strip()})
    except HmiError as exc:
        return _screen(request, results, nc, {"errors": {exc.field or "part_number": exc.message}, "texts": texts,
                                              "message": exc.message, "level": "error"})
    return _screen(request, results, nc, {"message": _("The next measurements belong to this part.")})


@router.post("/parts/next", name="parts_next_part", dependencies=[needs("measure")])
def next_part(request: Request, results: ResultsDep, nc: NcDep):
    try:
        job = results.next_part()
    except HmiError as exc:
        return _screen(request, results, nc, {"message": exc.message, "level": "error"})
    return _screen(request, results, nc, {"message": _("Next part: serial %(serial)s") % {"serial": job["serial"]}})


@router.post("/parts/end", name="parts_end_job", dependencies=[needs("measure")])
def end_job(request: Request, results: ResultsDep, nc: NcDep):
    results.delete_job()
    return _screen(request, results, nc, {"message": _("Job ended: measurements belong to no part.")})


@router.get("/parts/{part_id}/protocol", name="part_protocol")
def part_protocol(request: Request, part_id: Annotated[int, Path(ge=1, le=2**63 - 1)], results: ResultsDep,
                  probes: ProbesDep):
    """The per-part protocol, a page of its own for the browser's print (A4, static/protocol.css)."""
    part = results.part(part_id)
    probe = results.probe_of(part)
    record = None
    if probe is not None:
        try:
            record = probes.get(probe)
        except HmiError:
            record = None
    rows = [{**c, "mark": VIOLATION_MARK if c["verdict"] in ("rework", "scrap") else ""}
            for c in part["characteristics"]]
    return templates.TemplateResponse(request, "part_protocol.html", {
        "part": part, "rows": rows, "probe": probe, "record": record, "mark": VIOLATION_MARK})


@router.get("/spc", name="spc_screen")
def spc_screen(request: Request, quality: QualityDep, results: ResultsDep,
               part_number: Annotated[str | None, Query(max_length=64)] = None,
               characteristic: Annotated[str | None, Query(max_length=80)] = None):
    """The run chart of one characteristic over the parts of a part number."""
    names = quality.characteristic_names(part_number) if part_number else []
    chart = error = None
    if part_number and names:
        try:
            chart = quality.spc(part_number, characteristic or names[0])
        except HmiError as exc:
            error = exc.message
    return render_screen(request, "spc.html", {"screen": "log", "part_number": part_number, "names": names,
                                               "chart": chart, "svg": run_chart(chart) if chart else None,
                                               "error": error})


# --- the run chart, drawn on the server ------------------------------------------------------------

WIDTH, HEIGHT, LEFT, RIGHT, TOP, BOTTOM = 720, 230, 70, 20, 12, 30


def run_chart(chart: dict) -> dict:
    """Coordinates of the run chart: the values in measuring order, the nominal, the limits, the
    control limits (x̄ ± 3 σ), the values after which the tool was compensated marked."""
    points = chart["points"]
    values = [p["value"] for p in points if p["value"] is not None]
    levels = [v for v in (chart["nominal"], chart["lower"], chart["upper"], chart["ucl"], chart["lcl"], chart["mean"])
              if v is not None]
    low, high = min(values + levels), max(values + levels)
    pad = (high - low) * 0.08 or 0.01
    low, high = low - pad, high + pad
    n = max(len(points), 2)

    def x(i: int) -> float:
        return round(LEFT + (WIDTH - LEFT - RIGHT) * i / (n - 1), 1)

    def y(v: float) -> float:
        return round(TOP + (HEIGHT - TOP - BOTTOM) * (high - v) / (high - low), 1)

    dots = [{"x": x(i), "y": y(p["value"]), "value": p["value"], "serial": p["serial"], "verdict": p["verdict"],
             "compensated": p["compensation"] is not None} for i, p in enumerate(points) if p["value"] is not None]
    lines = [{"kind": kind, "y": y(v), "value": v} for kind, v in
             (("nominal", chart["nominal"]), ("lower", chart["lower"]), ("upper", chart["upper"]),
              ("ucl", chart["ucl"]), ("lcl", chart["lcl"]), ("mean", chart["mean"])) if v is not None]
    return {"width": WIDTH, "height": HEIGHT, "left": LEFT, "right": WIDTH - RIGHT, "top": TOP,
            "bottom": HEIGHT - BOTTOM, "dots": dots, "lines": lines,
            "path": " ".join(f"{d['x']},{d['y']}" for d in dots)}

"""Measurement log screen: table, detail view, export as CSV and JSON."""

from __future__ import annotations

import csv
import io
import json
from datetime import UTC, datetime
from typing import Annotated, Literal
from zoneinfo import ZoneInfo, ZoneInfoNotFoundError

from fastapi import APIRouter, Query, Request
from fastapi.responses import StreamingResponse

from app.deps import LogDep
from app.errors import InvalidInput

from .task_screens import correction_rows
from .templating import fmt_result, render_screen

router = APIRouter()
MAIN_KEYS = ("position", "corner", "center", "distance", "diameter", "length", "width", "radius", "angle",
             "alpha", "beta", "p1")


def main_result(result: dict | None) -> str:
    """The result in one line: the task's main keys (design.md §4), or the alarm of a failed attempt."""
    alarm = (result or {}).get("alarm")
    if isinstance(alarm, dict) and alarm.get("code"):
        point = f" at P{alarm['point']}" if alarm.get("point") else ""
        return f"alarm {alarm['code']} {alarm.get('text', '')}{point}: nothing written"
    parts = []
    for key in MAIN_KEYS:
        value = (result or {}).get(key)
        if isinstance(value, dict):
            parts.append(f"{key} " + " ".join(f"{a}={fmt_result(key, v)}" for a, v in value.items()
                                              if isinstance(v, int | float)))
        elif isinstance(value, int | float) and not isinstance(value, bool):
            parts.append(f"{key}={fmt_result(key, value)}")
    if not parts and isinstance((result or {}).get("probe"), dict):
        parts.append("probe data")
    return "; ".join(parts)


def correction_text(correction: dict | None) -> str:
    """Changed components of the target WO: 'G54: trans.X 10.000→12.345'."""
    if not correction or not correction.get("after"):
        return "measure only" if correction and correction.get("target") == "measure_only" else ""
    changes = [f"{row['field']} {row['before']}→{row['after']}" for row in correction_rows(correction)
               if row["changed"]]
    return f"{correction.get('target')}: " + (", ".join(changes) if changes else "unchanged")


def _row(entry: dict) -> dict:
    return {"id": entry["id"], "time": str(entry.get("time", ""))[:19].replace("T", " "), "task": entry["task"],
            "target": entry.get("target") or "", "status": entry.get("status") or "",
            "result": main_result(entry.get("result")), "correction": correction_text(entry.get("correction"))}


PAGE = 100
LIST_FIELDS = ("task", "target", "status", "result", "correction")    # the overview reads no raw latches


@router.get("/log", name="log_screen")
def log_screen(request: Request, log: LogDep, page: Annotated[int, Query(ge=1, le=10**9)] = 1):
    """The newest PAGE entries of page ``page`` (newest first); the table pages, it never loads all."""
    total = log.count()
    pages = max(1, -(-total // PAGE))
    page = min(page, pages)
    rows = [_row(e) for e in log.list(PAGE, (page - 1) * PAGE, fields=LIST_FIELDS)]
    return render_screen(request, "log.html", {"screen": "log", "rows": rows, "entry": None, "total": total,
                                               "page": page, "pages": pages})


# the first nine as before (extended, never renamed), then every other log field
CSV_COLUMNS = ("id", "time", "task", "target", "status", "result", "correction", "result_json",
               "correction_json", "local_time", "measuring_wo", "warnings", "program", "block", "probe",
               "params_json", "raw_json", "points_json", "probe_json", "part_id", "calibration_id")


def _local_zone(tz: str | None):
    """The zone of the local time column: ``tz`` (IANA name) or the computer's own zone."""
    if not tz:
        return None
    try:
        return ZoneInfo(tz)
    except (ZoneInfoNotFoundError, ValueError):
        raise InvalidInput(f"tz: {tz!r} is not a time zone (e.g. Europe/Berlin, Asia/Shanghai)", field="tz") from None


def _local_time(utc_text: str | None, zone) -> str:
    """ISO 8601 with the offset, e.g. 2026-12-02T09:15:03+01:00 (the stored time is UTC)."""
    if not utc_text:
        return ""
    moment = datetime.fromisoformat(str(utc_text))
    if moment.tzinfo is None:
        moment = moment.replace(tzinfo=UTC)
    return moment.astimezone(zone).isoformat(timespec="seconds")


def _csv_row(entry: dict, zone) -> list:
    row = _row(entry)
    probe = entry.get("probe")
    if not isinstance(probe, dict):
        probe = {}
    warnings = entry.get("warnings") or []
    as_json = {k: json.dumps(entry.get(k), ensure_ascii=False) for k in ("params", "raw", "points", "result",
                                                                       "correction", "probe")}
    return [row["id"], entry.get("time"), row["task"], row["target"], row["status"], row["result"],
            row["correction"], as_json["result"], as_json["correction"],
            _local_time(entry.get("time"), zone), entry.get("measuring_wo") or "",
            " | ".join(str(w.get("text", w)) if isinstance(w, dict) else str(w) for w in warnings),
            entry.get("program") or "", entry.get("block") or "",
            f"probe {probe.get('number')}" if probe.get("number") is not None else "",
            as_json["params"], as_json["raw"], as_json["points"], as_json["probe"],
            entry.get("part_id") if entry.get("part_id") is not None else "",
            entry.get("calibration_id") if entry.get("calibration_id") is not None else ""]


@router.get("/log/export.csv", name="log_export_csv")
def export_csv(log: LogDep, bom: Annotated[bool, Query()] = False,
               delimiter: Annotated[Literal[",", ";"], Query()] = ",",
               tz: Annotated[str | None, Query(max_length=64)] = None):
    """Every entry with every log field, streamed page by page (design.md §9.1). ``bom``: a UTF-8
    byte-order mark first (Excel then reads the Chinese and German texts right); ``delimiter``
    ";" for spreadsheets with a decimal comma; ``tz``: the zone of ``local_time`` (default: this
    computer's)."""
    zone = _local_zone(tz)

    def lines():
        out = io.StringIO()
        if bom:
            out.write("\ufeff")
        writer = csv.writer(out, delimiter=delimiter)
        writer.writerow(CSV_COLUMNS)
        for entry in log.iterate():
            writer.writerow(_csv_row(entry, zone))
            if out.tell() > 64_000:
                yield out.getvalue()
                out.seek(0)
                out.truncate()
        yield out.getvalue()

    return StreamingResponse(lines(), media_type="text/csv; charset=utf-8",
                             headers={"Content-Disposition": 'attachment; filename="measurement-log.csv"'})


@router.get("/log/export.json", name="log_export_json")
def export_json(log: LogDep):
    """Every entry as one JSON array, streamed page by page."""
    def chunks():
        yield "["
        for i, entry in enumerate(log.iterate()):
            yield ("," if i else "") + "\n" + json.dumps(entry)
        yield "\n]\n"

    return StreamingResponse(chunks(), media_type="application/json",
                             headers={"Content-Disposition": 'attachment; filename="measurement-log.json"'})


@router.get("/log/{log_id}", name="log_detail")
def log_detail(request: Request, log_id: int, log: LogDep):
    entry = log.get(log_id)
    return render_screen(request, "log.html", {
        "screen": "log", "rows": None, "entry": entry, "row": _row(entry),
        "detail_json": json.dumps({k: entry.get(k) for k in ("params", "result", "correction", "points", "probe")},
                                  indent=1)})

"""Measurement log screen: table, detail view, export as CSV and JSON."""

from __future__ import annotations

import csv
import io
import json

from fastapi import APIRouter, Request
from fastapi.responses import Response

from app.deps import LogDep

from .task_screens import correction_rows
from .templating import fmt_result, render_screen

router = APIRouter()
LIMIT = 500
MAIN_KEYS = ("position", "corner", "center", "distance", "diameter", "length", "width", "radius", "angle",
             "alpha", "beta", "p1")


def main_result(result: dict | None) -> str:
    """The result in one line: the task's main keys (design.md §4)."""
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


@router.get("/log")
def log_screen(request: Request, log: LogDep):
    rows = [_row(e) for e in log.list(LIMIT)]
    return render_screen(request, "log.html", {"screen": "log", "rows": rows, "entry": None})


@router.get("/log/export.csv")
def export_csv(log: LogDep):
    out = io.StringIO()
    writer = csv.writer(out)
    writer.writerow(["id", "time", "task", "target", "status", "result", "correction",
                     "result_json", "correction_json"])
    for entry in log.list(LIMIT):
        row = _row(entry)
        writer.writerow([row["id"], entry.get("time"), row["task"], row["target"], row["status"], row["result"],
                         row["correction"], json.dumps(entry.get("result")), json.dumps(entry.get("correction"))])
    return Response(out.getvalue(), media_type="text/csv; charset=utf-8",
                    headers={"Content-Disposition": 'attachment; filename="measurement-log.csv"'})


@router.get("/log/export.json")
def export_json(log: LogDep):
    return Response(json.dumps(log.list(LIMIT), indent=1), media_type="application/json",
                    headers={"Content-Disposition": 'attachment; filename="measurement-log.json"'})


@router.get("/log/{log_id}")
def log_detail(request: Request, log_id: int, log: LogDep):
    entry = log.get(log_id)
    return render_screen(request, "log.html", {
        "screen": "log", "rows": None, "entry": entry, "row": _row(entry),
        "detail_json": json.dumps({k: entry.get(k) for k in ("params", "result", "correction", "points", "probe")},
                                  indent=1)})

"""The plant view (design.md §10.5): the machines on the shared database with their state, one
machine's parts and measurements, a characteristic across machines. Each HMI reports its own state
(alarms, mode, program state) into its ``machines`` row when it starts, every HEARTBEAT_S and when
the plant view is asked for; the other machines' state is what they last reported."""

from __future__ import annotations

import contextvars
import logging
import threading
from collections.abc import Callable
from datetime import UTC, datetime
from typing import Any

from db import Database, StorageUnavailable
from engine.verdict import worst

HEARTBEAT_S = 10.0
OFFLINE_AFTER_S = 3 * HEARTBEAT_S      # not seen for longer: shown as offline
log = logging.getLogger(__name__)


def _age_hours(iso: str | None, now: datetime) -> float | None:
    if not iso:
        return None
    try:
        moment = datetime.fromisoformat(iso)
    except ValueError:
        return None
    if moment.tzinfo is None:
        moment = moment.replace(tzinfo=UTC)
    return round((now - moment).total_seconds() / 3600.0, 2)


class PlantService:
    def __init__(self, db: Database, machine_status: Callable[[], dict[str, Any]]):
        self._db = db
        self._machine_status = machine_status
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    @property
    def machine_name(self) -> str:
        return self._db.machine

    # --- this HMI's report -------------------------------------------------------------------

    def report(self) -> None:
        """This machine's state into its row (alarms, mode, program state, active offset)."""
        status = self._machine_status()
        self._db.report_status({"alarms": [{"code": a["code"], "text": a["text"]} for a in status.get("alarms", [])],
                                "mode": status.get("mode"), "program_state": status.get("program_state"),
                                "active_offset": status.get("active_offset"), "busy": status.get("busy")})

    def start(self) -> None:
        """Reports now and then every HEARTBEAT_S until ``stop()``."""
        self.report()
        context = contextvars.copy_context()
        self._thread = threading.Thread(target=context.run, args=(self._beat,), name="plant-heartbeat", daemon=True)
        self._thread.start()

    def _beat(self) -> None:
        while not self._stop.wait(HEARTBEAT_S):
            try:
                self.report()
            except StorageUnavailable as exc:     # the database is away: the next beat tries again
                log.warning("plant heartbeat: %s", exc)

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=5)

    # --- the plant -----------------------------------------------------------------------------

    def overview(self) -> dict[str, Any]:
        """``GET /api/plant``: every machine on the database, this one's state fresh."""
        self.report()
        now = datetime.now(UTC)
        with self._db.unit(readonly=True) as unit:
            machines = unit.plant_machines()
        return {"machine": self.machine_name, "time": now.isoformat(timespec="seconds"),
                "machines": [self._entry(m, now) for m in machines]}

    def _entry(self, row: dict[str, Any], now: datetime) -> dict[str, Any]:
        status = row["status"]
        seen = _age_hours(row["last_seen"], now)
        return {
            "name": row["name"], "last_seen": row["last_seen"],
            "online": seen is not None and seen * 3600.0 <= OFFLINE_AFTER_S,
            "this": row["name"] == self.machine_name,
            "active_offset": status.get("active_offset") or row["active_offset"],
            "mode": status.get("mode"), "program_state": status.get("program_state"),
            "last_measurement": row["last_measurement"],
            "alarms": status.get("alarms", []),
            "calibrated_at": row["calibrated_at"],
            "calibration_age_h": _age_hours(row["calibrated_at"], now),
            "parts": row["parts"],
            "links": {"screen": f"/plant/{row['name']}", "api": f"/api/plant/{row['name']}"},
        }

    def machine(self, name: str) -> dict[str, Any]:
        """``GET /api/plant/{name}``: the machine's state, newest parts (with verdicts) and
        measurements; KeyError for a machine not on the database."""
        overview = self.overview()
        entry = next((m for m in overview["machines"] if m["name"] == name), None)
        if entry is None:
            raise KeyError(name)
        with self._db.unit(readonly=True) as unit:
            parts = unit.machine_parts(name)
            measurements = unit.machine_log(name)
        for part in parts:
            part["verdict"] = worst(c["verdict"] for c in part["characteristics"])
        return {**entry, "parts_list": parts, "measurements": measurements}

    def series(self, part_number: str, characteristic: str) -> dict[str, Any]:
        """A characteristic's values on every machine (the plant's SPC input), by machine."""
        with self._db.unit(readonly=True) as unit:
            rows = unit.plant_series(part_number, characteristic)
        by_machine: dict[str, list[dict[str, Any]]] = {}
        for row in rows:
            by_machine.setdefault(row.pop("machine"), []).append(row)
        return {"part_number": part_number, "characteristic": characteristic, "machines": by_machine}

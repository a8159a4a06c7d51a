"""The events of a probe record (design.md §10.4): calibrations (the row id is the calibration
id), repeatability checks and what invalidated a calibration. A mixin of ``db.repository.Unit``."""

from __future__ import annotations

import json
from datetime import UTC, datetime
from typing import Any

from sqlalchemy import select
from sqlalchemy.orm import Session

from db.models import ProbeEvent

PROBES = ("workpiece", "tool")
EVENTS = ("calibration", "repeatability", "invalidated")


def _event_dict(row: ProbeEvent) -> dict[str, Any]:
    return {"id": row.id, "probe": row.probe, "number": row.number, "time": row.time, "event": row.event,
            "calibration_id": row.calibration_id, "data": row.data}


class ProbeEventsUnit:
    _session: Session
    machine: str

    def add_probe_event(self, probe: str, number: int, event: str, data: dict[str, Any] | None = None,
                        calibration_id: int | None = None, time: str | None = None) -> dict[str, Any]:
        if probe not in PROBES:
            raise ValueError(f"probe must be one of {PROBES}, got {probe!r}")
        if event not in EVENTS:
            raise ValueError(f"event must be one of {EVENTS}, got {event!r}")
        stored = None if data is None else json.loads(json.dumps(data, allow_nan=False))
        row = ProbeEvent(machine=self.machine, probe=probe, number=int(number), event=event,
                         time=time or datetime.now(UTC).isoformat(timespec="microseconds"),
                         calibration_id=calibration_id, data=stored)
        self._session.add(row)
        self._session.flush()
        return _event_dict(row)

    def list_probe_events(self, probe: str, number: int, event: str | None = None,
                          limit: int = 100) -> list[dict[str, Any]]:
        """Newest first."""
        query = (select(ProbeEvent).where(ProbeEvent.machine == self.machine, ProbeEvent.probe == probe,
                                          ProbeEvent.number == int(number))
                 .order_by(ProbeEvent.id.desc()).limit(limit))
        if event is not None:
            query = query.where(ProbeEvent.event == event)
        return [_event_dict(row) for row in self._session.scalars(query)]

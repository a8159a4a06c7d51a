"""Protocol files of CYCLE100…CYCLE106 (manual §7.1, design.md §10.3): programs in the program
store (the manual: "in the directory of the calling program", extension MPF), listed by
``GET /api/protocols`` and the program screen, downloaded as text."""

from __future__ import annotations

from datetime import UTC, datetime

from app.errors import NotFoundError
from db import Database

STATE_PROTOCOLS = "protocols"          # machine_state: {name: {"program", "updated"}}


class ProtocolFileStore:
    """``app.nc.cycles.protocol.ProtocolFiles`` over the program table."""

    def __init__(self, db: Database):
        self._db = db

    def write(self, name: str, text: str, program: str | None) -> None:
        with self._db.unit() as unit:
            unit.put_program(name, text)
            known = dict(unit.get_state(STATE_PROTOCOLS, None) or {})
            known[name] = {"program": program, "updated": datetime.now(UTC).isoformat(timespec="seconds")}
            unit.set_state(STATE_PROTOCOLS, known)

    def delete(self, name: str) -> None:
        with self._db.unit() as unit:
            if unit.get_program(name) is not None:
                unit.delete_program(name)
            known = dict(unit.get_state(STATE_PROTOCOLS, None) or {})
            if known.pop(name, None) is not None:
                unit.set_state(STATE_PROTOCOLS, known)

    def list(self) -> list[dict]:
        """The protocol files that exist, by name: ``{"name", "program", "updated", "size", "lines"}``."""
        with self._db.unit(readonly=True) as unit:
            known = unit.get_state(STATE_PROTOCOLS, None) or {}
            programs = {p["name"]: p for p in unit.list_programs()}
        return [{"name": name, "program": info.get("program"), "updated": programs[name]["updated_at"],
                 "size": programs[name]["size"], "lines": programs[name]["lines"]}
                for name, info in sorted(known.items()) if name in programs]

    def text(self, name: str) -> str:
        with self._db.unit(readonly=True) as unit:
            known = unit.get_state(STATE_PROTOCOLS, None) or {}
            program = unit.get_program(name) if name in known else None
        if program is None:
            raise NotFoundError(f"no protocol file {name!r}", field="name", code="unknown_protocol")
        return program["text"]

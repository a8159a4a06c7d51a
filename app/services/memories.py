"""The EV and MV memories of the tool-offset strategy (measuring-math §3.3, design.md §9.3).

``n`` is the memory number of _EVNUM (n = 10 is ``_EV[9]``), 1..MEMORY_COUNT (_EVMVNUM, the
manual's default 20 each). Reads give 0 for a memory never written; every write is audited.
"""

from __future__ import annotations

from app import checks
from app.errors import InvalidInput
from db import Database

MEMORY_COUNT = 20
KINDS = {"ev": "EV", "mv": "MV"}
MAX_VALUE = 1000.0          # mm: a memory beyond is a typo
#: the access function a memory write needs on every route (API, screen, NC program, NC variables;
#: the level table: "offsets ... EV/MV memories")
WRITE_FUNCTION = "offsets"


def check_value(value, field: str = "value") -> float:
    """A memory's value: the same range through the API, the screen and an NC program (_EV[i]=)."""
    return checks.number(value, field, lo=-MAX_VALUE, hi=MAX_VALUE, unit="mm")


class MemoryService:
    def __init__(self, db: Database):
        self._db = db

    @staticmethod
    def _key(kind: str, n) -> tuple[str, int]:
        if kind not in KINDS:
            raise InvalidInput("kind: must be ev or mv", field="kind")
        return KINDS[kind], checks.integer(n, "n", lo=1, hi=MEMORY_COUNT)

    def get(self, kind: str, n: int) -> dict:
        name, n = self._key(kind, n)
        with self._db.unit(readonly=True) as unit:
            return {"kind": kind, "n": n, "value": unit.get_memory(name, n)}

    def list(self) -> dict:
        with self._db.unit(readonly=True) as unit:
            stored = {kind: unit.list_memories(name) for kind, name in KINDS.items()}
        return {kind: [{"n": n, "value": values.get(n, 0.0)} for n in range(1, MEMORY_COUNT + 1)]
                for kind, values in stored.items()}

    def put(self, kind: str, n: int, value, source: str = "api") -> dict:
        name, n = self._key(kind, n)
        number = check_value(value)
        with self._db.unit() as unit:
            unit.put_memory(name, n, number, source=source)
        return {"kind": kind, "n": n, "value": number}

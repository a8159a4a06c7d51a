"""The NC's tool probe records ``_TP`` / ``_TPW`` (GUD6) are the HMI's tool-probe records: a program
reads what JOG or a cycle calibrated, and what it assigns is stored, validated and audited as
``PUT /api/tool-probes/{n}`` does (source "nc"). k = record number − 1.

Layouts: milling jog-measuring.md §9.2 ("Tool probe record _TP[k, 0…9]": trigger −X, +X, −Y, +Y,
−Z, +Z, edge length / disc diameter, axes code, type, distance to the upper edge; manual §9.2);
turning turning.md §0.7 (trigger −Z, +Z, −X, +X; 4…9 have no meaning there). ``_TPW`` has the same
layout over the workpiece-related trigger values (SW 6.3)."""

from __future__ import annotations

from collections.abc import Callable

from app.errors import InvalidInput, NotFoundError
from app.nc.variables import CallbackBacking, InvalidValue
from app.records import ToolProbeData

from .probes import ToolProbeService

MILL_TRIGGERS = ("X-", "X+", "Y-", "Y+", "Z-", "Z+")
LATHE_TRIGGERS = ("Z-", "Z+", "X-", "X+")
MILL_FIELDS = {6: "disc_diameter", 7: "axes", 8: "type", 9: "dz"}
TRIGGER_FIELDS = {"_TP": "trigger", "_TPW": "workpiece_trigger"}


def tool_probe_backing(name: str, records: ToolProbeService, is_lathe: Callable[[], bool],
                       may_write: Callable[[str], None]) -> CallbackBacking:
    """The backing of ``name`` ("_TP" or "_TPW") over ``records``."""
    trigger_field = TRIGGER_FIELDS[name]

    def element(key) -> tuple[int, str, str | None] | None:
        """(record number, field, trigger key or None) of ``name[k, i]``; None: no meaning."""
        k, i = key
        triggers = LATHE_TRIGGERS if is_lathe() else MILL_TRIGGERS
        if i < len(triggers):
            return k + 1, trigger_field, triggers[i]
        if not is_lathe() and i in MILL_FIELDS:
            return k + 1, MILL_FIELDS[i], None
        return None

    def stored(n: int) -> dict | None:
        try:
            record = records.get(n)
        except NotFoundError:
            return None
        return {k: v for k, v in record.items() if k in ToolProbeData.model_fields}

    def read(key):
        where = element(key)
        record = stored(where[0]) if where else None
        if where is None or record is None:
            return None
        _n, field, trigger = where
        return (record.get(field) or {}).get(trigger) if trigger else record.get(field)

    def write(key, value) -> None:
        where = element(key)
        if where is None:
            raise InvalidValue(f"{name}[{key[0]},{key[1]}] has no meaning on the lathe (turning.md §0.7)")
        may_write(name)
        n, field, trigger = where
        record = stored(n) or {"number": n}
        if trigger:
            record[field] = {**(record.get(field) or {}), trigger: float(value)}
        elif field in ("axes", "type"):
            if float(value) != int(value):      # a code, not a length: 133.5 is no axes code, not 133
                raise InvalidValue(f"{name}[{key[0]},{key[1]}] = {value:g}: the {field} code is a whole number")
            record[field] = int(value)
        else:
            record[field] = float(value)
        try:
            records.put(n, record, source="nc")
        except (InvalidInput, NotFoundError) as exc:
            raise InvalidValue(f"{name}[{key[0]},{key[1]}]: {exc.message}") from None

    return CallbackBacking(read, write)

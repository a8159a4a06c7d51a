"""A lathe's data in the HMI (turning.md §10.2): seeding from the scenario, reference grooves _KB.

Seeding (scenario load, start-up) from what the scenario says the HMI is told, never its truth
beyond that: the tool table from the tools' and the probe's ``nominal`` values (type, SL,
L1, L2, radius; the probe's radius = half its nominal ball diameter), the probe record bound
to the probe's T, the tool probe's rough ``_TP`` values (``tool_probe.nominal``, default the
faces rounded to whole mm) where no trigger value is stored, and the reference groove records
``_KB`` as the grooves' certificate gives them (the scenario's groove surfaces). Without
``reset`` only what is missing is added; with it the tables are emptied first.

Reference grooves: ``_KB[k]`` records 1.._CVAL[2] (default 3) in the machine state, each the
values an operator enters (``params.groove``: SL 7 ``x_minus``, ``x_plus``, ``bottom_z``; SL 8
``z_minus``, ``z_plus``, ``top_x``, ``bottom_x``; machine-related radius values).
"""

from __future__ import annotations

from collections.abc import Mapping

from app import checks
from app.errors import InvalidInput, NotFoundError
from db import Database

from .data_reset import clear_stored_data

STATE_GROOVES = "lathe_grooves"
GROOVE_RECORDS = 3                     # _CVAL[2] (turning.md §0.7)
GROOVE_KEYS = ("x_minus", "x_plus", "bottom_z", "z_minus", "z_plus", "top_x", "bottom_x")


def tool_row(tool) -> dict:
    """The tool table row of a scenario tool (its nominal values)."""
    return {"name": tool.name, "type": tool.type, "sl": tool.sl, "length": 0.0,
            "l1": tool.nominal_value("l1"), "l2": tool.nominal_value("l2"), "radius": tool.nominal_value("radius"),
            "wear": {"length": 0.0, "radius": 0.0, "l1": 0.0, "l2": 0.0}}


def probe_row(probe) -> dict:
    return {"name": "Lathe probe", "type": probe.type, "sl": probe.sl, "length": 0.0,
            "l1": probe.nominal_value("l1"), "l2": probe.nominal_value("l2"),
            "radius": probe.nominal_value("ball_diameter") / 2.0,
            "wear": {"length": 0.0, "radius": 0.0, "l1": 0.0, "l2": 0.0}}


def seed(db: Database, scenario, reset: bool, tool_probe_number: int) -> None:
    """The lathe's stored data from the scenario's nominal values: tools, probe record 1, the tool
    probe's rough triggers, the grooves _KB; ``reset`` clears tools, offsets and records first."""
    with db.unit() as unit:
        if reset:
            clear_stored_data(unit)
        present = {tool["t"] for tool in unit.list_tools()}
        if scenario.probe.t not in present:
            unit.put_tool(scenario.probe.t, probe_row(scenario.probe))
        for tool in scenario.tools:
            if tool.t not in present:
                unit.put_tool(tool.t, tool_row(tool))
        _seed_probe_record(unit, scenario, reset)
        if scenario.tool_probe is not None:
            n = 1 if reset else int(tool_probe_number)
            record = unit.get_tool_probe(n) or {}
            if not record.get("trigger"):
                unit.put_tool_probe(n, {**record, "number": n, "trigger": scenario.tool_probe.rough()})
        stored = unit.get_state(STATE_GROOVES, None)
        if reset or not stored:
            records = [g.kb() for g in scenario.grooves][:GROOVE_RECORDS]
            records += [{} for _ in range(GROOVE_RECORDS - len(records))]
            unit.set_state(STATE_GROOVES, records)


def _seed_probe_record(unit, scenario, reset: bool) -> None:
    """Probe record 1 names the scenario's probe unless a record does already (or after a reset)."""
    probe = unit.get_probe(1) or {}
    if reset or not any(r.get("tool") == scenario.probe.t for r in unit.list_probes()):
        if not probe.get("tool"):
            unit.put_probe(1, {**probe, "number": 1, "tool": scenario.probe.t,
                               "ball_diameter": scenario.probe.nominal_value("ball_diameter")})


# --- reference grooves _KB ------------------------------------------------------------------------

def check_groove(values) -> dict:
    """A groove record as entered: known keys, finite numbers (422 naming the field)."""
    if not isinstance(values, Mapping):
        raise InvalidInput("groove: must be an object of the _KB values", field="groove")
    out = {}
    for key, value in values.items():
        if key == "number":
            continue
        if key not in GROOVE_KEYS:
            raise InvalidInput(f"{key}: not a groove value ({', '.join(GROOVE_KEYS)})", field=key)
        out[key] = checks.number(value, key)
    return out


class GrooveService:
    """``GET/PUT /api/lathe/grooves/{n}``: the reference groove records _KB (machine state)."""

    def __init__(self, db: Database):
        self._db = db

    def list(self) -> list[dict]:
        with self._db.unit(readonly=True) as unit:
            records = unit.get_state(STATE_GROOVES, None) or [{} for _ in range(GROOVE_RECORDS)]
        return [{"number": i + 1, **record} for i, record in enumerate(records)]

    def get(self, n: int) -> dict:
        n = checks.integer(n, "n", lo=1, hi=GROOVE_RECORDS)
        records = self.list()
        if n > len(records):
            raise NotFoundError(f"no groove record {n}", code="unknown_groove")
        return records[n - 1]

    def put(self, n: int, values) -> dict:
        n = checks.integer(n, "n", lo=1, hi=GROOVE_RECORDS)
        record = check_groove(values)
        with self._db.unit() as unit:
            records = unit.get_state(STATE_GROOVES, None) or [{} for _ in range(GROOVE_RECORDS)]
            records = list(records) + [{} for _ in range(GROOVE_RECORDS - len(records))]
            records[n - 1] = record
            unit.set_state(STATE_GROOVES, records)
        return {"number": n, **record}

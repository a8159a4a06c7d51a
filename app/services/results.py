"""Jobs, parts and characteristics with verdicts (design.md §10.3, docs/results.md).

A job (part number, order, serial or ``"auto"``, operator, program, optional characteristic
limits) says which part the next measurements belong to. ``PUT /api/job`` starts its first part,
``POST /api/job/next-part`` the next one. Each measurement logged while a part is open links to
it (``part_id``) and each of its result values becomes a characteristic with nominal, limits,
actual, deviation and verdict (``engine.verdict``), written in the measurement's transaction.
"""

from __future__ import annotations

import re
import socket
from typing import Any, TypeGuard

from app import checks
from app.errors import InvalidInput, NotFoundError
from app.gud import GudSettings
from app.services.settings import SettingsService
from db import Database
from engine.verdict import MATERIAL_SIDES, verdict, worst

STATE_JOB = "job"
JOB_FIELDS = ("part_number", "order", "serial", "operator", "program")
TEXT_MAX = 64
INNER_TASKS = ("hole.", "pocket.")
OUTER_TASKS = ("spigot.",)
# the value the tolerance object of design.md §9.3 applies to, per task (measuring-math §3.5 D)
TOLERANCED = {"hole.1": ("diameter",), "spigot.1": ("diameter",), "pocket.rect": ("length", "width"),
              "spigot.rect": ("length", "width"), "edge.distance": ("distance",), "edge.set": ("position",)}
# sizes: their nominal is the parameter of that name (or the tolerance's setpoint)
SIZES = ("diameter", "length", "width", "distance")
# positions and angles: characteristics only when the job gives their limits and the measurement
# does not set a zero offset (measuring to set a zero point defines the datum: its deviation is
# the clamping, not the part)
POSITIONS = ("center", "corner", "p1", "position")
ANGLES = ("angle", "alpha", "beta")


def _text(body: dict, key: str, required: bool = False) -> str | None:
    value = body.get(key)
    if value is None or value == "":
        if required:
            raise InvalidInput(f"{key}: required", field=key)
        return None
    if not isinstance(value, str) or len(value) > TEXT_MAX or any(ch in value for ch in "\r\n"):
        raise InvalidInput(f"{key}: a text of at most {TEXT_MAX} characters on one line", field=key)
    return value.strip()


def _limits(body: Any) -> dict[str, dict[str, float | None]]:
    """The job's characteristic limits: {name: {"nominal", "lower", "upper"}} (absolute values)."""
    if body is None:
        return {}
    if not isinstance(body, dict) or len(body) > 200:
        raise InvalidInput("characteristics: an object {name: {nominal, lower, upper}}", field="characteristics")
    out: dict[str, dict[str, float | None]] = {}
    for name, limits in body.items():
        field = f"characteristics.{name}"
        if not isinstance(name, str) or not 0 < len(name) <= 80:
            raise InvalidInput("characteristics: names of 1..80 characters", field="characteristics")
        if not isinstance(limits, dict) or set(limits) - {"nominal", "lower", "upper"}:
            raise InvalidInput(f"{field}: an object with nominal, lower, upper", field=field)
        item = {key: checks.optional_number(limits.get(key), f"{field}.{key}") for key in ("nominal", "lower", "upper")}
        lower, upper = item["lower"], item["upper"]
        if lower is not None and upper is not None and lower > upper:
            raise InvalidInput(f"{field}.lower: above the upper limit", field=f"{field}.lower")
        out[name] = item
    return out


def next_serial(serial: str) -> str:
    """The serial after ``serial``: its trailing number counts up, keeping the width (SN-0099 →
    SN-0100); a serial without a trailing number gets "-2"."""
    match = re.search(r"(\d+)$", serial)
    if match is None:
        return f"{serial}-2"
    digits = match.group(1)
    return serial[: match.start()] + str(int(digits) + 1).zfill(len(digits))


class ResultsService:
    def __init__(self, db: Database, settings: SettingsService, machine_name: str | None = None):
        self._db = db
        self._settings = settings
        self.machine_name = machine_name or socket.gethostname()

    # --- the job --------------------------------------------------------------------------

    def job(self) -> dict:
        with self._db.unit(readonly=True) as unit:
            job = unit.get_state(STATE_JOB, None)
            part = unit.get_part(job["part_id"]) if job and job.get("part_id") else None
        return self._job_answer(job, part)

    def _job_answer(self, job: dict | None, part: dict | None) -> dict:
        if not job:
            return {"active": False, "part": None}
        return {"active": True, **{k: job.get(k) for k in JOB_FIELDS}, "characteristics": job.get("characteristics") or {},
                "part_id": job.get("part_id"), "part": None if part is None else self._part_answer(part)}

    def put_job(self, body: Any) -> dict:
        """A new job; its first part starts now (serial ``"auto"``: the count of parts of this part
        number so far + 1)."""
        if not isinstance(body, dict):
            raise InvalidInput("the job must be an object")
        unknown = sorted(set(body) - {*JOB_FIELDS, "characteristics"})
        if unknown:
            raise InvalidInput(f"{unknown[0]}: unknown key (use {', '.join(JOB_FIELDS)}, characteristics)",
                               field=unknown[0])
        job: dict[str, Any] = {key: _text(body, key, required=key == "part_number") for key in JOB_FIELDS}
        job["characteristics"] = _limits(body.get("characteristics"))
        job["auto_serial"] = (job["serial"] or "auto") == "auto"
        with self._db.unit() as unit:
            part = self._start_part(unit, job, job["serial"])
            unit.set_state(STATE_JOB, job)
        return self._job_answer(job, {**part, "characteristics": []})

    def delete_job(self) -> None:
        """Measurements no longer belong to a part."""
        with self._db.unit() as unit:
            unit.set_state(STATE_JOB, None)

    def next_part(self, body: Any = None) -> dict:
        """The next part of the same job: the next serial (or ``body.serial``)."""
        body = body or {}
        if not isinstance(body, dict) or set(body) - {"serial"}:
            raise InvalidInput("next part: {} or {\"serial\": ...}", field="serial")
        serial = _text(body, "serial")
        with self._db.unit() as unit:
            job = unit.get_state(STATE_JOB, None)
            if not job:
                raise InvalidInput("no job: set one first (PUT /api/job)", field="part_number", code="no_job")
            if serial is None and not job.get("auto_serial"):
                serial = next_serial(job.get("serial") or "1")
            part = self._start_part(unit, job, serial)
            unit.set_state(STATE_JOB, job)
        return self._job_answer(job, {**part, "characteristics": []})

    @staticmethod
    def _start_part(unit, job: dict, serial: str | None) -> dict:
        if serial is None or serial == "auto":
            serial = str(unit.count_parts(job["part_number"]) + 1)
        job["serial"] = serial
        part = unit.add_part({key: job.get(key) for key in JOB_FIELDS})
        job["part_id"] = part["id"]
        return part

    # --- the measurement's characteristics (inside its write transaction) ----------------------

    def add_log(self, unit, entry: dict) -> int:
        """``unit.add_log(entry)`` linking the entry to the open part and writing its characteristics."""
        job = unit.get_state(STATE_JOB, None)
        part_id = job.get("part_id") if job else None
        if part_id is None:
            return unit.add_log(entry)
        entry["part_id"] = part_id
        log_id = unit.add_log(entry)
        present = set(unit.characteristic_names(part_id))
        for item in characteristics_of(entry, job.get("characteristics") or {}, self._settings.get()):
            if item["name"] in present:       # measured again in this part: the newest counts
                unit.remove_characteristic(part_id, item["name"])
            unit.add_characteristic(part_id, {**item, "log_id": log_id})
        return log_id

    # --- parts ------------------------------------------------------------------------------

    def _part_answer(self, part: dict) -> dict:
        chars = [{k: c[k] for k in ("name", "nominal", "upper", "lower", "actual", "deviation", "verdict",
                                    "log_id", "unit", "compensation", "time")} for c in part["characteristics"]]
        return {"id": part["id"], **{k: part.get(k) for k in JOB_FIELDS}, "machine": self.machine_name,
                "started": part["started"], "verdict": worst(c["verdict"] for c in chars), "characteristics": chars}

    def parts(self, part_number: str | None = None, limit: int = 100, offset: int = 0) -> list[dict]:
        with self._db.unit(readonly=True) as unit:
            rows = unit.list_parts(part_number, limit, offset)
        return [self._part_answer(p) for p in rows]

    def part(self, part_id: int) -> dict:
        with self._db.unit(readonly=True) as unit:
            part = unit.get_part(part_id) if 1 <= part_id < 2**63 else None
        if part is None:
            raise NotFoundError(f"no part {part_id}", field="part_id")
        return self._part_answer(part)

    def probe_of(self, part: dict) -> int | None:
        """The workpiece probe record the part's newest value was measured with."""
        ids = [c["log_id"] for c in part["characteristics"] if c.get("log_id")]
        if not ids:
            return None
        with self._db.unit(readonly=True) as unit:
            entry = unit.get_log(max(ids)) or {}
        probe = entry.get("probe")
        return int(probe["number"]) if isinstance(probe, dict) and probe.get("number") else None

    def series(self, part_number: str, characteristic: str | None = None) -> list[dict]:
        """The characteristics of every part of ``part_number``, in measuring order."""
        with self._db.unit(readonly=True) as unit:
            return unit.characteristic_series(part_number, characteristic)


# --- which characteristics a log entry gives --------------------------------------------------------

def _material(task: str, name: str, result: dict) -> int | None:
    if name not in SIZES:
        return None
    if name == "distance":
        return {"slot": MATERIAL_SIDES["inner"], "web": MATERIAL_SIDES["outer"]}.get(result.get("feature") or "")
    if task.startswith(INNER_TASKS):
        return MATERIAL_SIDES["inner"]
    if task.startswith(OUTER_TASKS):
        return MATERIAL_SIDES["outer"]
    return None


def _is_number(value: object) -> TypeGuard[int | float]:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _values(task: str, params: dict, result: dict, zero_offset: bool) -> list[tuple[str, str, float, float | None]]:
    """(name, result key, actual, nominal) of the entry's result values: the sizes, and without a
    zero offset corrected also the positions and the angles."""
    out = _size_values(params, result)
    if zero_offset:
        return out
    setpoint: dict = params["setpoint"] if isinstance(params.get("setpoint"), dict) else {}
    if task == "edge.set":
        out += _edge_values(params, result, setpoint)
    else:
        out += _position_values(result, setpoint)
    return out + _angle_values(params, result)


def _size_values(params: dict, result: dict) -> list[tuple[str, str, float, float | None]]:
    out: list[tuple[str, str, float, float | None]] = []
    for key in SIZES:
        value = result.get(key)
        if _is_number(value):
            nominal = params.get(key) if key != "distance" else params.get("setpoint")
            out.append((key, key, float(value), nominal if isinstance(nominal, int | float) else None))
    return out


def _edge_values(params: dict, result: dict, setpoint: dict) -> list[tuple[str, str, float, float | None]]:
    """The edge's position on its axis."""
    if not isinstance(result.get("position"), dict):
        return []
    axis = params.get("axis")
    value = result["position"].get(axis)
    if not isinstance(value, int | float):
        return []
    given = params.get("setpoint")            # a number (the edge's position) or {axis: value}
    nominal = given if _is_number(given) else setpoint.get(axis)
    return [(f"position {axis}", "position", float(value), nominal)]


def _position_values(result: dict, setpoint: dict) -> list[tuple[str, str, float, float | None]]:
    out: list[tuple[str, str, float, float | None]] = []
    for key in POSITIONS:
        point = result.get(key)
        if isinstance(point, dict):
            out += [(f"{key} {axis}", key, float(value), setpoint.get(axis))
                    for axis, value in point.items() if _is_number(value)]
    return out


def _angle_values(params: dict, result: dict) -> list[tuple[str, str, float, float | None]]:
    out: list[tuple[str, str, float, float | None]] = []
    for key in ANGLES:
        value = result.get(key)
        if _is_number(value):
            nominal = params.get("setpoint_angle", 0.0) if key == "angle" else 0.0
            out.append((key, key, float(value), nominal if isinstance(nominal, int | float) else None))
    return out


def _entry_parts(entry: dict) -> tuple[str, dict, dict]:
    """(task, params, result) of a log entry, empty where the entry has none."""
    params: dict = entry["params"] if isinstance(entry.get("params"), dict) else {}
    result: dict = entry["result"] if isinstance(entry.get("result"), dict) else {}
    return str(entry.get("task") or ""), params, result


def _name_prefix(params: dict) -> str:
    """The characteristic's name the operator gave, with a space before the value's name."""
    prefix = params.get("characteristic")
    return f"{prefix} " if isinstance(prefix, str) and prefix.strip() else ""


def characteristics_of(entry: dict, job_limits: dict, settings: GudSettings) -> list[dict]:
    """The characteristics of one log entry (docs/results.md): each result value with its nominal,
    its band (the job's limits by name; else the tolerance object of design.md §9.3 for the value
    it applies to) and its verdict."""
    task, params, result = _entry_parts(entry)
    target = entry.get("target")
    tool_target = isinstance(params.get("target"), dict) or (isinstance(target, str) and target.startswith("T"))
    zero_offset = not (tool_target or target in (None, "measure_only"))
    tolerance = params.get("tolerance") if isinstance(params.get("tolerance"), dict) else None
    banded = tolerance is not None or tool_target         # the tolerance object (or a tool's) applies
    prefix = _name_prefix(params)
    toleranced = TOLERANCED.get(task, ())
    out = []
    for name, key, actual, nominal in _values(task, params, result, zero_offset):
        given = job_limits.get(prefix + name)
        if key not in SIZES and key not in toleranced and not given:
            continue            # a position or angle has no band unless the job gives one
        tol = (tolerance or {}) if key in toleranced and banded else None
        nominal, upper, lower = _band(key, nominal, tol, given, settings)
        compensation = result.get("compensation") if key in toleranced else None
        out.append({"name": prefix + name, "nominal": nominal, "upper": upper, "lower": lower, "actual": actual,
                    "deviation": actual - nominal if nominal is not None else None,
                    "unit": "deg" if key in ANGLES else "mm",
                    "verdict": verdict(actual, lower, upper, _material(task, key, result), settings.verdict_rule),
                    "compensation": compensation if isinstance(compensation, int | float) and compensation else None})
    return out


def _band(key: str, nominal: float | None, tol: dict | None, given: dict | None,
          settings: GudSettings) -> tuple[float | None, float | None, float | None]:
    """(nominal, upper, lower) of a value: from the job's limits ``given`` by name, else from the
    tolerance object ``tol`` where it applies to the value (None where it does not)."""
    upper = lower = None
    if tol is not None:
        if key in SIZES and tol.get("setpoint") is not None and key in ("diameter", "distance"):
            nominal = float(tol["setpoint"])
        if nominal is not None:
            upper = nominal + float(tol.get("upper", settings.tol_upper))
            lower = nominal + float(tol.get("lower", settings.tol_lower))
    if given:
        nominal = given["nominal"] if given.get("nominal") is not None else nominal
        upper, lower = given.get("upper"), given.get("lower")
    return nominal, upper, lower

"""Probe health (design.md §10.4): the repeatability check and the events that make a calibration
invalid (issue [probe-health] items 3, 4, 6).

- Repeatability (ISO 230-10:2022 §7.1, measuring-math §1.5, engine.repeatability): from where the
  probe stands it probes once towards the face ahead to find it, then ``touches`` times from
  ``clearance`` before the face at the measuring feed, always from the same side; the latched
  positions along the direction give 2σ and the range. ``"directions": ["X+", "X-", ...]`` (e.g.
  around a ring gauge from its centre) does the same per direction and reports the worst. The
  probe record keeps the last check (``repeatability``), probe_events the history.
- Invalid on an event: a collision while the probe is in the spindle (61302/61402), a broken
  probe (61302 that Reset cannot clear), a collision that names the tool probe, a scenario load
  whose probe is not the one calibrated (``probe_identity``); a change of the ball or stylus data
  is app.services.probes' PUT, the age is worked out on each read (app.workflow.probe_trust).

Decisions (where the spec leaves room):
- The first touch only finds the face and is not counted: every counted touch starts from the same
  point, as ISO 230-10 asks.
- An invalidated calibration keeps its first reason until it is calibrated again; later events are
  history only.
- Directions are machine axes (MCS): repeatability is the probe's and the machine's, not the
  workpiece's.
"""

from __future__ import annotations

from datetime import UTC, datetime

import numpy as np

from app import checks
from app.errors import ConflictError, HmiError, InvalidInput
from app.machine.protocol import Alarm
from app.workflow import probe_trust
from db import Database, StorageUnavailable
from engine import alarms
from engine.repeatability import repeatability

from .machine_service import MachineService
from .measuring import probe_number_for
from .probes import invalidation
from .settings import SettingsService

DIRECTIONS = {f"{axis}{sign}": np.array([float(sign == "+") - float(sign == "-") if axis == a else 0.0
                                         for a in "XYZ"]) for axis in "XYZ" for sign in "+-"}
MAX_TOUCHES = 100
DEFAULT_TOUCHES = 10
DEFAULT_DISTANCE = 50.0        # mm searched for the face (a measuring move: it stops at the switch)
DEFAULT_CLEARANCE = 1.0        # mm before the face where each counted touch starts
BODY_KEYS = {"touches", "direction", "directions", "distance", "clearance", "feed"}
COLLISIONS = (alarms.PROBE_COLLISION.number, alarms.COLLISION_LIMITED.number)


def _now() -> str:
    return datetime.now(UTC).isoformat(timespec="seconds")


class ProbeHealthService:
    def __init__(self, db: Database, machine: MachineService, settings: SettingsService) -> None:
        self._db = db
        self._machine = machine
        self._settings = settings
        machine.on_alarm(self._on_alarm)
        machine.on_scenario(self._on_scenario)

    # --- the repeatability check -----------------------------------------------------------
    def check_body(self, body: dict) -> dict:
        if not isinstance(body, dict):
            raise InvalidInput("the body must be a JSON object")
        unknown = sorted(set(body) - BODY_KEYS)
        if unknown:
            raise InvalidInput(f"{unknown[0]}: unknown field; use {sorted(BODY_KEYS)}", field=unknown[0])
        touches = checks.integer(body.get("touches", DEFAULT_TOUCHES), "touches", lo=2, hi=MAX_TOUCHES)
        if "directions" in body:
            directions = body["directions"]
            if not isinstance(directions, list) or not directions or len(directions) > len(DIRECTIONS):
                raise InvalidInput("directions: a list of 1 to 6 of " + ", ".join(DIRECTIONS), field="directions")
        else:
            directions = [body.get("direction", "Z-")]
        for d in directions:
            if d not in DIRECTIONS:
                field = "directions" if "directions" in body else "direction"
                raise InvalidInput(f"{field}: {d!r} is not one of {', '.join(DIRECTIONS)}", field=field)
        if len(set(directions)) != len(directions):
            raise InvalidInput("directions: each direction once", field="directions")
        distance = checks.number(body.get("distance", DEFAULT_DISTANCE), "distance")
        if not 0 < distance <= 1000:
            raise InvalidInput("distance: mm, more than 0 and at most 1000", field="distance")
        clearance = checks.number(body.get("clearance", DEFAULT_CLEARANCE), "clearance")
        if not 0.05 <= clearance <= 50:
            raise InvalidInput("clearance: mm, 0.05 to 50", field="clearance")
        gud = self._settings.get()
        feed = checks.number(body.get("feed", gud.measuring_feed), "feed")
        if not 0 < feed <= 10_000:
            raise InvalidInput("feed: mm/min, more than 0 and at most 10000", field="feed")
        return {"touches": touches, "directions": directions, "distance": distance, "clearance": clearance,
                "feed": feed, "position_feed": float(gud.position_feed)}

    def repeatability(self, n: int, body: dict) -> dict:
        """``POST /api/probes/{n}/repeatability``: ``{"n", "two_sigma", "range", "at", ...}`` (mm)."""
        n = checks.integer(n, "n", lo=1, hi=99)
        args = self.check_body(body)
        self._refuse_unready()
        start = self._machine.status()["mcs"]
        per_direction: dict[str, dict] = {}
        try:
            for name in args["directions"]:
                per_direction[name] = self._touches(DIRECTIONS[name], args)
                self._machine.goto(start, "MCS")
        except HmiError:
            self._return_to(start)
            raise
        worst = max(per_direction.values(), key=lambda r: r["two_sigma"])
        limit = float(self._settings.get().repeatability_limit)
        figures = {"n": args["touches"], "two_sigma": worst["two_sigma"], "range": worst["range"], "at": _now(),
                   "direction": args["directions"][0] if len(per_direction) == 1 else "+".join(per_direction),
                   "feed": args["feed"], "limit": limit, "exceeded": worst["two_sigma"] > limit}
        if len(per_direction) > 1:
            figures["directions"] = {k: {"two_sigma": v["two_sigma"], "range": v["range"]}
                                     for k, v in per_direction.items()}
        with self._db.unit() as unit:
            record = unit.get_probe(n) or {"number": n}
            event = unit.add_probe_event("workpiece", n, "repeatability",
                                         {**figures, "deviations": {k: v["deviations"]
                                                                    for k, v in per_direction.items()}},
                                         calibration_id=record.get("calibration_id"))
            unit.put_probe(n, {**record, "repeatability": {**figures, "id": event["id"]}},
                           source="repeatability", detail={"two_sigma": figures["two_sigma"]})
        return {"probe": n, **figures, "id": event["id"], "calibration_id": record.get("calibration_id"),
                "deviations": {k: v["deviations"] for k, v in per_direction.items()}}

    def _refuse_unready(self) -> None:
        status = self._machine.status()
        if status["alarms"]:
            a = status["alarms"][-1]
            raise ConflictError(f"{a['code']} {a['text']}: press Reset first", code="alarm")
        probe = status["probe"]
        if not probe["in_spindle"]:
            raise ConflictError("The probe is not the tool in the spindle: load the probe first",
                                code="probe_not_in_spindle")
        if probe.get("armed") is False:
            raise ConflictError("The probe is not switched on (armed)", code="probe_not_armed")
        if probe.get("deflected"):
            raise ConflictError("The probe is deflected already: clear the stylus first", code="probe_deflected")

    def _touches(self, direction: np.ndarray, args: dict) -> dict:
        """One face from one direction: find it, then the counted touches from the same point."""
        first = self._machine.probe(list(direction), args["distance"], args["feed"], "MCS")
        if not first["triggered"]:
            raise ConflictError(f"No face within {args['distance']:g} mm in this direction: position the probe "
                                "in front of a known face", code="not_switched")
        latch = np.array([first["mcs"][a] for a in "XYZ"])
        approach = latch - args["clearance"] * direction
        positions = []
        for _ in range(args["touches"]):
            self._machine.goto(dict(zip("XYZ", map(float, approach), strict=True)), "MCS", args["position_feed"])
            touch = self._machine.probe(list(direction), 2.0 * args["clearance"], args["feed"], "MCS")
            if not touch["triggered"]:
                raise ConflictError("The probe did not switch again on the face: check the probe and the "
                                    "face", code="not_switched")
            positions.append(float(np.array([touch["mcs"][a] for a in "XYZ"]) @ direction))
        self._machine.goto(dict(zip("XYZ", map(float, approach), strict=True)), "MCS")
        figures = repeatability(positions)
        return {"two_sigma": figures.two_sigma, "range": figures.range, "deviations": list(figures.deviations)}

    def _return_to(self, start: dict) -> None:
        try:
            if not self._machine.status()["alarms"]:
                self._machine.goto(start, "MCS")
        except HmiError:
            pass

    def history(self, probe: str, n: int, limit: int = 50) -> list[dict]:
        with self._db.unit(readonly=True) as unit:
            return unit.list_probe_events(probe, n, limit=limit)

    # --- events that make a calibration invalid -------------------------------------------------
    def invalidate(self, probe: str, numbers: list[int], reason: str, text: str) -> list[int]:
        """Mark each calibrated record of ``numbers`` invalid (the first reason stays); the numbers
        whose calibration became invalid now."""
        done = []
        with self._db.unit() as unit:
            for n in numbers:
                read, write = ((unit.get_probe, unit.put_probe) if probe == "workpiece"
                               else (unit.get_tool_probe, unit.put_tool_probe))
                record = read(n)
                if not probe_trust.is_calibrated(record, probe):
                    continue
                assert record is not None
                mark = invalidation(reason, text)
                unit.add_probe_event(probe, n, "invalidated", mark, calibration_id=record.get("calibration_id"))
                if record.get("invalidated"):
                    continue
                write(n, {**record, "invalidated": mark}, source="probe_health", detail={"reason": reason})
                done.append(n)
        return done

    def _active_probe_numbers(self, tool: int | None) -> list[int]:
        with self._db.unit(readonly=True) as unit:
            records = unit.list_probes()
        return [probe_number_for(records, tool, int(self._settings.get().probe_number))]

    def _on_alarm(self, alarm: Alarm, probes: dict) -> None:
        if alarm.code not in COLLISIONS:
            return
        try:
            self._invalidate_for(alarm, probes)
        except StorageUnavailable:      # the database cannot be written now: the alarm stays on screen
            pass

    def _invalidate_for(self, alarm: Alarm, probes: dict) -> None:
        text = f"{alarm.code} {alarm.text}"
        if "tool probe" in alarm.text.lower():
            self.invalidate("tool", [int(self._settings.get().tool_probe_number)], "collision", text)
        if probes["probe"] and probes["probe"]["in_spindle"]:
            reason = "collision" if alarm.resettable else "broken_probe"
            self.invalidate("workpiece", self._active_probe_numbers(probes.get("tool")), reason, text)

    def _on_scenario(self) -> None:
        """Another scenario's probe: the calibrations made with a different probe are invalid."""
        for probe, list_name in (("workpiece", "list_probes"), ("tool", "list_tool_probes")):
            identity = self._machine.probe_identity(probe)
            with self._db.unit(readonly=True) as unit:
                records = getattr(unit, list_name)()
            other = [int(r["number"]) for r in records
                     if r.get("probe_identity") and r.get("probe_identity") != identity]
            if other:
                self.invalidate(probe, other, "other_probe", "a scenario with another probe was loaded")

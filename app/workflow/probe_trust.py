"""Is the probe to be trusted for this measurement? (issue [probe-health] items 3–5, design.md §10.4)

Checked before anything moves, in every path that measures (screen, API, the cycles of a part
program: they all go through ``WorkflowService._prepare_start``). Each finding is a warning, or a
refusal (409, nothing moved) when the setting ``calibration_invalid`` is "refuse":

- a direction the task is about to probe in that the probe was never calibrated for: the
  infeed (length L1, ``calibrated_length``) or a plane direction (``calibrated_radius``): an
  uncalibrated length writes Z off by the nominal/true length difference (the issue measured
  0.174 mm) without it;
- a calibration made invalid by an event (collision, broken probe, a change of the ball or
  stylus data, another scenario's probe) or older than ``calibration_max_age_h``;
- a last repeatability check whose 2σ exceeds ``repeatability_limit``.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from datetime import UTC, datetime
from typing import Any

import numpy as np

from app.workflow.executor import StepExecutor
from app.workflow.tasks import Category
from engine import alarms
from engine.alarms import AlarmDef
from engine.plan import ideal_path
from engine.types import MeasuringError, ProbeStep


@dataclass(frozen=True)
class Finding:
    """One reason not to trust the probe: the alarm, the error code of a refusal, the message."""

    alarm: AlarmDef
    code: str
    detail: str

    @property
    def message(self) -> str:
        return f"{self.alarm.number} {self.alarm.text}: {self.detail}"


_INFEED_SHARE = 0.5       # a travel with more than this share along the infeed axis measures on it


def needed_directions(plane, directions: Iterable[np.ndarray]) -> tuple[bool, list[str]]:
    """(measures on the infeed axis, plane trigger keys "X+", ... it probes along).

    A direction mostly along the infeed axis needs the length (L1); an axis-parallel plane
    direction its trigger value; any other plane direction the effective diameter."""
    infeed = False
    keys: list[str] = []
    p = plane.infeed_unit
    for d in directions:
        d = np.asarray(d, dtype=float)
        if abs(float(d @ p)) > _INFEED_SHARE:
            infeed = True
            continue
        j = int(np.argmax(np.abs(d)))
        if float(np.linalg.norm(np.delete(d, j))) < 1e-9:
            key = f"{'XYZ'[j]}{'+' if d[j] > 0 else '-'}"
        else:
            key = "plane"
        if key not in keys:
            keys.append(key)
    return infeed, keys


def uncalibrated(record: Mapping[str, Any] | None, task: str, infeed: bool, keys: list[str],
                 plane) -> list[Finding]:
    """The directions ``task`` probes in that ``record`` has no calibration for (item 5)."""
    data = record or {}
    out: list[Finding] = []

    def missing(detail: str) -> None:
        out.append(Finding(alarms.PROBE_NOT_CALIBRATED, "not_calibrated", detail))

    if infeed and task != "probe.length" and not data.get("calibrated_length"):
        missing(f"length {plane.infeed}-: calibrate the probe length on a known surface first")
    if task not in ("probe.radius", "probe.surface") and keys:      # both calibrate these directions
        trigger = data.get("trigger") or {}
        absent = [k for k in keys if k != "plane" and k not in trigger]
        if not data.get("calibrated_radius"):
            missing("radius: calibrate the probe in the ring gauge first")
        elif absent:
            missing(f"direction {', '.join(absent)}: calibrate the probe in the ring gauge in this plane first")
    return out


def age_hours(calibrated_at: str | None, now: datetime | None = None) -> float | None:
    """Hours since ``calibrated_at`` (ISO text), None when never calibrated or unreadable."""
    if not calibrated_at:
        return None
    try:
        when = datetime.fromisoformat(calibrated_at)
    except ValueError:
        return None
    if when.tzinfo is None:
        when = when.replace(tzinfo=UTC)
    return max(0.0, ((now or datetime.now(UTC)) - when).total_seconds() / 3600.0)


# what made a calibration invalid (design.md §10.4); the screens translate these texts
INVALID_REASONS = {
    "not_calibrated": "never calibrated",
    "collision": "a collision after the calibration",
    "broken_probe": "the probe broke (overtravel) after the calibration",
    "ball_changed": "the ball or stylus data changed after the calibration",
    "other_probe": "another probe was loaded (scenario) after the calibration",
    "age": "older than the setting calibration_max_age_h",
}
HEALTH_KEYS = ("calibration_id", "probe_identity", "invalidated", "repeatability")   # kept by the HMI
COMPUTED_KEYS = ("valid", "invalid_reason", "calibration_age_h")                      # worked out on read


def is_calibrated(record: Mapping[str, Any] | None, probe: str = "workpiece") -> bool:
    data = record or {}
    if probe == "tool":
        return bool(data.get("calibrated_length") or data.get("calibrated_diameter"))
    # a lathe's probe (turning.md §0.7): calibrated by CYCLE973 in the directions it measured
    return bool(data.get("calibrated_length") or data.get("calibrated_radius") or data.get("calibrated_directions"))


def validity(record: Mapping[str, Any] | None, max_age_h: float, probe: str = "workpiece",
             now: datetime | None = None) -> tuple[bool, str | None]:
    """(valid, reason) of ``record``'s calibration: never calibrated, invalidated by an event
    (the first one), or older than ``max_age_h`` hours (0: no limit)."""
    data = record or {}
    if not is_calibrated(data, probe):
        return False, "not_calibrated"
    if data.get("invalidated"):
        return False, str(data["invalidated"].get("reason") or "collision")
    age = age_hours(data.get("calibrated_at"), now)
    if max_age_h > 0 and age is not None and age > max_age_h:
        return False, "age"
    return True, None


def with_validity(record: dict, max_age_h: float, probe: str = "workpiece") -> dict:
    """``record`` with ``valid``, ``invalid_reason`` and ``calibration_age_h`` worked out now."""
    valid, reason = validity(record, max_age_h, probe)
    age = age_hours(record.get("calibrated_at"))
    return {**record, "valid": valid, "invalid_reason": reason,
            "calibration_age_h": None if age is None else round(age, 4)}


def health_findings(record: Mapping[str, Any] | None, settings, probe: str = "workpiece") -> list[Finding]:
    """An invalid calibration (an event or its age) and a repeatability above the limit (items 3, 4).
    A record never calibrated is left to ``uncalibrated`` (it names the direction)."""
    data = record or {}
    out: list[Finding] = []
    valid, reason = validity(data, float(settings.calibration_max_age_h), probe)
    which = "tool probe" if probe == "tool" else "probe"
    if not valid and reason != "not_calibrated":
        out.append(Finding(alarms.CALIBRATION_INVALID, "calibration_invalid",
                           f"{which} {data.get('number', '')}: {INVALID_REASONS.get(reason or '', reason)}; "
                           "calibrate it again"))
    last = data.get("repeatability") or {}
    two_sigma = last.get("two_sigma")
    if isinstance(two_sigma, int | float) and two_sigma > float(settings.repeatability_limit):
        out.append(Finding(alarms.REPEATABILITY_EXCEEDED, "repeatability",
                           f"{which} {data.get('number', '')}: 2σ {two_sigma * 1000:.1f} µm > limit "
                           f"{float(settings.repeatability_limit) * 1000:.1f} µm"))
    return out


def calibration_of(category, ctx) -> dict:
    """What a result says about the calibration it was measured with (design.md §10.4): the
    tool probe's for tool measuring and its calibration, else the workpiece probe's."""
    tool = category in (Category.TOOL_MEASURING, Category.TOOL_PROBE_CALIBRATION)
    record = (ctx.extra.get("tool_probe") if tool else ctx.probe_data) or {}
    valid, reason = validity(record, float(ctx.settings.calibration_max_age_h), "tool" if tool else "workpiece")
    last = record.get("repeatability") or {}
    return {"id": record.get("calibration_id"), "probe": "tool" if tool else "workpiece",
            "number": record.get("number"), "at": record.get("calibrated_at"), "valid": valid,
            "invalid_reason": reason, "repeatability": last.get("two_sigma"),
            "repeatability_at": last.get("at")}


def probing_directions(spec, params: dict, n: int, ctx, machine) -> list[np.ndarray]:
    """The travel directions (WCS) of point ``n``'s program from where the probe is now (the
    program the measurement will run, driven with ideal latches: nothing moves)."""
    try:
        plan_ctx = spec.plan_context(ctx, params)
        executor = StepExecutor(machine, ctx.chain().wcs2bcs, ctx.tool_length, ctx.plane.infeed_unit,
                                tip=spec.tool_tip(ctx))
        start = executor.current(spec.coords_for(params, plan_ctx))
        steps = ideal_path(spec.program(params, n, start, plan_ctx), start)
    except (MeasuringError, ValueError):
        return []                   # the measurement itself reports what is wrong with its plan
    return [np.asarray(s.direction, dtype=float) for s in steps if isinstance(s, ProbeStep)]


def findings(spec, params: dict, n: int, ctx, machine, directions: list[np.ndarray] | None = None
             ) -> list[Finding]:
    """Every reason not to trust the probe for point ``n`` of ``spec`` (module docstring): the
    workpiece probe for the workpiece tasks, the tool probe for tool measuring (item 6).
    ``directions``: ``probing_directions`` when known already (the start guard's run)."""
    if spec.category == Category.TOOL_MEASURING:
        return health_findings(ctx.extra.get("tool_probe"), ctx.settings, "tool")
    if spec.category == Category.TOOL_PROBE_CALIBRATION:
        return []
    if spec.lathe:
        return _lathe_findings(spec, params, ctx)
    if not spec.needs_probe or ctx.probe is None:
        return []
    if directions is None:
        directions = probing_directions(spec, params, n, ctx, machine)
    infeed, keys = needed_directions(ctx.plane, directions)
    found = uncalibrated(ctx.probe_data, spec.name, infeed, keys, ctx.plane)
    if spec.category != Category.PROBE_CALIBRATION:      # a calibration makes it valid again
        found += health_findings(ctx.probe_data, ctx.settings)
    return found


def _lathe_findings(spec, params: dict, ctx) -> list[Finding]:
    """A lathe measurement (CYCLE974/994): the health of the _WP record it uses (``params.probe``,
    _PRNUM). A direction never calibrated is the cycle's own alarm (61341, engine.turning_workpiece);
    a calibration (CYCLE973) makes the record valid again."""
    if spec.category != Category.WORKPIECE:
        return []
    number = int(params.get("probe") or 1)
    records = ((ctx.extra or {}).get("lathe") or {}).get("probes") or []
    record = next((r for r in records if int(r.get("number", 0)) == number), None)
    return health_findings(record, ctx.settings)

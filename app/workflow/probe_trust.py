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


def findings(spec, params: dict, n: int, ctx, machine) -> list[Finding]:
    """Every reason not to trust the workpiece probe for point ``n`` of ``spec`` (module docstring)."""
    if not spec.needs_probe or ctx.probe is None or spec.category == Category.TOOL_MEASURING:
        return []
    infeed, keys = needed_directions(ctx.plane, probing_directions(spec, params, n, ctx, machine))
    return uncalibrated(ctx.probe_data, spec.name, infeed, keys, ctx.plane)

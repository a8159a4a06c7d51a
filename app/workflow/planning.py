"""Adapter between the workflow and engine.plan: builds the PlanContext from the settings."""

from __future__ import annotations

import numpy as np

from engine import plan as engine_plan
from engine.compensation import skew_in_wcs
from engine.types import ProbeRecord

TASK_POINTS = engine_plan.TASK_POINTS
validate_params = engine_plan.validate_params
point_program = engine_plan.point_program
planned_path = engine_plan.planned_path


def context_from(ctx, session=None) -> engine_plan.PlanContext:
    """PlanContext from the MeasuringContext (GUD settings of spec §8, active probe record)."""
    s = ctx.settings
    probe = ctx.probe or ProbeRecord()
    wcs2bcs = ctx.chain().wcs2bcs
    return engine_plan.PlanContext(
        plane=ctx.plane,
        probe=probe,
        skew_wcs=skew_in_wcs(probe, wcs2bcs, ctx.spindle_angle) if ctx.probe else np.zeros(3),
        measuring_feed=float(s.get("measuring_feed", 300.0)),
        position_feed=float(s.get("position_feed", 2000.0)),
        position_feed_infeed=float(s.get("position_feed_infeed", 2000.0)),
        measuring_path=float(s.get("measuring_path", 50.0)),
        attempts=int(s.get("attempts", 1)),
        fast_feed=float(s.get("fast_feed", 900.0)) if s.get("two_stage") else None,
        rapid_return=bool(s.get("rapid_return", False)),
        spigot_safety=float(s.get("spigot_safety", 5.0)),
    )

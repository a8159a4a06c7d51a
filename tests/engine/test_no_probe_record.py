"""A missing workpiece probe record fails loudly (issue 27 item 7): no plan, no evaluation and no
touch radius quietly assumes a ball (the engine once took a 4 mm one when no record was given)."""

from __future__ import annotations

import numpy as np
import pytest
from test_plan_world import Bore, World, drive

from engine.evaluate import touch_radius
from engine.plan import PlanContext, planned_path, point_program, validate_params
from engine.planes import PLANES
from engine.tasks import evaluate
from engine.types import NoProbeRecord, ProbeRecord

G17 = PLANES["G17"]
CENTRE = np.array([10.0, 20.0, -5.0])


def _hole_point():
    """One measured hole point (Ø 30, probe Ø 6) to evaluate."""
    probe = ProbeRecord(ball_diameter=6.0, effective_diameter=6.0,
                        trigger={"X-": 3.0, "X+": -3.0, "Y-": 3.0, "Y+": -3.0}, calibrated_radius=True)
    ctx = PlanContext(plane=G17, probe_record=probe, skew_wcs=np.zeros(3))
    params = validate_params("hole.1", {"diameter": 30.0}, G17)
    point, _ = drive(point_program("hole.1", params, 1, CENTRE, ctx),
                     CENTRE, World(shapes=[Bore(CENTRE, 15.0, np.array([0.0, 0.0, 1.0]))], r=3.0))
    return point, params, probe


def test_a_workpiece_plan_without_a_probe_record_is_refused():
    ctx = PlanContext(plane=G17, probe_record=None, skew_wcs=np.zeros(3))
    params = validate_params("hole.1", {"diameter": 30.0}, G17)
    with pytest.raises(NoProbeRecord):
        planned_path("hole.1", params, 1, CENTRE, ctx)


def test_evaluating_without_a_probe_record_is_refused():
    point, params, probe = _hole_point()
    with pytest.raises(NoProbeRecord):
        evaluate("hole.1", params, [point], G17, None)
    with pytest.raises(NoProbeRecord):
        touch_radius(point.touches[0], None, G17)
    # with the record given, the same point is the Ø 30 hole at the centre (the record is used)
    result = evaluate("hole.1", params, [point], G17, probe)
    assert result.values["diameter"] == pytest.approx(30.0, abs=1e-9)
    assert result.values["center"] == pytest.approx({"X": 10.0, "Y": 20.0}, abs=1e-9)


def test_no_probe_record_is_a_value_error_naming_what_needed_it():
    """The screens treat ValueError as an expected refusal (app/web/failsafe.EXPECTED)."""
    err = NoProbeRecord("evaluating hole.1")
    assert isinstance(err, ValueError)
    assert "evaluating hole.1" in str(err) and "probe" in str(err)

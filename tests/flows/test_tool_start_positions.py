"""Where the operator may leave the tool before Measure tool → Diameter: spec §7.3 says "beside
and above the probe"; starting roughly above its centre must work too (the cycle knows the probe
from its calibration) and give the same radius."""

import pytest
from test_tool_measuring_truth import CUTTER_T, TOL, TRUE, api, client  # noqa: F401


@pytest.mark.parametrize("dx, dy, above", [(0.4, 0.3, 7.0), (-30.0, 0.0, 5.0), (0.0, 30.0, 8.0)])
def test_diameter_from_other_start_positions(api, dx, dy, above):  # noqa: F811
    api.calibrate("length_diameter")
    api.length(CUTTER_T)
    api.place(CUTTER_T, dx, dy, above)
    api.measure("tool.diameter", {})
    assert abs(api.tool(CUTTER_T)["radius"] - TRUE[CUTTER_T]["radius"]) <= TOL

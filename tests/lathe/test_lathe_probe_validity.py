"""The lathe's probe record (_WP) after a CYCLE973 calibration in JOG: valid, with the values the
lathe's measuring tasks use (turning.md §0.7, §4.4; design.md §10.4 / docs/probe-health.md).

Before, a lathe record calibrated in the groove still read ``valid: false, not_calibrated``: the
validity looked at the milling flags (ring and length calibration) only. The truth is the
scenario's probe: its true ball radius, its true L1 against the nominal L1 the NC uses.
"""

from __future__ import annotations

import pytest
from lathe_kit import LATHE_SCENARIO, Lathe, make_client

PROBE = LATHE_SCENARIO["probe"]
R_TRUE = PROBE["ball_diameter"] / 2.0                      # the ball's true radius
DL1 = PROBE["nominal"]["l1"] - PROBE["l1"]                 # true ball centre minus the NC's, in X
EXACT = 1e-9                                               # noise_sigma 0, no pre-travel


@pytest.fixture
def lathe(tmp_path):
    with make_client(tmp_path) as client:
        yield Lathe(client)


def record(lathe: Lathe, n: int = 1) -> dict:
    return lathe.ok(lathe.c.get(f"/api/probes/{n}"))


def test_an_uncalibrated_record_stays_invalid(lathe):
    """The seeded record and one whose values were typed in (the operator's rough record before
    the first calibration) are not calibrated: no CYCLE973 measured them."""
    fresh = record(lathe)
    assert (fresh["valid"], fresh["invalid_reason"]) == (False, "not_calibrated")
    assert "calibrated_directions" not in fresh or not fresh["calibrated_directions"]
    r = PROBE["nominal"]["ball_diameter"] / 2.0
    lathe.ok(lathe.c.put("/api/probes/1", json={"tool": PROBE["t"], "ball_diameter": 2 * r,
                                                "trigger": {"X-": r, "X+": -r, "Z-": r}}))
    typed = record(lathe)
    assert (typed["valid"], typed["invalid_reason"]) == (False, "not_calibrated")
    # a forged status in a PUT is refused by its list of directions only: it names real directions
    bad = lathe.c.put("/api/probes/1", json={"calibrated_directions": ["W-"]})
    assert bad.status_code == 422 and "calibrated_directions" in bad.text
    assert record(lathe)["trigger"] == typed["trigger"]


def test_groove_calibration_in_jog_makes_the_record_valid_with_the_true_values(lathe):
    """4-A through the JOG task: X both walls with skew and ball diameter, then −Z onto the bottom."""
    before = record(lathe)
    out = lathe.calibrate_probe_in_groove()
    data = record(lathe)
    assert data["valid"] is True and data["invalid_reason"] is None
    assert data["calibrated_directions"] == ["X+", "X-", "Z-"]
    assert data["calibration_id"] is not None and data["calibration_id"] != before["calibration_id"]
    assert data["trigger"]["X-"] == pytest.approx(R_TRUE, abs=EXACT)
    assert data["trigger"]["X+"] == pytest.approx(-R_TRUE, abs=EXACT)
    assert data["trigger"]["Z-"] == pytest.approx(R_TRUE, abs=EXACT)
    assert data["effective_diameter"] == pytest.approx(2 * R_TRUE, abs=EXACT)
    assert data["position_deviation"]["X"] == pytest.approx(DL1, abs=EXACT)
    assert data["calibrated_plane"] == "G18"
    # each answer names the calibration it was measured with: the second saw the first's record
    assert out["Z"]["calibration"]["valid"] is True


def test_surface_calibration_counts_for_its_direction_and_adds_to_the_earlier_ones(lathe):
    """CYCLE973 _MVAR=0 on the end face (W on the chuck face, the face at Z 60): Z− only."""
    lathe.tool(PROBE["t"])
    face_z = LATHE_SCENARIO["workpiece"]["profile"][0]["z"][1]
    lathe.ball_to(20.0, 80.0)
    lathe.task("lathe.probe.surface", {"axis": "Z", "direction": "-", "setpoint": face_z, "measuring_path": 3,
                                       "tolerance": {"safe_area": 4}})
    data = record(lathe)
    assert data["valid"] is True and data["calibrated_directions"] == ["Z-"]
    assert data["trigger"]["Z-"] == pytest.approx(R_TRUE, abs=EXACT)
    lathe.calibrate_probe_in_groove()
    assert record(lathe)["calibrated_directions"] == ["X+", "X-", "Z-"]


def test_a_lathe_calibration_is_invalidated_like_a_milling_one(lathe):
    """The lathe's record now takes part in probe health: a change of the ball makes it invalid
    (ball_changed) until the next calibration."""
    lathe.calibrate_probe_in_groove()
    data = record(lathe)
    changed = {k: v for k, v in data.items() if k not in ("valid", "invalid_reason", "calibration_age_h")}
    lathe.ok(lathe.c.put("/api/probes/1", json={**changed, "ball_diameter": 5.0}))
    after = record(lathe)
    assert (after["valid"], after["invalid_reason"]) == (False, "ball_changed")
    lathe.calibrate_probe_in_groove()
    assert record(lathe)["valid"] is True


def test_a_measurement_before_the_calibration_is_refused_and_runs_after_it(lathe):
    """The lathe's 1-point measurement needs the trigger value of its direction (61xxx "not
    calibrated" from the cycle, nothing moves); after the groove calibration it measures the
    shaft's true diameter and names the valid calibration."""
    lathe.tool(PROBE["t"])
    lathe.ball_to(60.0, 30.0, coords="WCS")
    params = {"axis": "X", "setpoint": 45, "measuring_path": 2, "reversal": True}
    session = lathe.ok(lathe.c.post("/api/measure", json={"task": "lathe.point", "params": params}))
    where = lathe.status()["mcs"]
    refused = lathe.c.post(f"/api/measure/{session['id']}/start", json={})
    assert refused.status_code in (409, 422) and "not calibrated" in refused.text, refused.text
    assert lathe.status()["mcs"] == where
    lathe.ok(lathe.c.post("/api/machine/reset"))               # the operator acknowledges the alarm
    lathe.calibrate_probe_in_groove()
    lathe.ball_to(60.0, 30.0, coords="WCS")
    answer = lathe.task("lathe.point", params)
    diameter = next(p for p in LATHE_SCENARIO["workpiece"]["profile"] if p["type"] == "cylinder")["diameter"]
    assert answer["result"]["actual"] == pytest.approx(diameter, abs=2e-6)
    assert answer["calibration"]["valid"] is True and answer["calibration"]["number"] == 1


def test_a_measurement_with_an_invalidated_lathe_calibration_warns_or_is_refused(lathe):
    """design.md §10.4 on the lathe: after a ball change the 1-point measurement warns 65121 (the
    setting "warn") or is refused before anything moves (the setting "refuse"); a new CYCLE973
    calibration makes it measure again without the warning."""
    lathe.calibrate_probe_in_groove()
    data = record(lathe)
    kept = {k: v for k, v in data.items() if k not in ("valid", "invalid_reason", "calibration_age_h")}
    lathe.ok(lathe.c.put("/api/probes/1", json={**kept, "ball_diameter": 5.0}))
    params = {"axis": "X", "setpoint": 45, "measuring_path": 2}
    lathe.ball_to(60.0, 30.0, coords="WCS")
    warned = lathe.task("lathe.point", params)
    assert any(w.startswith("65121") for w in warned["warnings"]), warned["warnings"]
    lathe.ok(lathe.c.put("/api/settings", json={"calibration_invalid": "refuse"}))
    lathe.ball_to(60.0, 30.0, coords="WCS")
    where = lathe.status()["mcs"]
    session = lathe.ok(lathe.c.post("/api/measure", json={"task": "lathe.point", "params": params}))
    refused = lathe.c.post(f"/api/measure/{session['id']}/start", json={})
    assert refused.status_code == 409 and refused.json()["error"]["code"] == "calibration_invalid", refused.text
    assert lathe.status()["mcs"] == where
    lathe.calibrate_probe_in_groove()
    lathe.ball_to(60.0, 30.0, coords="WCS")
    again = lathe.task("lathe.point", params)
    assert not any(w.startswith("65121") for w in again["warnings"])

"""A probe whose pre-travel has lobes (3rd and 4th harmonic of the probing angle in the probe's
own frame, design.md §9.8): a 12-direction ring calibration stores the direction-dependent map
with the probe record, and a hole probed at 20° to the machine axes reads its true diameter and
centre; the 4-direction calibration cannot see between its axes (issue [probe-physics] item 6).

Truth: the scenario's hole (own numpy through flowkit), never the product's numbers."""

from __future__ import annotations

import math

import numpy as np
import pytest
from flowkit import Flow, cal_scenario, make_client, ok

HOLE = (100.0, 60.0)           # part coordinates of the Ø20 hole
HOLE_D = 20.0
TURN = 20.0                    # the part (and G54) turned about Z: probing at 20° to the probe's axes


def lobed_scenario() -> dict:
    sc = cal_scenario(seed=3)
    sc["probe"]["pretravel"] = {"X+": 0.004, "X-": 0.005, "Y+": 0.004, "Y-": 0.006, "Z-": 0.002}
    sc["probe"]["lobing"] = [{"order": 3, "amplitude": 0.0015, "phase": 10.0},
                             {"order": 4, "amplitude": 0.0015, "phase": 0.0}]
    sc["probe"]["noise_sigma"] = 0.0001
    sc["workpiece"]["pose"] = {"trans": [250.0, 150.0, -120.0], "rot": [0.0, 0.0, TURN]}
    sc["workpiece"]["features"] = [{"type": "block", "size": [200, 120, 60]},
                                   {"type": "hole", "center": list(HOLE), "diameter": HOLE_D, "depth": 30.0}]
    return sc


def hole_in_g54(flow: Flow) -> dict:
    """G54 = the part's pose (measured earlier, say), the ball in the hole, measure only."""
    pose = flow.sc["workpiece"]["pose"]
    ok(flow.c.put("/api/offsets/G54", json={"trans": dict(zip("XYZ", pose["trans"], strict=True)),
                                            "rot": {"X": 0.0, "Y": 0.0, "Z": TURN}}))
    flow.activate("G54")
    flow.travel(HOLE[0] + 0.4, HOLE[1] - 0.3, -8.0, safe_z=20.0)
    session = flow.create("hole.1", {"diameter": HOLE_D}, "measure_only")
    answer = flow.start(session["id"])
    flow.goto(z=20.0)
    flow.activate("G500")
    return answer["result"]


def calibrate(flow: Flow, directions: int) -> dict:
    ring = flow.sc["ring_gauge"]
    cx, cy, top = ring["center"]
    flow.activate("G500")
    flow.travel(cx + 0.3, cy - 0.2, top - 8.0)
    session = flow.create("probe.radius", {"diameter": ring["diameter"], "directions": directions})
    answer = flow.start(session["id"])
    flow.goto(z=-100.0)
    return answer


def errors(result: dict) -> tuple[float, float]:
    centre = np.array([result["center"]["X"], result["center"]["Y"]])
    return abs(result["diameter"] - HOLE_D), float(np.linalg.norm(centre - np.array(HOLE)))


@pytest.fixture
def flow(tmp_path):
    sc = lobed_scenario()
    with make_client(tmp_path, sc) as client:
        yield Flow(client, sc)


def test_twelve_directions_store_the_map_and_the_hole_at_an_angle_reads_true(flow):
    calibrate(flow, 4)
    record = ok(flow.c.get("/api/probes"))
    assert all(not r.get("lobing") for r in (record if isinstance(record, list) else record.get("probes", [])))
    d_err_4, c_err_4 = errors(hole_in_g54(flow))

    calibrate(flow, 12)
    probes = ok(flow.c.get("/api/probes"))
    stored = [r for r in (probes if isinstance(probes, list) else probes.get("probes", [])) if r.get("lobing")]
    assert len(stored) == 1 and len(stored[0]["lobing"]["angles"]) == 12
    d_err_12, c_err_12 = errors(hole_in_g54(flow))

    # the lobes between the axes: 4th harmonic 1.5 µm at 80° instead of 0° -> about 2·1.5·(1 − cos 80°)
    expected_4 = 2 * 0.0015 * (1 - math.cos(math.radians(4 * TURN)))
    assert d_err_4 > 0.5 * expected_4, f"the 4-direction calibration should miss the lobes: {d_err_4 * 1e3:.2f} µm"
    assert d_err_12 < 0.0004, f"diameter {d_err_12 * 1e3:.2f} µm off with the map"
    assert c_err_12 < 0.0004, f"centre {c_err_12 * 1e3:.2f} µm off with the map"
    print(f"\nØ error 4 dirs {d_err_4 * 1e3:.2f} µm, 12 dirs {d_err_12 * 1e3:.2f} µm; "
          f"centre {c_err_4 * 1e3:.2f} -> {c_err_12 * 1e3:.2f} µm")


def test_four_directions_again_replace_the_map(flow):
    calibrate(flow, 12)
    calibrate(flow, 4)
    probes = ok(flow.c.get("/api/probes"))
    assert all(not r.get("lobing") for r in (probes if isinstance(probes, list) else probes.get("probes", [])))


def _stored(records) -> list:
    """The records as stored: without the calibration's age, which the answer works out at its time."""
    rows = records if isinstance(records, list) else records.get("probes", [])
    return [{k: v for k, v in r.items() if k != "calibration_age_h"} for r in rows]


def test_a_hand_edited_map_is_refused(flow):
    calibrate(flow, 12)
    probes = ok(flow.c.get("/api/probes"))
    record = next(r for r in (probes if isinstance(probes, list) else probes.get("probes", [])) if r.get("lobing"))
    lobing = dict(record["lobing"], coefficients=[c + 0.01 for c in record["lobing"]["coefficients"]])
    body = flow.c.put(f"/api/probes/{record['number']}", json={**record, "lobing": lobing})
    assert body.status_code == 422, body.text            # the API's validation status
    assert "lobing" in body.json()["error"]["message"]
    after = ok(flow.c.get("/api/probes"))
    assert _stored(after) == _stored(probes)                 # nothing changed


def test_the_probe_screen_shows_the_map_and_typed_trigger_values_drop_it(flow):
    calibrate(flow, 12)
    probes = ok(flow.c.get("/api/probes"))
    record = next(r for r in (probes if isinstance(probes, list) else probes.get("probes", [])) if r.get("lobing"))
    n = record["number"]
    page = flow.c.get(f"/probes?n={n}").text
    assert "12 directions" in page
    form = {f"trigger.{k}": f"{v:.4f}" for k, v in record["trigger"].items()}
    form.update({"ball_diameter": f"{record['ball_diameter']:.4f}",
                 "effective_diameter": f"{record['effective_diameter']:.4f}",
                 "skew.X": f"{record['skew'][0]:.4f}", "skew.Y": f"{record['skew'][1]:.4f}",
                 "tool": str(record.get("tool") or "")})
    htmx = {"HX-Request": "true"}
    assert "saved" in flow.c.post(f"/probes/{n}", data=form, headers=htmx).text
    assert ok(flow.c.get(f"/api/probes/{n}"))["lobing"] == record["lobing"]        # saved as shown: kept
    form["trigger.X+"] = f"{record['trigger']['X+'] - 0.001:.4f}"
    assert "saved" in flow.c.post(f"/probes/{n}", data=form, headers=htmx).text
    assert ok(flow.c.get(f"/api/probes/{n}"))["lobing"] is None                    # typed: the map no longer agrees

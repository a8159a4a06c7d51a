"""N-point circle fits (design.md §10.2, issue 28 item 3): ``params.points`` / ``params.angles``
on hole.*, spigot.* and probe.radius, against the scenario's truth.

Each circle is then probed along N diameters from the centre the manual's first pass found and
fitted by geometric least squares (engine.fit.fit_circle: objective Σ(|p − u| − R)², at least 3
points); ``residuals`` and ``form_error`` come with the result and ``max_form_error`` refuses
the write. Truth: the hole's centre from the scenario pose (truthkit), never the product's output.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from truthkit import HOLE_D, HOLES, SPIGOT_D, SPIGOT_H, SPIGOTS, Operator, scenario

DEPTH = -8.0


def operator(client, kind: str = "holes", noise: float = 0.0, seed: int = 3) -> Operator:
    data = scenario(rot=(0.0, 0.0, 4.0), kind=kind)
    data["probe"]["noise_sigma"] = noise
    data["seed"] = seed
    op = Operator(client, data)
    op.load()
    pose = data["workpiece"]["pose"]
    op.put_offset("G54", rot=pose["rot"], trans=pose["trans"])      # WCS = part coordinates
    op.activate("G54")
    return op


@pytest.mark.parametrize("extra", [{"points": 7}, {"points": 3}, {"angles": [10.0, 100.0, 175.0, 260.0, 300.0]}])
def test_hole_from_n_touches_is_the_true_hole(client, extra):
    op = operator(client)
    op.ball_to_part(HOLES[0][0] + 0.4, HOLES[0][1] - 0.3, DEPTH)
    answer = op.start(op.create("hole.1", {"diameter": HOLE_D, **extra}, "measure_only")["id"])
    result = answer["result"]
    n = extra.get("points") or len(extra["angles"])
    assert result["center"] == {"X": pytest.approx(HOLES[0][0], abs=1e-6), "Y": pytest.approx(HOLES[0][1], abs=1e-6)}
    assert result["diameter"] == pytest.approx(HOLE_D, abs=1e-6)
    assert len(result["residuals"]) == n == result["touches"]
    assert result["form_error"] == pytest.approx(0.0, abs=1e-6)
    touches = answer["point"]["point"]["touches"] if "touches" in answer["point"].get("point", {}) else None
    if touches is not None:
        assert len(touches) == n


def test_spigot_from_six_touches(client):
    op = operator(client, kind="spigots")
    c = SPIGOTS[1]
    op.ball_to_part(c[0] - 0.3, c[1] + 0.2, SPIGOT_H + 4.0)
    result = op.start(op.create("spigot.1", {"diameter": SPIGOT_D, "infeed": 10.0, "points": 6},
                                "measure_only")["id"])["result"]
    assert [result["center"]["X"], result["center"]["Y"]] == pytest.approx(list(c), abs=1e-6)
    assert result["diameter"] == pytest.approx(SPIGOT_D, abs=1e-6) and len(result["residuals"]) == 6


def test_three_holes_each_from_five_touches(client):
    op = operator(client)
    session = op.create("hole.3", {"diameter": HOLE_D, "points": 5}, "measure_only")
    assert len(session["points"]) == 3                     # still P1..P3: the points are per circle
    answer = None
    for hole in HOLES[:3]:
        op.ball_to_part(hole[0] + 0.2, hole[1] + 0.1, DEPTH)
        answer = op.start(session["id"])
    result = op.calculate(session["id"])["result"]
    assert answer is not None
    truth = np.array(HOLES[:3])          # circumcentre of the three hole centres (right angle at P2)
    centre = (truth[0] + truth[2]) / 2.0
    assert [result["center"]["X"], result["center"]["Y"]] == pytest.approx(list(centre), abs=1e-6)
    assert len(result["form_errors"]) == 3 and result["form_error"] == pytest.approx(0.0, abs=1e-6)


def test_max_form_error_refuses_a_noisy_circle_and_keeps_the_measurement(client):
    op = operator(client, noise=0.004)
    op.ball_to_part(HOLES[0][0], HOLES[0][1], DEPTH)
    before = op.offset("G54")
    body = op.start(op.create("hole.1", {"diameter": HOLE_D, "points": 12, "max_form_error": 0.001}, "G54")["id"],
                    status=409)
    assert body["error"]["code"] == "form_error"
    assert body["error"]["result"]["form_error"] > 0.001 and len(body["error"]["result"]["residuals"]) == 12
    assert op.offset("G54") == before


@pytest.mark.parametrize("params, field", [({"points": 2}, "points"), ({"points": 37}, "points"),
                                           ({"points": True}, "points"), ({"angles": [0, 10, 20]}, "angles"),
                                           ({"angles": [0, 120, 240], "points": 4}, "points")])
def test_bad_circle_points_are_refused_naming_the_field(client, params, field):
    op = operator(client)
    body = op.ok(op.c.post("/api/measure", json={"task": "hole.1", "params": {"diameter": 12.0, **params}}), 400)
    assert body["error"]["field"] == field


def centre_error(client, n: int, seeds) -> float:
    """RMS distance of the fitted centre from the true one over ``seeds`` (noise 2 µm per touch)."""
    errors = []
    for seed in seeds:
        op = operator(client, noise=0.002, seed=seed)
        op.ball_to_part(HOLES[0][0], HOLES[0][1], DEPTH)
        c = op.start(op.create("hole.1", {"diameter": HOLE_D, "points": n}, "measure_only")["id"])["result"]["center"]
        errors.append(math.hypot(c["X"] - HOLES[0][0], c["Y"] - HOLES[0][1]))
    return float(np.sqrt(np.mean(np.square(errors))))


def test_the_centre_error_shrinks_with_more_touches(client):
    """σ_centre = σ·√(2/N) for N evenly spaced touches: 16 touches halve the error of 4 (the
    bench bench/bench_circle_points.py prints the curve over N)."""
    seeds = range(10, 22)
    few, many = centre_error(client, 4, seeds), centre_error(client, 16, seeds)
    assert many < 0.75 * few, (few, many)


def test_ring_calibration_with_points_probes_that_many_directions(client):
    """probe.radius ``points`` = the directions of each spindle pass (engine.lobing map above 4):
    the ideal probe's trigger values are ∓r in every axis direction, the effective Ø the ball's."""
    op = operator(client)
    ring = op.scen["ring_gauge"]
    op.ball_to([ring["center"][0] + 0.3, ring["center"][1] - 0.2, ring["center"][2] - 10.0])
    session = op.create("probe.radius", {"diameter": ring["diameter"], "points": 8})
    assert session["params"]["directions"] == 8
    probe = op.start(session["id"])["result"]["probe"]
    assert probe["effective_diameter"] == pytest.approx(4.0, abs=1e-6)
    for key in ("X+", "Y+"):
        assert probe["trigger"][key] == pytest.approx(-2.0, abs=1e-6)
    for key in ("X-", "Y-"):
        assert probe["trigger"][key] == pytest.approx(2.0, abs=1e-6)

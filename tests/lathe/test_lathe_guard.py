"""The start guard on the lathe (issue 24 §1, §2): the workpiece probe's tasks are checked against
the lathe's model of its work space (the part, the chuck, the reference grooves, the tool probe):
each runs from a start just above the feature (measured, the truth of turning.md §10.2) and from
the far side of the turning centre (refused before anything moves, never a collision). Tool
measuring on the lathe is not checked for collisions (the HMI has no model of the cutter around
the tool probe): NC Start says so and its positioning moves are ``unknown`` (no silent pass).
The probe's own reach (measuring-math §1.3) is checked for every task: a measuring feed whose
braking would push the tool probe beyond its permissible deflection (1 mm in turning.md §10.2's
scenario) is refused before motion.

Truth: the scenario's machine data (latency 0 s, deceleration 1 m/s², Kv 1 (m/min)/mm, the lathe
scenario's defaults) in the formula worked by hand, and the simulator, which with the guard off
pushes the tool probe beyond its deflection (a collision) at the same feed."""

from __future__ import annotations

import pytest
from lathe_kit import Lathe, make_client

TOOL_PROBE_LIMIT = 1.0


def braking_by_hand(feed_mm_min: float, t: float = 0.0, a: float = 1.0, kv: float = 1.0) -> float:
    """s_b = 1000·v·t + 1000·v²/(2a) + v[m/min]/Kv, v in m/s."""
    v = feed_mm_min / 60000.0
    return 1000.0 * v * t + 1000.0 * v * v / (2.0 * a) + (feed_mm_min / 1000.0) / kv


@pytest.fixture
def lathe(tmp_path):
    with make_client(tmp_path) as client:
        yield Lathe(client)


def _tool_in_front_of_the_probe(lathe: Lathe) -> None:
    """As test_lathe_api's incremental variant: T3's nose 30 mm above the tool probe's X- face."""
    lathe.tool(3)
    lathe.tip_to(3, 430.0, 208.0)


def _calibrated_tool_probe(lathe: Lathe) -> None:
    """test_lathe_api's 1-C: the X- face calibrated with T7 at the default feed."""
    lathe.tool(7)
    lathe.tip_to(7, 430.0, 205.0)
    answer = lathe.task("lathe.toolprobe.calibrate", {"axis": "X", "incremental": True, "direction": "-",
                                                      "measuring_path": 20})
    assert answer["result"]["trigger"]["X-"] == pytest.approx(400.25, abs=1e-9)


def _stored(lathe: Lathe) -> dict:
    return {"tool": lathe.ok(lathe.c.get("/api/tools/3")), "log": lathe.ok(lathe.c.get("/api/log")),
            "tool_probe": lathe.ok(lathe.c.get("/api/tool-probes/1"))}


MEASURE = {"axis": "X", "incremental": True, "direction": "-", "measuring_path": 20}


def test_a_feed_beyond_the_tool_probes_deflection_is_refused_before_motion(lathe):
    feed = 1200.0                     # 0.02 m/s: 0.2 mm + 1.2 mm = 1.4 mm > 1 mm
    assert braking_by_hand(feed) == pytest.approx(1.4, abs=1e-12)
    _tool_in_front_of_the_probe(lathe)
    before, data = lathe.status(), _stored(lathe)
    session = lathe.ok(lathe.c.post("/api/measure", json={"task": "lathe.tool.measure",
                                                          "params": {**MEASURE, "feed": feed}}))
    plan = lathe.ok(lathe.c.get(f"/api/measure/{session['id']}/plan"))
    assert plan["verdict"] == "refused"
    answer = lathe.c.post(f"/api/measure/{session['id']}/start", json={})
    assert answer.status_code == 409, answer.text
    error = answer.json()["error"]
    assert error["code"] == "guard" and error["alarm"]["code"] == 65302
    segment = error["segment"]
    assert segment["kind"] == "probe" and segment["verdict"] == "overtravel"
    assert segment["braking"] == pytest.approx(braking_by_hand(feed), abs=1e-9)
    assert segment["max_deflection"] == TOOL_PROBE_LIMIT
    after = lathe.status()
    assert after["mcs"] == before["mcs"] and not after["alarms"] and not after["busy"]
    assert _stored(lathe) == data


def test_the_simulator_agrees_with_the_guard_off(lathe):
    _tool_in_front_of_the_probe(lathe)
    session = lathe.ok(lathe.c.post("/api/measure", json={"task": "lathe.tool.measure",
                                                          "params": {**MEASURE, "feed": 1200.0, "guard": False}}))
    answer = lathe.c.post(f"/api/measure/{session['id']}/start", json={})
    assert answer.status_code == 409 and "61302" in answer.json()["error"]["message"], answer.text


def test_a_feed_within_the_deflection_measures_and_says_what_is_not_checked(lathe):
    feed = 600.0                      # 0.01 m/s: 0.05 mm + 0.6 mm = 0.65 mm < 1 mm
    assert braking_by_hand(feed) == pytest.approx(0.65, abs=1e-12)
    _calibrated_tool_probe(lathe)
    _tool_in_front_of_the_probe(lathe)
    session = lathe.ok(lathe.c.post("/api/measure", json={"task": "lathe.tool.measure",
                                                          "params": {**MEASURE, "feed": feed}}))
    plan = lathe.ok(lathe.c.get(f"/api/measure/{session['id']}/plan"))
    assert plan["verdict"] == "unknown"                       # no model of the lathe's work space
    assert all(s["verdict"] == "unknown" for s in plan["segments"])
    probe = [s for s in plan["segments"] if s["kind"] == "probe"][0]
    assert probe["braking"] == pytest.approx(0.65, abs=1e-9)
    answer = lathe.ok(lathe.c.post(f"/api/measure/{session['id']}/start", json={}))
    assert any(w.startswith("Start guard: tool measuring is not checked for collisions") for w in answer["warnings"])
    assert answer["result"]["length"]["L1"]["actual"] == pytest.approx(100.70, abs=1e-9)     # the true L1 of T3


# --- safe approaches: from just above the feature and from the far side ------------------------------

SHAFT_D, ECCENTRICITY_X = 45.006, 0.030          # the scenario's shaft, clamped 0.030 off centre in X
BALL_R = 3.0                                     # the probe's nominal ball (Ø6)
ABOVE_D = SHAFT_D + 2 * (BALL_R + 1.0)           # ball 1 mm above the shaft (a diameter, DIAMON)

# task, params, start (WCS: X a diameter, Z), outcome: the measured value, "guard" (the start guard
# refuses) or an alarm number (the cycle refuses before motion)
SAFE_CASES = {
    "point-X-above": ("lathe.point", {"axis": "X", "setpoint": 45, "measuring_path": 2}, (ABOVE_D, 30.0),
                      # at SPOS 0 the single point reads the diameter plus twice the X eccentricity (5-C)
                      SHAFT_D + 2 * ECCENTRICITY_X),
    # straight through the shaft to its far side: the start guard refuses it
    "point-X-far-side": ("lathe.point", {"axis": "X", "setpoint": 45, "measuring_path": 2}, (-ABOVE_D, 30.0),
                         "guard"),
    "point-Z-above": ("lathe.point", {"axis": "Z", "setpoint": 60, "measuring_path": 2}, (40.0, 60.0 + BALL_R + 1.0),
                      60.0),                     # the face at Z 60, the probe over the ring between bore and OD
    "two-point-above": ("lathe.two_point", {"axis": "X", "setpoint": 45, "zone": {"Z": 70, "X": 60},
                                            "measuring_path": 2}, (ABOVE_D, 30.0), SHAFT_D),
    # CYCLE994 itself refuses a start on the side of its second point (turning.md §6.3)
    "two-point-far-side": ("lathe.two_point", {"axis": "X", "setpoint": 45, "zone": {"Z": 70, "X": 60},
                                               "measuring_path": 2}, (-ABOVE_D, 30.0), "61307"),
}


def _probe_to(lathe: Lathe, x_diameter: float, z: float) -> None:
    """Around the part: retract, out beyond its end face (Z 80), across, then along Z to the start."""
    lathe.retract()
    lathe.goto(coords="WCS", Z=80.0)
    lathe.goto(coords="WCS", X=x_diameter)
    lathe.goto(coords="WCS", Z=z)


@pytest.mark.parametrize("case", sorted(SAFE_CASES))
def test_lathe_tasks_from_above_and_from_the_far_side(lathe, case):
    task, params, (x, z), outcome = SAFE_CASES[case]
    lathe.calibrate_probe_in_groove()
    _probe_to(lathe, x, z)
    before, log = lathe.status(), lathe.ok(lathe.c.get("/api/log"))
    session = lathe.ok(lathe.c.post("/api/measure", json={"task": task, "params": params}))
    answer = lathe.c.post(f"/api/measure/{session['id']}/start", json={})
    state = lathe.status()
    assert all(a["code"] != 61302 for a in state["alarms"]), state["alarms"]         # never a collision
    if isinstance(outcome, str):
        assert answer.status_code == 409, answer.text
        error = answer.json()["error"]
        assert error["code"] == "guard" if outcome == "guard" else outcome in error["message"], error
        if outcome == "guard":       # where it would touch: the shaft's far side (its axis 0.030 off in X), a radius
            assert f"X{-(SHAFT_D / 2 - ECCENTRICITY_X + BALL_R):.3f} " in error["message"], error
            assert "(WCS, X a radius)" in error["message"], error
        assert state["mcs"] == before["mcs"] and not state["busy"]                    # nothing moved
        if outcome == "guard":
            assert lathe.ok(lathe.c.get("/api/log")) == log                           # nothing logged
        return
    assert answer.status_code == 200, answer.text
    result = answer.json()["result"]
    assert result.get("diameter", result["actual"]) == pytest.approx(outcome, abs=1e-6)


# --- property: on the lathe too the guard refuses exactly what the simulator collides on ------------

LATHE_COUNTS: dict[str, dict[str, int]] = {}


def _random_start(rng, case: str) -> tuple[str, dict, float, float]:
    if case == "X":          # above or below the turning centre, over the shaft
        side = 1.0 if rng.uniform() < 0.5 else -1.0
        return "lathe.point", {"axis": "X", "setpoint": 45, "measuring_path": 2}, \
            side * float(rng.uniform(ABOVE_D, ABOVE_D + 20.0)), float(rng.uniform(15.0, 55.0))
    # Z: in front of the face, anywhere from inside the bore to beyond the outer diameter
    return "lathe.point", {"axis": "Z", "setpoint": 60, "measuring_path": 2}, \
        float(rng.uniform(5.0, 70.0)), float(rng.uniform(60.0 + BALL_R + 0.5, 75.0))


@pytest.mark.parametrize("case", ["X", "Z"])
def test_lathe_guard_refuses_exactly_what_the_simulator_collides_on(lathe, case):
    import numpy as np
    from lathe_kit import LATHE_SCENARIO

    rng = np.random.default_rng(24 + ord(case))
    counts = LATHE_COUNTS.setdefault(case, {"refused": 0, "agreed": 0, "trials": 0})
    for _ in range(10):
        task, params, x, z = _random_start(rng, case)
        lathe.ok(lathe.c.post("/api/sim/scenario", json=LATHE_SCENARIO))     # a fresh machine (no broken probe)
        lathe.calibrate_probe_in_groove()
        _probe_to(lathe, x, z)
        session = lathe.ok(lathe.c.post("/api/measure", json={"task": task, "params": {**params, "guard": False}}))
        plan = lathe.ok(lathe.c.get(f"/api/measure/{session['id']}/plan"))
        refused = plan["verdict"] == "refused"
        answer = lathe.c.post(f"/api/measure/{session['id']}/start", json={})
        collided = answer.status_code == 409 and "61302" in answer.json()["error"]["message"]
        counts["trials"] += 1
        counts["refused"] += int(refused)
        assert refused == collided, (task, params, x, z, plan, answer.text)
        counts["agreed"] += 1
    print(f"lathe start guard {case}: {counts}")

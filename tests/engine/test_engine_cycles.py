"""engine.cycles against the worked examples of measuring-math §10.1 (10-A), §13.2 (13-A) and
§13.3 (13.3-A, 13.3-B), and against analytic spheres/circles (contacts computed here)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from engine.cycles import (
    SpherePoint,
    angle_circle_program,
    angle_line_program,
    cycle119,
    evaluate_sphere,
    reframed,
    sphere_program,
)
from engine.frames import Frame, rot_z
from engine.plan_base import PlanContext
from engine.planes import PLANES
from engine.types import EdgePoint, Latch, MoveStep, ProbeRecord, ProbeStep

G17 = PLANES["G17"]
TRIG = {"X-": 2.990, "X+": -2.990, "Y-": 2.990, "Y+": -2.990, "Z-": 2.990}


def ctx_for(probe: ProbeRecord, fa: float = 5.0) -> PlanContext:
    return PlanContext(plane=G17, probe_record=probe, skew_wcs=np.zeros(3), measuring_path=fa)


def drive(program, latch_of):
    """Run a program: every probe step answered by ``latch_of(position, step)`` (the rec)."""
    pos = None
    reply = None
    probes = []
    try:
        while True:
            step = program.send(reply)
            reply = None
            if isinstance(step, MoveStep):
                pos = np.asarray(step.target, float)
            elif isinstance(step, ProbeStep):
                rec = latch_of(pos, step)
                probes.append((pos.copy(), step))
                pos = np.asarray(rec, float)
                reply = Latch(triggered=True, rec=pos.copy())
    except StopIteration as done:
        return done.value, probes


def test_worked_example_13a_paraxial_sphere():
    probe = ProbeRecord(ball_diameter=6.0, effective_diameter=5.98, trigger=TRIG)
    latched = iter([72.814, 128.786, 71.713, 127.687, 128.390])

    def latch(pos, step):
        rec = pos.copy()
        axis = int(np.argmax(np.abs(step.direction)))
        rec[axis] = next(latched)
        return rec

    start = np.array([100.0, 100.0, 160.0])
    params = {"center": (100.0, 100.0, 100.0), "diameter": 50.0}
    point, probes = drive(sphere_program(params, start, ctx_for(probe), "S"), latch)
    assert [tuple(np.sign(s.direction).astype(int)) for _, s in probes] == [
        (1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, -1)]
    assert point.center == pytest.approx([100.8, 99.7, 100.4], abs=1e-9)
    assert point.diameter == pytest.approx(50.0)
    # P3/P4 pass through the found a-centre, P5 above the found centre
    assert probes[2][0][0] == pytest.approx(100.8) and probes[4][0][:2] == pytest.approx([100.8, 99.7])


def test_worked_example_13a_with_diameter_determination():
    probe = ProbeRecord(ball_diameter=6.0, effective_diameter=5.98, trigger=TRIG)
    latched = iter([72.814, 128.786, 71.713, 127.687, 128.405, 72.795004])

    def latch(pos, step):
        rec = pos.copy()
        rec[int(np.argmax(np.abs(step.direction)))] = next(latched)
        return rec

    params = {"center": (100.0, 100.0, 100.0), "diameter": 50.0, "determine": True, "refine": False}
    point, probes = drive(sphere_program(params, np.array([100.0, 100.0, 160.0]), ctx_for(probe), "S"), latch)
    assert probes[5][0][2] == pytest.approx(125.415 - 25.0)        # P6 at p = z_top − R_n
    assert point.diameter / 2 == pytest.approx(25.014996, abs=1e-9)     # D_act = 50.030
    assert point.center[2] == pytest.approx(125.415 - 25.014996, abs=1e-9)   # cp = 100.400


def sphere_contact(centre, radius):
    """Ball (radius r) centre switching on a sphere: first point along the ray at |c − C| = R + r."""
    def latch(pos, step, r=3.0):
        d = np.asarray(step.direction, float)
        w = pos - centre
        b = float(w @ d)
        c = float(w @ w) - (radius + r) ** 2
        disc = b * b - c
        assert disc >= 0.0, "the probing move misses the sphere"
        s = -b - math.sqrt(disc)
        assert 0.0 <= s <= step.distance
        return pos + s * d
    return latch


@pytest.mark.parametrize("angle", [False, True])
@pytest.mark.parametrize("determine", [False, True])
def test_sphere_against_an_analytic_sphere(angle, determine):
    probe = ProbeRecord(ball_diameter=6.0)                   # ideal: t = ∓3
    true_c, true_d = np.array([100.37, 99.62, 100.41]), 50.0 + (0.06 if determine else 0.0)
    params = {"center": (100.0, 100.0, 100.0), "diameter": 50.0, "angle": angle, "start_angle": 10.0,
              "increment": 120.0, "points": 3, "determine": determine}
    point, _ = drive(sphere_program(params, np.array([100.0, 100.0, 150.0]), ctx_for(probe), "S"),
                     sphere_contact(true_c, true_d / 2))
    assert point.center == pytest.approx(true_c, abs=1e-9)
    if determine:
        assert point.diameter == pytest.approx(true_d, abs=1e-9)


def test_evaluate_sphere_is_the_programs_evaluation():
    probe = ProbeRecord(ball_diameter=6.0)
    point, _ = drive(sphere_program({"center": (0, 0, 0), "diameter": 30.0}, np.array([0.0, 0.0, 40.0]),
                                    ctx_for(probe), "S"), sphere_contact(np.array([0.1, -0.2, 0.3]), 15.0))
    centre, diameter = evaluate_sphere(SpherePoint(point.kind, 30.0, False, point.touches, np.zeros(3), 0.0), G17)
    assert centre == pytest.approx(point.center) and diameter == pytest.approx(30.0)


def test_worked_example_10a_bore_at_an_angle():
    probe = ProbeRecord(ball_diameter=6.0, effective_diameter=5.98)
    recs = iter([np.array([239.931286, 16.058540, 0.0]), np.array([174.595184, 61.777332, 0.0]),
                 np.array([118.227195, 5.404420, 0.0])])
    params = {"center": (180.0, 0.0), "diameter": 130.0, "start_angle": 15.0, "increment": 80.0,
              "points": 3, "inner": True}
    point, probes = drive(angle_circle_program(params, np.array([180.0, 0.0, 0.0]), ctx_for(probe, 1.0), "B"),
                          lambda pos, step: next(recs))
    for (_pos, step), theta in zip(probes, (15.0, 95.0, 175.0), strict=True):
        assert step.direction[:2] == pytest.approx([math.cos(math.radians(theta)), math.sin(math.radians(theta))])
    from engine.evaluate import circle_from_touches
    centre, diameter = circle_from_touches(point.touches, G17, "hole", probe)
    assert centre[:2] == pytest.approx([180.020, -0.015], abs=1e-5)
    assert diameter == pytest.approx(130.040, abs=1e-5)


def test_worked_examples_13_3():
    s = [(10, 0, 0), (0, 20, 0), (0, 0, 30)]
    fit = cycle119(s, [(11, 0, 0), (1, 20, 0), (1, 0, 30)])
    assert fit.translation == pytest.approx([1, 0, 0]) and fit.rotation == pytest.approx(np.eye(3))
    assert fit.residual == pytest.approx(0.0, abs=1e-12)
    m = [rot_z(1.0) @ np.array(p, float) + np.array([0.5, -0.2, 0.1]) for p in s]
    fit = cycle119(s, m)
    assert fit.rotation == pytest.approx(rot_z(1.0), abs=1e-12)
    assert fit.translation == pytest.approx([0.5, -0.2, 0.1], abs=1e-12)
    m[2] = m[2] + np.array([0.0, 0.0, 0.012])
    fit = cycle119(s, m)
    from engine.frames import rpy_from_matrix
    assert rpy_from_matrix(fit.rotation) == pytest.approx([-0.005511, 0.004258, 0.999098], abs=1e-6)
    assert fit.translation == pytest.approx([0.499168, -0.200924, 0.104889], abs=1e-6)
    assert fit.residual == pytest.approx(0.015020, abs=1e-6)


def test_reframed_target_reads_the_setpoints():
    g54 = Frame(coarse=(100.0, 50.0, -20.0), rot=(0.0, 0.0, 3.0))
    s = np.array([(10, 0, 0), (0, 20, 0), (0, 0, 30)], float)
    true = Frame(coarse=(100.4, 49.8, -19.9), rot=(0.1, -0.2, 4.0))          # where the part really is
    m = np.array([g54.parent2child(true.child2parent(p)) for p in s])       # measured in the old G54
    new = reframed(cycle119(s, m), target_frame=g54, target_parent2bcs=Frame(), meas2bcs=g54)
    assert new.isclose(true, 1e-9)


def clearance(a, b, centre) -> float:
    """Smallest distance of the segment a→b from ``centre`` (analytic)."""
    a, b, centre = (np.asarray(v, float) for v in (a, b, centre))
    ab = b - a
    t = 0.0 if not ab.any() else float(np.clip((centre - a) @ ab / (ab @ ab), 0.0, 1.0))
    return float(np.linalg.norm(a + t * ab - centre))


@pytest.mark.parametrize("angle", [False, True])
@pytest.mark.parametrize("offset", [(0.0, 0.0), (30.0, -20.0), (-60.0, 10.0), (3.0, 0.5)])
@pytest.mark.parametrize("height", [33.0, 38.0, 50.0, 60.0, 200.0])
def test_sphere_positioning_never_enters_the_sphere(angle, offset, height):
    """Issue 24 item 2: from any start above the sphere (also the start height at or above the
    safe height, where the crossing used to be skipped), every positioning move of the ball stays
    outside the sphere + ball radius; only the probing moves reach it."""
    probe = ProbeRecord(ball_diameter=6.0)
    true_c = np.array([100.1, 99.9, 100.05])
    start = np.array([100.0 + offset[0], 100.0 + offset[1], 100.0 + height])
    params = {"center": (100.0, 100.0, 100.0), "diameter": 50.0, "angle": angle, "start_angle": 10.0,
              "increment": 120.0, "points": 3, "determine": True}
    program = sphere_program(params, start, ctx_for(probe), "S")
    contact = sphere_contact(true_c, 25.0)
    pos, reply, moves = start, None, 0
    try:
        while True:
            step = program.send(reply)
            reply = None
            if isinstance(step, MoveStep):
                target = np.asarray(step.target, float)
                assert clearance(pos, target, true_c) >= 25.0 + 3.0 - 1e-9, f"{step.label} cuts the sphere"
                pos, moves = target, moves + 1
            elif isinstance(step, ProbeStep):
                pos = contact(pos, step)
                reply = Latch(triggered=True, rec=pos.copy())
    except StopIteration as done:
        assert done.value.center == pytest.approx(true_c, abs=1e-9)
    assert moves > 0


def wall_contact(cp, u, along, rho):
    """Ball (radius ``rho``) centre switching on the wall at ``along`` from ``cp`` on the line û:
    the centre stops ``rho`` before it, on the side it comes from."""
    def latch(pos, step):
        d = np.asarray(step.direction, float)
        travel = float(d @ u)
        s = (along - rho * math.copysign(1.0, travel) - float((pos - cp) @ u)) / travel
        assert 0.0 <= s <= step.distance, "the probing move misses the wall"
        return pos + s * d
    return latch


@pytest.mark.parametrize(("inner", "angle", "width", "along"), [
    (True, 70.0, 130.01, 0.3),        # the §5.6.3 slot
    (False, 25.0, 39.98, 0.15),       # a web
    (True, -200.0, 20.02, -0.4),
])
def test_slot_and_web_at_an_angle_against_analytic_walls(inner, angle, width, along):
    """measuring-math §10.2: touches along ±û on the line through CP; W and the centre's component
    along û of walls placed here (an ideal ball, ρ = 3, _FA = 2)."""
    from engine.evaluate import distance_along_line
    probe = ProbeRecord(ball_diameter=6.0)
    fa, lift = 2.0, 30.0
    cp = np.array([150.0, 130.0, 40.0])
    u = np.array([math.cos(math.radians(angle)), math.sin(math.radians(angle)), 0.0])
    plan = {"center": (150.0, 130.0), "width": round(width), "start_angle": angle, "inner": inner, "lift": lift}
    start = cp + (0.0 if inner else round(width) / 2 + 8.0) * u
    walls = (along + width / 2, along - width / 2)              # the +û and the −û wall
    touches, probes, starts = [], [], []
    for n, wall in zip((1, 2), walls, strict=True):
        point, steps = drive(angle_line_program(plan, n, start, ctx_for(probe, fa), f"P{n}"),
                             wall_contact(cp, u, wall, 3.0))
        assert isinstance(point, EdgePoint)
        touches.append(point.touch)
        probes.extend(steps)
        starts.append(steps[0][0])
        start = starts[-1]                                       # each point ends at its P'
    signs = (1.0, -1.0) if inner else (-1.0, 1.0)               # slot P1 +û, P2 −û; web P1 −û, P2 +û
    for (_pos, step), sign in zip(probes, signs, strict=True):
        assert step.direction == pytest.approx(sign * u)
    reach = round(width) / 2 + (-3.0 - fa if inner else 3.0 + fa)
    assert starts[0] == pytest.approx(cp + reach * u) and starts[1] == pytest.approx(cp - reach * u)
    params = {"line_angle": angle, "setpoint": {"X": 150.0, "Y": 130.0}, "axis": "X"}
    result = distance_along_line("edge.distance", params, touches[0], touches[1], G17)
    assert result.values["distance"] == pytest.approx(width, abs=1e-9)
    centre = cp + along * u
    assert [result.values["center"][a] for a in "XY"] == pytest.approx(list(centre[:2]), abs=1e-9)
    assert result.fix.position == pytest.approx(result.values["center"])


def test_web_at_an_angle_crosses_over_at_the_lift():
    """The web's P2 (measuring-math §10.2, manual §5.6.1): up by _ID, over to P2', down."""
    probe = ProbeRecord(ball_diameter=6.0)
    plan = {"center": (0.0, 0.0), "width": 40.0, "start_angle": 90.0, "inner": False, "lift": 50.0}
    program = angle_line_program(plan, 2, np.array([0.0, 25.0, 10.0]), ctx_for(probe, 2.0), "P2")
    moves = []
    step = program.send(None)
    while isinstance(step, MoveStep):
        moves.append(np.asarray(step.target, float))
        step = program.send(None)
    assert moves == [pytest.approx([0.0, 25.0, 60.0]), pytest.approx([0.0, -25.0, 60.0]),
                     pytest.approx([0.0, -25.0, 10.0])]
    assert isinstance(step, ProbeStep) and step.direction == pytest.approx([0.0, 1.0, 0.0])

"""engine.plan: point programs driven against an analytic world (tests/engine/test_plan_world.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_plan_world import Bore, HalfSpace, Spigot, World, drive

from engine.plan import (
    TASK_POINTS,
    ParamError,
    PlanContext,
    RingCalibrationPoint,
    planned_path,
    point_program,
    validate_params,
)
from engine.planes import PLANES
from engine.types import (
    CirclePoint,
    EdgePoint,
    Latch,
    MeasuringError,
    MoveStep,
    ProbeRecord,
    ProbeStep,
    RectPoint,
)

R_BALL = 2.0
PRE = {"X+": 0.004, "X-": 0.005, "Y+": 0.003, "Y-": 0.006, "Z+": 0.001, "Z-": 0.002}
SKEW = np.array([0.010, -0.006, 0.0])


def calibrated_probe() -> ProbeRecord:
    """Trigger values matching the world's pre-travel: t(−) = r − δ, t(+) = −(r − δ) (math §5.1)."""
    trig = {k: (R_BALL - v if k.endswith("-") else -(R_BALL - v)) for k, v in PRE.items()}
    return ProbeRecord(ball_diameter=2 * R_BALL, effective_diameter=2 * R_BALL, trigger=trig,
                       calibrated_radius=True)


def ctx_for(plane="G17", skew=SKEW, **kw) -> PlanContext:
    pl = PLANES[plane]
    skew_wcs = pl.to_xyz(np.array([skew[0], skew[1], 0.0]))   # skew in the plane
    return PlanContext(plane=pl, probe_record=kw.pop("probe", calibrated_probe()), skew_wcs=skew_wcs, **kw)


def world_for(ctx: PlanContext, shapes, pre=PRE, **kw) -> World:
    return World(shapes=shapes, r=R_BALL, skew=np.asarray(ctx.skew_wcs, float), pretravel=dict(pre), **kw)


def run(task, params, n, start, ctx, world):
    params = validate_params(task, params, ctx.plane)
    return drive(point_program(task, params, n, np.asarray(start, float), ctx), start, world)


def probes(steps):
    return [s for s in steps if isinstance(s, ProbeStep)]


# --- validation --------------------------------------------------------------------------------

@pytest.mark.parametrize("task,params,field", [
    ("nope", {}, "task"),
    ("hole.1", {"diameter": 0}, "diameter"),
    ("hole.1", {"diameter": -3}, "diameter"),
    ("spigot.1", {"diameter": 10}, "infeed"),
    ("spigot.1", {"diameter": 10, "infeed": 0}, "infeed"),
    ("spigot.1", {"infeed": 5}, "diameter"),
    ("edge.set", {"axis": "X", "direction": "x"}, "direction"),
    ("edge.set", {"axis": "Q"}, "axis"),
    ("edge.align", {"axis": "Y", "reference_axis": "Y"}, "reference_axis"),
    ("edge.align", {"axis": "Y", "reference_axis": "Z"}, "reference_axis"),
    ("edge.align", {"axis": "Y", "angle_correction": "none"}, "angle_correction"),
    ("hole.3", {"angle_correction": "twist"}, "angle_correction"),
    ("corner.right", {"kind": "round"}, "kind"),
    ("corner.any", {"position": 5}, "position"),
    ("edge.align", {"setpoint_angle": 360}, "setpoint_angle"),
    ("hole.4", {"setpoint_angle": -360.0}, "setpoint_angle"),
    ("hole.1", {"probe_angle": float("nan")}, "probe_angle"),
    ("pocket.rect", {"length": 0}, "length"),
    ("spigot.rect", {"length": 10, "width": -1, "infeed": 3}, "width"),
    ("tool.length", {"offset_v": -0.1}, "offset_v"),
    ("toolprobe.calibrate", {"mode": "radius"}, "mode"),
    ("hole.1", {"setpoint": {"X": "a"}}, "setpoint.X"),
    ("hole.1", {"setpoint": {"Z": 1.0}}, "setpoint.Z"),
    ("edge.set", {"axis": "X", "setpoint": float("inf")}, "setpoint.X"),
    ("probe.radius", {}, "diameter"),
])
def test_validate_errors_name_the_field(task, params, field):
    with pytest.raises(ParamError) as err:
        validate_params(task, params, PLANES["G17"])
    assert err.value.field == field
    assert str(err.value)


def test_validate_defaults_and_normalisation():
    g17, g18 = PLANES["G17"], PLANES["G18"]
    assert validate_params("edge.set", {"axis": "x", "direction": "-", "setpoint": 5}, g17) == \
        {"axis": "X", "direction": "-", "setpoint": {"X": 5.0}}
    assert validate_params("edge.distance", {"axis": "Y"}, g17)["direction_p2"] == "-"
    align = validate_params("edge.align", {"axis": "Y", "angle_correction": "c"}, g17)
    assert align["reference_axis"] == "X" and align["angle_correction"] == "C"
    assert validate_params("hole.2", {"diameter": 8}, g18)["setpoint"] == {"Z": 0.0, "X": 0.0}
    assert validate_params("hole.3", {}, g17)["angle_correction"] == "none"
    assert validate_params("hole.1", {"target": "G55"}, g17)["target"] == "G55"
    assert validate_params("probe.length", {"setpoint": -20}, g17)["setpoint"] == {"Z": -20.0}
    assert validate_params("tool.diameter", {}, g17) == {"offset_v": 0.0, "compensation": "geometry"}
    assert set(TASK_POINTS) >= {"spigot.1", "spigot.2", "spigot.3", "spigot.4"}


# --- edges ---------------------------------------------------------------------------------------

@pytest.mark.parametrize("plane", ["G17", "G18", "G19"])
@pytest.mark.parametrize("axis_i", [0, 1, 2])
@pytest.mark.parametrize("direction", ["+", "-"])
def test_edge_set_reproduces_the_wall(plane, axis_i, direction):
    ctx = ctx_for(plane)
    axis = "XYZ"[axis_i]
    sign = 1.0 if direction == "+" else -1.0
    start = np.array([12.0, -7.0, 30.0])
    wall = start[axis_i] + sign * 23.456           # surface ahead of the start
    n = np.zeros(3)
    n[axis_i] = -sign                              # outward normal faces the probe
    world = world_for(ctx, [HalfSpace(n, float(n @ (wall * np.abs(n))))])
    point, steps = run("edge.set", {"axis": axis, "direction": direction}, 1, start, ctx, world)
    assert isinstance(point, EdgePoint)
    assert point.touch.surface[axis_i] == pytest.approx(wall, abs=1e-9)
    (probe,) = probes(steps)
    assert probe.distance == pytest.approx(2 * ctx.measuring_path) and probe.feed == 300.0
    assert isinstance(steps[-1], MoveStep) and np.allclose(steps[-1].target, start)
    assert steps[-1].feed == 2000.0


def test_edge_two_stage_feeds_and_rapid_return():
    ctx = ctx_for(fast_feed=900.0, rapid_return=True)
    world = world_for(ctx, [HalfSpace(np.array([-1.0, 0, 0]), -40.0)])
    point, steps = run("edge.set", {"axis": "X", "direction": "+"}, 1, [0, 0, 0], ctx, world)
    p1, p2 = probes(steps)
    assert (p1.feed, p2.feed) == (900.0, 300.0) and p2.distance == pytest.approx(4.0)
    retract = steps[steps.index(p1) + 1]
    assert isinstance(retract, MoveStep)
    rec = 40.0 - R_BALL + PRE["X+"] - SKEW[0]
    assert retract.target[0] == pytest.approx(rec - 2.0)
    assert point.touch.surface[0] == pytest.approx(40.0, abs=1e-9)
    assert steps[-1].feed is None                  # _JM_B[2]=1: rapid return


def test_retries_then_61301():
    wall = [HalfSpace(np.array([0, -1.0, 0]), -30.0)]
    ctx = ctx_for(attempts=5)
    world = world_for(ctx, wall, miss=2)
    point, steps = run("edge.set", {"axis": "Y", "direction": "+"}, 1, [0, 0, 0], ctx, world)
    assert len(probes(steps)) == 3 and point.touch.surface[1] == pytest.approx(30.0, abs=1e-9)
    retry = [s for s in steps if isinstance(s, MoveStep) and "retry" in s.label]
    assert len(retry) == 2 and all(np.allclose(s.target, 0) for s in retry)
    for attempts, miss in ((1, 1), (5, 5)):
        ctx = ctx_for(attempts=attempts)
        world = world_for(ctx, wall, miss=miss)
        with pytest.raises(MeasuringError) as err:
            run("edge.set", {"axis": "Y", "direction": "+"}, 1, [0, 0, 0], ctx, world)
        assert err.value.alarm == 61301 and len(world.probes) == attempts


def test_two_stage_miss_in_fine_stage_retries():
    ctx = ctx_for(attempts=2, fast_feed=900.0)
    program = point_program("edge.set", validate_params("edge.set", {"axis": "X"}, ctx.plane), 1,
                            np.zeros(3), ctx)
    step = next(program)
    step = program.send(Latch(True, rec=np.array([37.0, 0, 0])))       # fast touch
    assert isinstance(step, MoveStep)
    step = program.send(None)                                            # fine probe
    assert isinstance(step, ProbeStep) and step.feed == 300.0
    step = program.send(Latch(False))                                    # fine misses -> retry
    assert isinstance(step, MoveStep) and np.allclose(step.target, 0) and "retry" in step.label


# --- corners -------------------------------------------------------------------------------------

EXPECTED_OUTSIDE = {  # position: (P1/P2 direction along 2nd, P3/P4 direction along 1st)
    1: (+1, +1), 2: (+1, -1), 3: (-1, -1), 4: (-1, +1),
}


@pytest.mark.parametrize("plane", ["G17", "G18", "G19"])
@pytest.mark.parametrize("position", [1, 2, 3, 4])
@pytest.mark.parametrize("kind", ["outside", "inside"])
def test_corner_directions(plane, position, kind):
    ctx = ctx_for(plane)
    pl = ctx.plane
    s2, s1 = EXPECTED_OUTSIDE[position]
    if kind == "inside":
        s2, s1 = -s2, -s1
    params = validate_params("corner.any", {"kind": kind, "position": position}, pl)
    for n in (1, 2, 3, 4):
        steps = planned_path("corner.any", params, n, np.zeros(3), ctx)
        (probe,) = probes(steps)
        expected = s2 * pl.unit(pl.second) if n <= 2 else s1 * pl.unit(pl.first)
        np.testing.assert_allclose(probe.direction, expected)


def test_outside_corner_front_left_touches_block():
    """A block [0, 100] x [0, 60]: corner position 1 outside probes +Y at the front, +X at the left."""
    ctx = ctx_for()
    block = [HalfSpace(np.array([0, -1.0, 0]), 0.0), HalfSpace(np.array([-1.0, 0, 0]), 0.0)]
    world = world_for(ctx, block)
    for n, start, axis in ((1, [10, -15, -5], 1), (2, [60, -15, -5], 1), (3, [-15, 20, -5], 0)):
        if n == 3:
            world.shapes = [block[1]]
        else:
            world.shapes = [block[0]]
        point, _ = run("corner.right", {"kind": "outside", "position": 1}, n, start, ctx, world)
        assert point.touch.surface[axis] == pytest.approx(0.0, abs=1e-9)


# --- plane and probe length ------------------------------------------------------------------------

@pytest.mark.parametrize("plane", ["G17", "G18", "G19"])
def test_plane_and_probe_length_probe_minus_infeed(plane):
    ctx = ctx_for(plane)
    pl = ctx.plane
    p = pl.infeed_unit
    world = world_for(ctx, [HalfSpace(p, -12.5)])
    start = 20.0 * p + 3.0 * pl.unit(pl.first)
    point, steps = run("plane.align", {}, 2, start, ctx, world)
    np.testing.assert_allclose(probes(steps)[0].direction, -p)
    assert float(point.touch.surface @ p) == pytest.approx(-12.5, abs=1e-9)
    assert steps[-1].feed == ctx.position_feed_infeed      # pure infeed return: E_MESS_FZ
    point, _ = run("probe.length", {"setpoint": -12.5}, 1, start, ctx, world)
    assert point.touch.latched_mcs is not None
    np.testing.assert_allclose(point.touch.ball_centre, point.touch.latched_mcs)   # raw: no skew
    assert float(point.touch.ball_centre @ p) == pytest.approx(-12.5 + R_BALL - PRE[f"{pl.infeed}-"])


# --- holes, pockets, spigots -------------------------------------------------------------------------

def _circle_truth(plane, centre_ao, p_height):
    pl = PLANES[plane]
    return pl.to_xyz(np.array([centre_ao[0], centre_ao[1], p_height]))


@pytest.mark.parametrize("plane", ["G17", "G18", "G19"])
@pytest.mark.parametrize("diameter", [None, 30.0])
def test_hole_centre_and_diameter_exact(plane, diameter):
    ctx = ctx_for(plane, measuring_path=8.0)
    pl = ctx.plane
    centre = _circle_truth(plane, (40.03, -11.98), -10.0)
    world = world_for(ctx, [Bore(centre, 15.01, pl.infeed_unit)])
    start = centre + 1.7 * pl.unit(pl.first) - 2.3 * pl.unit(pl.second) + 0 * pl.infeed_unit
    params = {} if diameter is None else {"diameter": diameter}
    point, steps = run("hole.1", params, 1, start, ctx, world)
    assert isinstance(point, CirclePoint)
    ao = pl.to_aop(point.center)
    np.testing.assert_allclose(ao[:2], pl.to_aop(centre)[:2], atol=1e-9)
    assert point.diameter == pytest.approx(30.02, abs=1e-9)
    assert len(probes(steps)) == 8 and len(point.touches) == 4
    # 2nd pass: every travel line runs through the true centre (normal incidence)
    for t in point.touches:
        rel = pl.to_aop(t.ball_centre - centre)[:2]
        d = pl.to_aop(t.direction)[:2]
        assert abs(rel[0] * d[1] - rel[1] * d[0]) < 1e-9
    assert np.allclose(steps[-1].target, start)
    if diameter is not None:   # pre-positioned (monitored) E_MESS_D_M before the expected wall
        first = steps[0]
        assert isinstance(first, MoveStep) and first.monitored
        reach = diameter / 2 - R_BALL
        assert probes(steps)[0].expected == pytest.approx(8.0)
        assert np.linalg.norm(first.target - start) == pytest.approx(reach - 8.0)


@settings(max_examples=15, deadline=None)
@given(angle=st.floats(-80, 80), off=st.tuples(st.floats(-3, 3), st.floats(-3, 3)))
def test_hole_at_probing_angle_circle_fit(angle, off):
    probe = ProbeRecord(ball_diameter=4.0, effective_diameter=4.0)
    ctx = ctx_for(probe=probe)
    centre = np.array([5.0, 7.0, -3.0])
    world = world_for(ctx, [Bore(centre, 12.5, np.array([0, 0, 1.0]))], pre={})
    start = centre + np.array([off[0], off[1], 0.0])
    point, steps = run("hole.1", {"diameter": 25, "probe_angle": angle}, 1, start, ctx, world)
    np.testing.assert_allclose(point.center[:2], centre[:2], atol=1e-9)
    assert point.diameter == pytest.approx(25.0, abs=1e-9)
    d0 = probes(steps)[0].direction
    assert math.degrees(math.atan2(d0[1], d0[0])) == pytest.approx(angle)


@pytest.mark.parametrize("plane", ["G17", "G19"])
def test_spigot_path_and_result(plane):
    ctx = ctx_for(plane, spigot_safety=5.0)
    pl = ctx.plane
    p = pl.infeed_unit
    top = 0.0
    centre = _circle_truth(plane, (100.02, 50.01), top)
    radius = 15.0
    world = world_for(ctx, [Spigot(centre, radius, p, top)])
    start = centre + 10.0 * p + 0.8 * pl.unit(pl.first) - 0.5 * pl.unit(pl.second)
    dz = 18.0
    point, steps = run("spigot.1", {"diameter": 30.0, "infeed": dz}, 1, start, ctx, world)
    np.testing.assert_allclose(pl.to_aop(point.center)[:2], pl.to_aop(centre)[:2], atol=1e-9)
    assert point.diameter == pytest.approx(30.0, abs=1e-9)
    h0 = float(start @ p)
    # every probe starts DZ below the start, safety (5) + nominal clearance from the nominal spigot
    for origin, step in world.probes:
        assert float(origin @ p) == pytest.approx(h0 - dz)
        assert step.expected == pytest.approx(5.0)
    # clearance: every move below the top keeps the ball outside the spigot
    for a, b, _ in world.moves:
        for s in np.linspace(0, 1, 21):
            q = a + s * (b - a) + ctx.skew_wcs
            if float(q @ p) < top + R_BALL:
                rel = q - centre
                rel = rel - float(rel @ p) * p
                assert np.linalg.norm(rel) >= radius + R_BALL - 0.01   # retract starts at the latch
    downs = [s for s in steps if isinstance(s, MoveStep) and "down DZ" in s.label]
    assert len(downs) == 8 and all(s.feed == ctx.position_feed_infeed for s in downs)
    assert np.allclose(steps[-1].target, start)


def test_rect_pocket_and_spigot():
    ctx = ctx_for()
    walls = [HalfSpace(np.array([-1.0, 0, 0]), -60.0), HalfSpace(np.array([1.0, 0, 0]), 10.0),
             HalfSpace(np.array([0, -1.0, 0]), -25.0), HalfSpace(np.array([0, 1.0, 0]), -5.0)]
    world = world_for(ctx, walls)
    point, _ = run("pocket.rect", {"length": 50, "width": 30}, 1, [33.0, 12.0, -4.0], ctx, world)
    assert isinstance(point, RectPoint)
    np.testing.assert_allclose(point.center[:2], [35.0, 10.0], atol=1e-9)
    assert (point.length, point.width) == (pytest.approx(50.0, abs=1e-9), pytest.approx(30.0, abs=1e-9))

    class Box:  # outer rectangle [0, 40] x [0, 20], top at z = 0
        def contact(self, c0, d, r):
            if c0[2] >= 0:
                return None
            i = 0 if abs(d[0]) > 0.5 else 1
            lo, hi = (0.0, 40.0) if i == 0 else (0.0, 20.0)
            return (lo - r - c0[i]) / d[i] if d[i] > 0 else (c0[i] - hi - r) / -d[i]

    world = world_for(ctx, [Box()])
    point, steps = run("spigot.rect", {"length": 40, "width": 20, "infeed": 6}, 1, [21.0, 9.0, 5.0], ctx, world)
    np.testing.assert_allclose(point.center[:2], [20.0, 10.0], atol=1e-9)
    assert (point.length, point.width) == (pytest.approx(40.0, abs=1e-9), pytest.approx(20.0, abs=1e-9))
    assert all(o[2] == pytest.approx(-1.0) for o, _ in world.probes)


# --- probe radius calibration --------------------------------------------------------------------

def test_ring_calibration_two_passes_raw():
    probe = ProbeRecord(ball_diameter=4.0)            # never calibrated: no triggers, no skew
    ctx = ctx_for(probe=probe, skew=np.zeros(3), measuring_path=10.0)
    true_skew = np.array([0.012, -0.008, 0.0])
    mp = np.array([600.03, 99.98, -150.0])
    world = World(shapes=[Bore(mp, 12.5, np.array([0, 0, 1.0]))], r=1.99, skew=true_skew,
                  pretravel={"X+": 0.003, "X-": 0.003, "Y+": 0.003, "Y-": 0.003})
    start = mp + np.array([0.9, -0.6, 0.0])
    point, steps = run("probe.radius", {"diameter": 25.0}, 1, start, ctx, world)
    assert isinstance(point, RingCalibrationPoint)
    angles = [s.angle for s in steps if not isinstance(s, MoveStep | ProbeStep)]
    assert angles == [0.0, 180.0, 0.0]
    p180, p0 = point.passes
    assert (p180.spindle_angle, p0.spindle_angle) == (180.0, 0.0)
    assert list(p0.rec) == ["X+", "X-", "Y+", "Y-"]

    def centre(ps):
        return np.array([(ps.rec["X+"][0] + ps.rec["X-"][0]) / 2, (ps.rec["Y+"][1] + ps.rec["Y-"][1]) / 2])
    m180, m0 = centre(p180), centre(p0)
    np.testing.assert_allclose((m0 + m180) / 2, mp[:2], atol=1e-9)          # math §7.3 MP
    np.testing.assert_allclose((m180 - m0) / 2, true_skew[:2], atol=1e-9)   # e
    # pass 2 at normal incidence: trigger = rec + e − S = −(r − δ)
    assert p0.rec["X+"][0] + true_skew[0] - (mp[0] + 12.5) == pytest.approx(-(1.99 - 0.003), abs=1e-9)
    np.testing.assert_allclose(steps[-1].target[:2], m0, atol=1e-12)      # ends on the centre


# --- tool tasks ----------------------------------------------------------------------------------

TP_CENTRE = np.array([700.0, 400.0])
TP_TOP = -200.0
DISC_R = 10.0


def tool_world(tool_r: float) -> World:
    z = np.array([0, 0, 1.0])
    return World(shapes=[HalfSpace(z, TP_TOP, r=0.0),
                         Spigot(np.array([*TP_CENTRE, 0.0]), DISC_R, z, TP_TOP)], r=tool_r)


def tool_ctx(**kw) -> PlanContext:
    tp = {"X-": 710.0, "X+": 690.0, "Y-": 410.0, "Y+": 390.0, "Z-": TP_TOP}
    base = dict(plane=PLANES["G17"], probe_record=None, skew_wcs=np.zeros(3), tool_probe=tp,
                mt_diameter_length=20.0, mt_diameter_radius=20.0)
    base.update(kw)
    return PlanContext(**base)


def test_toolprobe_calibration_length_diameter():
    ctx = tool_ctx(tool_probe=None, tool_radius=5.0, tool_length=100.0)
    world = tool_world(5.0)
    start = np.array([701.3, 399.2, -190.0])
    point, steps = run("toolprobe.calibrate", {"mode": "length_diameter"}, 1, start, ctx, world)
    keys = [t.key for t in point.touches]
    assert keys == ["Z-", "X+", "X-", "Y+", "Y-", "X+", "X-", "Z-"]
    rec = {t.key: t.rec for t in point.touches[1:7]}               # the last touch per key counts
    assert rec["X-"][0] - 5.0 == pytest.approx(TP_CENTRE[0] + DISC_R, abs=1e-9)   # _TP[0]
    assert rec["X+"][0] + 5.0 == pytest.approx(TP_CENTRE[0] - DISC_R, abs=1e-9)   # _TP[1]
    assert rec["Y-"][1] - 5.0 == pytest.approx(TP_CENTRE[1] + DISC_R, abs=1e-9)
    assert point.touches[0].rec[2] == pytest.approx(TP_TOP) and point.touches[-1].rec[2] == pytest.approx(TP_TOP)
    np.testing.assert_allclose(point.touches[-1].rec[:2], TP_CENTRE, atol=1e-9)   # final −Z at centre
    for origin, step in world.probes[1:7]:
        assert origin[2] == pytest.approx(TP_TOP - 2.0)             # E_MESS_MT_DZ below the top
        assert step.feed == 100.0 and step.coords == "MCS"
    assert np.allclose(steps[-1].target, start)
    only = run("toolprobe.calibrate", {}, 1, start, ctx, tool_world(5.0))[0]
    assert [t.key for t in only.touches] == ["Z-"]
    no_x = run("toolprobe.calibrate", {"mode": "length_diameter"}, 1, start,
               tool_ctx(tool_probe=None, tool_radius=5.0, mt_axes=130), tool_world(5.0))[0]
    assert [t.key for t in no_x.touches] == ["Z-", "Y+", "Y-", "Z-"]      # E_MESS_MT_AX: X not probeable


def test_tool_length_stationary_and_rotating():
    ctx = tool_ctx(tool_radius=4.0)                                # 2R = 8 <= DL 20: stationary
    world = tool_world(4.0)
    start = np.array([650.0, 380.0, -150.0])
    point, steps = run("tool.length", {"offset_v": 0.0}, 1, start, ctx, world)
    assert not point.rotating and point.speed == 0.0
    assert point.feeds == (1000.0, 100.0)                          # Q20: min(E_MESS_F, 10·FM), FM
    assert point.touch.rec[2] == pytest.approx(TP_TOP, abs=1e-9)
    assert [p.feed for _, p in world.probes] == [1000.0, 100.0]
    np.testing.assert_allclose(world.probes[0][0][:2], TP_CENTRE)  # centred
    assert world.spindle_speed == 0.0

    ctx = tool_ctx(tool_radius=20.0)                               # 2R = 40 > DL: rotating, offset R − V
    world = tool_world(20.0)
    point, steps = run("tool.length", {"offset_v": 1.5}, 1, start, ctx, world)
    n = min(1000.0, 100.0 / (2 * math.pi * 20.0 * 0.001))
    assert point.rotating and point.speed == pytest.approx(n)
    assert point.feeds == pytest.approx((min(20.0, max(1.0, 10 * n * 0.01)), n * 0.01))
    assert world.probes[0][0][0] == pytest.approx(TP_CENTRE[0] + 18.5)
    speeds = [s.speed for s in steps if type(s).__name__ == "SpindleStep"]
    assert speeds == [pytest.approx(n), 0.0]
    assert point.touch.rec[2] == pytest.approx(TP_TOP, abs=1e-9)


def test_tool_diameter_rotating_from_minus_direction():
    ctx = tool_ctx(tool_radius=6.0, feed_factor2=3.0)
    world = tool_world(6.0)
    start = np.array([740.0, 395.0, -150.0])
    point, steps = run("tool.diameter", {"offset_v": 0.5}, 1, start, ctx, world)
    assert point.touch.key == "X-"
    assert point.touch.rec[0] - 710.0 == pytest.approx(6.0, abs=1e-9)   # R = F_x − _TP[0]
    origin = world.probes[0][0]
    assert origin[2] == pytest.approx(TP_TOP - 2.0 + 0.5)           # DZ below, raised by V
    assert origin[1] == pytest.approx(400.0)                        # centred on the 2nd axis
    n = min(1000.0, 100.0 / (2 * math.pi * 6.0 * 0.001))
    assert point.feeds == pytest.approx((min(20.0, max(1.0, 10 * n * 0.01)), 3 * n * 0.01, n * 0.01))
    assert len(world.probes) == 3
    assert np.allclose(steps[-1].target, start)
    with pytest.raises(MeasuringError) as err:
        run("tool.diameter", {}, 1, start, tool_ctx(tool_radius=0.0), tool_world(6.0))
    assert err.value.alarm == 61351
    with pytest.raises(MeasuringError) as err:
        run("tool.length", {}, 1, start, tool_ctx(tool_probe=None, tool_radius=2.0), tool_world(2.0))
    assert err.value.alarm == 61341


# --- preview -------------------------------------------------------------------------------------

TASK_PARAMS = {
    "edge.set": {"axis": "X"}, "edge.align": {"axis": "Y"}, "edge.distance": {"axis": "X"},
    "corner.right": {}, "corner.any": {"kind": "inside", "position": 3},
    "pocket.rect": {"length": 40, "width": 20}, "hole.1": {"diameter": 20},
    "hole.2": {"diameter": 20}, "hole.3": {}, "hole.4": {"diameter": 20, "probe_angle": 15},
    "spigot.rect": {"length": 40, "width": 20, "infeed": 5},
    "spigot.1": {"diameter": 20, "infeed": 5}, "spigot.2": {"diameter": 20, "infeed": 5},
    "spigot.3": {"diameter": 20, "infeed": 5}, "spigot.4": {"diameter": 20, "infeed": 5},
    "plane.align": {}, "probe.length": {}, "probe.radius": {"diameter": 25},
    "toolprobe.calibrate": {"mode": "length_diameter"}, "tool.length": {}, "tool.diameter": {},
}


@pytest.mark.parametrize("task", sorted(TASK_POINTS))
def test_planned_path_every_task(task):
    ctx = tool_ctx(tool_radius=5.0) if task.split(".")[0] in ("tool", "toolprobe") else ctx_for()
    params = validate_params(task, TASK_PARAMS[task], ctx.plane)
    start = np.array([700.0, 400.0, -150.0])
    for n in range(1, TASK_POINTS[task] + 1):
        steps = planned_path(task, params, n, start, ctx)
        assert probes(steps)
        assert isinstance(steps[-1], MoveStep)
    bare = planned_path("tool.length", {}, 1, start, tool_ctx(tool_probe=None))
    assert bare == []


def test_planned_path_hole_ideal_hits_nominal_wall():
    ctx = ctx_for(skew=np.zeros(3))
    steps = planned_path("hole.1", {"diameter": 20.0, "probe_angle": 0.0}, 1, np.zeros(3), ctx)
    first = probes(steps)[0]
    assert first.expected == pytest.approx(10.0 - R_BALL)      # start at centre, wall at D/2 − ρ


def test_edge_distance_uses_direction_p2_for_p2():
    ctx = ctx_for()
    params = validate_params("edge.distance", {"axis": "X", "direction": "+"}, ctx.plane)
    d1 = probes(planned_path("edge.distance", params, 1, np.zeros(3), ctx))[0].direction
    d2 = probes(planned_path("edge.distance", params, 2, np.zeros(3), ctx))[0].direction
    np.testing.assert_allclose(d1, [1, 0, 0])
    np.testing.assert_allclose(d2, [-1, 0, 0])
    with pytest.raises(ValueError):
        point_program("edge.distance", params, 3, np.zeros(3), ctx)

"""Zero-offset correction (jog-measuring §2.5–§2.9, §4; measuring-math §2.2).

The truth is re-mapped independently: the true feature (point/direction/normal in the measuring
WCS) goes to the BCS through the measuring chain and back into the target's child system
through the *new* target frame; it must read the setpoints.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.correction import Correction, alpha_beta_from_normal, correct
from engine.frames import Frame, FrameChain, rot_axis
from engine.planes import PLANES
from engine.types import FeatureFix, MeasuringError

FAST = settings(max_examples=60, deadline=None)

coord = st.floats(-400.0, 400.0, allow_nan=False)
vec = st.tuples(coord, coord, coord)
fine_vec = st.tuples(*[st.floats(-1.0, 1.0)] * 3)
small_tilt = st.floats(-3.0, 3.0)
heading = st.floats(-179.0, 179.0)


def frame_st(tilt=small_tilt):
    return st.builds(lambda c, f, a, b, g: Frame(coarse=c, fine=f, rot=(a, b, g)),
                     vec, fine_vec, tilt, tilt, heading)


chain_st = st.builds(lambda s, bs, g54: FrameChain(setframe=s, basic=tuple(bs), settable=g54),
                     frame_st(), st.lists(frame_st(), max_size=2), frame_st())
plane_st = st.sampled_from(["G17", "G18", "G19"])
target_kind_st = st.sampled_from(["G54", "G55", "BASIC_REF", "BASIC_0"])


def target_of(kind, chain, other):
    """(name, frame, parent2bcs) as the app would pass them."""
    if kind == "G54":
        return "G54", chain.settable, chain.below_settable
    if kind == "G55":
        return "G55", other, chain.below_settable
    if kind == "BASIC_0" and chain.basic:
        return "BASIC_0", chain.basic[0], chain.parent2bcs_of_basic(0)
    return "BASIC_REF", chain.setframe, Frame()


def to_child(frame, parent2bcs, p_bcs):
    return frame.parent2child(parent2bcs.parent2child(p_bcs))


def dir_to_child(frame, parent2bcs, d_bcs):
    return frame.rotation.T @ (parent2bcs.rotation.T @ d_bcs)


def angle_in(u, pl):
    a, o, _ = pl.to_aop(u)
    return np.degrees(np.arctan2(o, a))


def angle_diff(x, y):
    return (x - y + 180.0) % 360.0 - 180.0


@FAST
@given(chain=chain_st, other=frame_st(), kind=target_kind_st, pl_name=plane_st, p=vec,
       setp=st.tuples(coord, coord, coord), mask=st.tuples(st.booleans(), st.booleans(), st.booleans()))
def test_translation_reads_setpoints(chain, other, kind, pl_name, p, setp, mask):
    pl = PLANES[pl_name]
    axes = [ax for ax, m in zip("XYZ", mask, strict=True) if m] or [pl.first]
    p_meas = np.array(p)
    fix = FeatureFix(position={ax: p_meas["XYZ".index(ax)] for ax in axes}, point=p_meas)
    setpoints = {ax: setp["XYZ".index(ax)] for ax in axes}
    name, frame, parent = target_of(kind, chain, other)
    corr = correct(fix, setpoints=setpoints, setpoint_angle=None, target=name, target_frame=frame,
                   chain=chain, target_parent2bcs=parent, plane=pl)
    p_bcs = chain.p_in_bcs(p_meas)
    old = to_child(frame, parent, p_bcs)
    new = to_child(corr.after, parent, p_bcs)
    for j, ax in enumerate("XYZ"):
        expected = setpoints[ax] if ax in axes else old[j]
        assert new[j] == pytest.approx(expected, abs=1e-9)
    # bookkeeping: rotation untouched, all translation in coarse, fine cleared
    assert np.array_equal(corr.after.rot, frame.rot)
    assert not np.any(corr.after.fine)
    assert corr.before is frame and corr.target == name


@FAST
@given(chain=chain_st, other=frame_st(), kind=target_kind_st, pl_name=plane_st, p=vec,
       setp=st.tuples(coord, coord), ang=st.floats(-60, 60), ang_set=st.floats(-90, 90),
       with_position=st.booleans())
def test_rotation_reads_setpoint_angle(chain, other, kind, pl_name, p, setp, ang, ang_set, with_position):
    pl = PLANES[pl_name]
    e_a, e_o, e_p = (pl.unit(ax) for ax in pl.axes)
    th = np.radians(ang)
    # the measured line P1->P2 lies in the measuring plane (both points at one height); the
    # chains' tilts take it out of the target child's plane
    u_meas = np.cos(th) * e_a + np.sin(th) * e_o
    p_meas = np.array(p)
    position = {pl.first: p_meas[pl.index[0]], pl.second: p_meas[pl.index[1]]} if with_position else {}
    fix = FeatureFix(position=position, angle=ang, angle_axis=pl.infeed, reference_axis=pl.first,
                     point=p_meas)
    setpoints = {pl.first: setp[0], pl.second: setp[1]}
    name, frame, parent = target_of(kind, chain, other)
    corr = correct(fix, setpoints=setpoints, setpoint_angle=ang_set, target=name, target_frame=frame,
                   chain=chain, target_parent2bcs=parent, plane=pl)
    p_bcs = chain.p_in_bcs(p_meas)
    u_bcs = chain.dir_in_bcs(u_meas)
    u_new = dir_to_child(corr.after, parent, u_bcs)
    assert angle_diff(angle_in(u_new, pl), ang_set) == pytest.approx(0.0, abs=1e-9)
    # the rotation is about the child's infeed axis: p axis of the target unchanged in the parent
    assert np.allclose(corr.after.rotation @ e_p, frame.rotation @ e_p, atol=1e-12)
    old = to_child(frame, parent, p_bcs)
    new = to_child(corr.after, parent, p_bcs)
    if with_position:
        assert new[pl.index[0]] == pytest.approx(setp[0], abs=1e-9)
        assert new[pl.index[1]] == pytest.approx(setp[1], abs=1e-9)
        assert new[pl.index[2]] == pytest.approx(old[pl.index[2]], abs=1e-9)   # infeed kept
        assert not np.any(corr.after.fine)
    else:   # rotation only: translation (and its coarse/fine split) kept (jog §2.5.2, §2.7.2)
        assert np.array_equal(corr.after.coarse, frame.coarse)
        assert np.array_equal(corr.after.fine, frame.fine)
    assert corr.rotary_axis is None and corr.tilts_infeed(pl) is False


@FAST
@given(chain=chain_st, other=frame_st(), kind=target_kind_st, ang=st.floats(-30, 30),
       ang_set=st.floats(-10, 10), c_old=st.floats(-90, 90))
def test_rotary_axis_correction(chain, other, kind, ang, ang_set, c_old):
    pl = PLANES["G17"]
    name, frame, parent = target_of(kind, chain, other)
    frame = frame.with_rotary("C", c_old)
    th = np.radians(ang)
    u_meas = np.array([np.cos(th), np.sin(th), 0.0])
    fix = FeatureFix(angle=ang, angle_axis="Z", reference_axis="X", point=np.zeros(3))
    corr = correct(fix, setpoints={}, setpoint_angle=ang_set, target=name, target_frame=frame,
                   chain=chain, target_parent2bcs=parent, plane=pl, angle_correction="C")
    assert corr.rotary_axis == "C"
    assert np.array_equal(corr.after.rot, frame.rot)
    assert np.allclose(corr.after.translation, frame.translation)
    assert corr.after.rotary_offset("C") == pytest.approx(c_old + corr.rotary_move)
    # DIN 66217 rotary table: turning C by +m turns the part by −m about the table (= child Z)
    u_child = dir_to_child(frame, parent, chain.dir_in_bcs(u_meas))
    turned = rot_axis("Z", -corr.rotary_move) @ u_child
    assert angle_diff(angle_in(turned, pl), ang_set) == pytest.approx(0.0, abs=1e-9)


@FAST
@given(chain=chain_st, other=frame_st(tilt=st.floats(-20, 20)), kind=target_kind_st, pl_name=plane_st,
       alpha=st.floats(-30, 30), beta=st.floats(-30, 30))
def test_orient_plane_makes_normal_the_infeed(chain, other, kind, pl_name, alpha, beta):
    pl = PLANES[pl_name]
    e_a, e_o, e_p = (pl.unit(ax) for ax in pl.axes)
    # true normal in the measuring WCS, built about the plane's own axes
    n_meas = rot_axis(pl.second, beta) @ rot_axis(pl.first, alpha) @ e_p
    name, frame, parent = target_of(kind, chain, other)
    fix = FeatureFix(normal=n_meas, point=np.array([5.0, 6.0, 7.0]))
    corr = correct(fix, setpoints={}, setpoint_angle=None, target=name, target_frame=frame,
                   chain=chain, target_parent2bcs=parent, plane=pl)
    n_new = dir_to_child(corr.after, parent, chain.dir_in_bcs(n_meas))
    assert np.allclose(n_new, e_p, atol=1e-9)
    assert np.allclose(corr.after.translation, frame.translation)      # jog §2.9: translation kept
    if pl_name == "G17":
        assert angle_diff(corr.after.rot[2], frame.rot[2]) == pytest.approx(0.0, abs=1e-9)  # gamma kept


def test_orient_plane_simple_case_needs_realignment():
    # G17, untilted chain, plane rising 10° along +Y: new frame = Rx(10°), translation kept
    g54 = Frame(coarse=[10.0, 20.0, 30.0], rot=[0.0, 0.0, 0.0])
    chain = FrameChain(settable=g54)
    n = np.array([0.0, -np.sin(np.radians(10)), np.cos(np.radians(10))])
    corr = correct(FeatureFix(normal=n), setpoints={}, setpoint_angle=None, target="G54",
                   target_frame=g54, chain=chain, target_parent2bcs=chain.below_settable,
                   plane=PLANES["G17"])
    assert np.allclose(corr.after.rot, [10.0, 0.0, 0.0], atol=1e-12)
    assert np.array_equal(corr.after.coarse, g54.coarse)
    assert corr.tilts_infeed(PLANES["G17"]) is True


@pytest.mark.parametrize("pl_name", ["G17", "G18", "G19"])
def test_alpha_beta_from_normal_by_hand(pl_name):
    pl = PLANES[pl_name]
    e_a, e_o, e_p = (pl.unit(ax) for ax in pl.axes)
    # plane rising 10° along +o: points (0,0,0), 10·a, 10·o + 10·tan10°·p
    p2, p3 = 10 * e_a, 10 * e_o + 10 * np.tan(np.radians(10)) * e_p
    n = np.cross(p2, p3)
    alpha, beta = alpha_beta_from_normal(n, pl)
    assert alpha == pytest.approx(10.0) and beta == pytest.approx(0.0, abs=1e-12)
    # plane falling 15° along +a: normal leans to +a -> beta = +15
    n = np.sin(np.radians(15)) * e_a + np.cos(np.radians(15)) * e_p
    alpha, beta = alpha_beta_from_normal(n, pl)
    assert alpha == pytest.approx(0.0, abs=1e-12) and beta == pytest.approx(15.0)
    # general: Rot_o(beta)·Rot_a(alpha)·p = n
    n = np.array([0.2, -0.3, 0.9])
    alpha, beta = alpha_beta_from_normal(n, pl)
    rebuilt = rot_axis(pl.second, beta) @ rot_axis(pl.first, alpha) @ e_p
    assert np.allclose(rebuilt, n / np.linalg.norm(n))


def test_set_edge_unrotated_by_hand():
    # jog §2.5.1: unrotated WO: T_a = c_parent,a − s; fine offset folded in and cleared (§4.4)
    g54 = Frame(coarse=[100.0, 50.0, -20.0], fine=[0.1, 0.2, 0.0])
    chain = FrameChain(settable=g54)
    fix = FeatureFix(position={"X": 2.5}, point=np.array([2.5, 7.0, -3.0]))
    corr = correct(fix, setpoints={"X": 0.0}, setpoint_angle=None, target="G54", target_frame=g54,
                   chain=chain, target_parent2bcs=chain.below_settable, plane=PLANES["G17"])
    assert np.allclose(corr.after.coarse, [102.6, 50.2, -20.0])
    assert np.array_equal(corr.after.fine, [0.0, 0.0, 0.0])
    # setpoint 10: the edge at 2.5 shall read 10 -> zero point moves −7.5
    corr = correct(fix, setpoints={"X": 10.0}, setpoint_angle=None, target="G54", target_frame=g54,
                   chain=chain, target_parent2bcs=chain.below_settable, plane=PLANES["G17"])
    assert corr.after.coarse[0] == pytest.approx(92.6)


def test_corner_worked_example_12a():
    # measuring-math §12.3 example 12-A: measured in G54 = (100, 50, 0), corner (20, 30) WCS at 2°,
    # written into G55 -> trans (120, 80), rot Z 2°, infeed translation unchanged
    g54 = Frame(coarse=[100.0, 50.0, 0.0])
    chain = FrameChain(settable=g54)
    g55 = Frame(coarse=[0.0, 0.0, -33.0])
    fix = FeatureFix(position={"X": 20.0, "Y": 30.0}, angle=2.0, angle_axis="Z", reference_axis="X",
                     point=np.array([20.0, 30.0, -5.0]))
    corr = correct(fix, setpoints={"X": 0.0, "Y": 0.0}, setpoint_angle=0.0, target="G55",
                   target_frame=g55, chain=chain, target_parent2bcs=chain.below_settable,
                   plane=PLANES["G17"])
    assert np.allclose(corr.after.coarse, [120.0, 80.0, -33.0], atol=1e-9)
    assert np.allclose(corr.after.rot, [0.0, 0.0, 2.0], atol=1e-12)


def test_align_edge_rotation_adds_difference():
    # jog §2.5.2 [I]: rot_new = rot_old + (alpha − alpha_set) for the active, Z-rotated WO
    g54 = Frame(coarse=[10.0, 20.0, 0.0], rot=[0.0, 0.0, 5.0])
    chain = FrameChain(settable=g54)
    fix = FeatureFix(angle=1.5, angle_axis="Z", reference_axis="X", point=np.array([40.0, 2.0, -1.0]))
    corr = correct(fix, setpoints={}, setpoint_angle=0.5, target="G54", target_frame=g54, chain=chain,
                   target_parent2bcs=chain.below_settable, plane=PLANES["G17"])
    assert corr.after.rot[2] == pytest.approx(6.0)
    assert np.array_equal(corr.after.coarse, g54.coarse)


def test_measure_only_and_translate_false():
    g54 = Frame(coarse=[1.0, 2.0, 3.0], fine=[0.5, 0.0, 0.0])
    chain = FrameChain(settable=g54)
    fix = FeatureFix(position={"X": 4.0}, angle=3.0, angle_axis="Z", reference_axis="X")
    kwargs = dict(setpoints={"X": 0.0}, setpoint_angle=0.0, target_frame=g54, chain=chain,
                  target_parent2bcs=chain.below_settable, plane=PLANES["G17"])
    corr = correct(fix, target="measure_only", **kwargs)
    assert isinstance(corr, Correction) and corr.after == corr.before == g54
    corr = correct(fix, target="G54", translate=False, **kwargs)
    assert np.array_equal(corr.after.coarse, g54.coarse) and np.array_equal(corr.after.fine, g54.fine)
    assert corr.after.rot[2] == pytest.approx(3.0)


def test_global_basic_frame_refuses_rotation():
    chain = FrameChain(basic=(Frame(coarse=[5.0, 0.0, 0.0]),))
    kwargs = dict(setpoints={"X": 0.0}, setpoint_angle=0.0, target="NCBASIC_0",
                  target_frame=chain.basic[0], chain=chain, target_parent2bcs=chain.parent2bcs_of_basic(0),
                  plane=PLANES["G17"])
    for fix in (FeatureFix(position={"X": 1.0}, angle=2.0, angle_axis="Z", reference_axis="X"),
                FeatureFix(normal=np.array([0.0, 0.1, 1.0]))):
        with pytest.raises(MeasuringError) as err:
            correct(fix, **kwargs)
        assert err.value.alarm == 61321
    with pytest.raises(MeasuringError):
        correct(FeatureFix(angle=2.0, angle_axis="Z", reference_axis="X"), angle_correction="C", **kwargs)
    corr = correct(FeatureFix(position={"X": 1.0}), **kwargs)     # translation only is fine
    assert corr.after.coarse[0] == pytest.approx(6.0)

"""Frames, RPY and planes (design.md §3, measuring-math §0)."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.frames import (
    Frame,
    FrameChain,
    compose_chain,
    matrix_from_rpy,
    rot_axis,
    rot_x,
    rot_y,
    rot_z,
    rpy_from_matrix,
)
from engine.planes import PLANES, axis_index, plane

FAST = settings(max_examples=60, deadline=None)

angle = st.floats(-179.0, 179.0, allow_nan=False)
tilt = st.floats(-88.9, 88.9, allow_nan=False)
coord = st.floats(-500.0, 500.0, allow_nan=False)
rpy = st.tuples(angle, tilt, angle)
vec = st.tuples(coord, coord, coord)


def frames(rotary=False):
    rot_part = st.fixed_dictionaries({"C": st.floats(-360, 360)}) if rotary else st.just({})
    return st.builds(lambda c, f, r, ro: Frame(coarse=c, fine=f, rot=r, rotary=tuple(ro.items())),
                     vec, vec, rpy, rot_part)


def test_rotations_are_right_handed():
    # +90° about Z takes +X to +Y; about X takes +Y to +Z; about Y takes +Z to +X (§0.1)
    assert np.allclose(rot_z(90) @ [1, 0, 0], [0, 1, 0])
    assert np.allclose(rot_x(90) @ [0, 1, 0], [0, 0, 1])
    assert np.allclose(rot_y(90) @ [0, 0, 1], [1, 0, 0])
    assert np.allclose(rot_axis("Y", 30), rot_y(30))


def test_rpy_order_is_z_then_new_y_then_new_x():
    # intrinsic Z, Y', X'' = extrinsic X, Y, Z: R = Rz(c)·Ry(b)·Rx(a), written out by hand
    a, b, c = np.radians([10.0, 20.0, 30.0])
    ca, sa, cb, sb, cc, sc = np.cos(a), np.sin(a), np.cos(b), np.sin(b), np.cos(c), np.sin(c)
    expected = np.array([
        [cc * cb, cc * sb * sa - sc * ca, cc * sb * ca + sc * sa],
        [sc * cb, sc * sb * sa + cc * ca, sc * sb * ca - cc * sa],
        [-sb, cb * sa, cb * ca],
    ])
    assert np.allclose(matrix_from_rpy([10, 20, 30]), expected, atol=1e-15)


@FAST
@given(rpy)
def test_rpy_round_trip(angles):
    back = rpy_from_matrix(matrix_from_rpy(angles))
    assert np.allclose(back, angles, atol=1e-9)


@pytest.mark.parametrize("b", [90.0, -90.0])
def test_rpy_gimbal_lock_gives_same_matrix(b):
    r = matrix_from_rpy([25.0, b, 40.0])
    back = rpy_from_matrix(r)
    assert back[2] == 0.0
    assert np.allclose(matrix_from_rpy(back), r, atol=1e-12)


@FAST
@given(frames(rotary=True), frames(rotary=True), vec)
def test_compose_maps_like_nested_application(outer, inner, p):
    composed = outer.compose(inner)
    assert np.allclose(composed.child2parent(p), outer.child2parent(inner.child2parent(p)), atol=1e-9)
    assert composed.rotary_offset("C") == pytest.approx(outer.rotary_offset("C") + inner.rotary_offset("C"))


@FAST
@given(frames(rotary=True), vec)
def test_inverse(frame, p):
    inv = frame.inverse()
    assert np.allclose(inv.child2parent(frame.child2parent(p)), p, atol=1e-9)
    assert np.allclose(frame.parent2child(p), inv.child2parent(p), atol=1e-9)
    assert frame.compose(inv).isclose(Frame(rotary=(("C", 0.0),)), tol=1e-9)


@FAST
@given(frames(), vec)
def test_point_and_direction_maps(frame, d):
    r = frame.rotation
    assert np.allclose(frame.child2parent(d), r @ d + frame.coarse + frame.fine, atol=1e-9)
    assert np.allclose(frame.dir_child2parent(d), r @ d, atol=1e-9)
    assert np.allclose(frame.dir_parent2child(frame.dir_child2parent(d)), d, atol=1e-9)
    assert np.allclose(r.T @ r, np.eye(3), atol=1e-12)
    assert np.linalg.det(r) == pytest.approx(1.0)


@FAST
@given(frames(rotary=True))
def test_api_round_trip(frame):
    data = frame.to_api()
    assert set(data["trans"]) == {"X", "Y", "Z", "C"}
    back = Frame.from_api(data)
    assert back == frame


def test_from_api_tolerates_missing_parts():
    f = Frame.from_api({"trans": {"X": 1.5, "B": 3.0}})
    assert np.allclose(f.coarse, [1.5, 0, 0]) and not np.any(f.fine) and not np.any(f.rot)
    assert f.rotary_offset("B") == 3.0


def test_frame_equality_and_hash():
    a = Frame(coarse=[1, 2, 3], rot=[0, 0, 5])
    b = Frame(coarse=[1, 2, 3], rot=[0, 0, 5])
    assert a == b and hash(a) == hash(b)
    assert a != a.replace(fine=[0, 0, 1e-6])
    assert a.with_rotary("C", 2.0).rotary_offset("C") == 2.0


def test_chain_order_setframe_outermost():
    # each frame a pure translation plus a 90° turn: the order shows in the result
    setframe = Frame(coarse=[100, 0, 0], rot=[0, 0, 90])
    basic0 = Frame(coarse=[0, 10, 0])
    settable = Frame(coarse=[1, 0, 0], rot=[0, 0, 90])
    chain = FrameChain(setframe=setframe, basic=(basic0,), settable=settable)
    p_wcs = np.array([1.0, 0.0, 0.0])
    # by hand: G54: Rz90(1,0,0) + (1,0,0) = (1,1,0); basic: (1,11,0); SET: Rz90 -> (-11,1,0) + 100
    assert np.allclose(chain.p_in_bcs(p_wcs), [89.0, 1.0, 0.0])
    assert np.allclose(chain.p_in_wcs([89.0, 1.0, 0.0]), p_wcs)
    assert chain.below_settable.isclose(compose_chain([setframe, basic0]))
    assert chain.parent2bcs_of_basic(0) == compose_chain([setframe])
    assert np.allclose(chain.dir_in_bcs([1, 0, 0]), [-1, 0, 0], atol=1e-12)
    assert chain.replace(settable=Frame()).wcs2bcs.isclose(compose_chain([setframe, basic0]))


@pytest.mark.parametrize("name", ["G17", "G18", "G19"])
def test_planes_right_handed(name):
    pl = plane(name)
    m = pl.aop2xyz
    assert np.linalg.det(m) == pytest.approx(1.0)
    a, o, p = (pl.unit(x) for x in pl.axes)
    assert np.allclose(np.cross(a, o), p)
    v = np.array([1.0, 2.0, 3.0])
    assert np.allclose(pl.to_xyz(pl.to_aop(v)), v)
    assert pl.to_aop(pl.unit(pl.infeed))[2] == 1.0


def test_plane_table():
    assert PLANES["G18"].axes == ("Z", "X", "Y") and PLANES["G19"].axes == ("Y", "Z", "X")
    assert axis_index("Y") == 1
    with pytest.raises(ValueError):
        plane("G16")
    assert math.isclose(np.linalg.norm(PLANES["G19"].infeed_unit), 1.0)

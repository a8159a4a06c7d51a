"""Probe compensation (measuring-math §5): latches synthesized from a physical ball model."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.compensation import (
    centre_trigger_value,
    make_touch,
    parallel_axis,
    skew_in_wcs,
    trigger_radius,
)
from engine.frames import Frame
from engine.planes import PLANES
from engine.types import ProbeRecord

FAST = settings(max_examples=50, deadline=None)

coord = st.floats(-300.0, 300.0, allow_nan=False)
small = st.floats(-0.05, 0.05, allow_nan=False)
pretravel = st.floats(0.0, 0.02, allow_nan=False)


def physical_probe(r, pre, *, to_tip=False, infeed="Z"):
    """Trigger values as calibration defines them (§5.1): reference point at switching − surface.

    Ball of true radius r, pre-travel pre[key]: switching happens pre after contact, so the
    centre is at s − σ(r − δ) along the axis; with to_tip the reference is r below the centre
    along the infeed axis.
    """
    trig = {}
    for key, delta in pre.items():
        sign = 1.0 if key[1] == "+" else -1.0
        t_centre = -sign * (r - delta)
        if to_tip and key[0] == infeed:
            t_centre -= r
        trig[key] = t_centre
    return trig


@FAST
@given(surface=st.tuples(coord, coord, coord), axis=st.integers(0, 2), sign=st.sampled_from([1.0, -1.0]),
       r=st.floats(0.5, 5.0), delta=pretravel, skew=st.tuples(small, small),
       spindle=st.floats(-180, 180), wcs_rot=st.tuples(st.floats(-5, 5), st.floats(-5, 5), st.floats(-180, 180)))
def test_axis_parallel_surface_recovered(surface, axis, sign, r, delta, skew, spindle, wcs_rot):
    key = f"{'XYZ'[axis]}{'+' if sign > 0 else '-'}"
    probe = ProbeRecord(ball_diameter=2 * r, effective_diameter=2 * r - 0.01,
                        trigger=physical_probe(r, {key: delta}), skew=skew)
    wcs2bcs = Frame(coarse=[10, 20, -30], rot=wcs_rot)
    s = np.array(surface)
    d = np.zeros(3)
    d[axis] = sign
    centre_true = s - d * (r - delta)                       # contact, then pre-travel along d
    # skew: machine XY vector turned by SPOS about Z, seen in the WCS (independent rebuild)
    phi = np.radians(spindle)
    e_mcs = np.array([np.cos(phi) * skew[0] - np.sin(phi) * skew[1],
                      np.sin(phi) * skew[0] + np.cos(phi) * skew[1], 0.0])
    e_wcs = wcs2bcs.rotation.T @ e_mcs
    assert np.allclose(skew_in_wcs(probe, wcs2bcs, spindle), e_wcs, atol=1e-12)
    rec = centre_true - e_wcs                               # the NC latches the spindle axis
    touch = make_touch(rec, d * 7.0, probe, PLANES["G17"], skew_wcs=e_wcs, latched_mcs=[1, 2, 3])
    assert np.allclose(touch.ball_centre, centre_true, atol=1e-9)
    assert touch.surface[axis] == pytest.approx(s[axis], abs=1e-9)
    assert np.allclose(np.delete(touch.surface, axis), np.delete(centre_true, axis), atol=1e-9)
    assert np.allclose(touch.direction, d)
    assert trigger_radius(probe, d) == pytest.approx(r - delta)
    assert touch.latched_mcs is not None


@pytest.mark.parametrize("plane_name", ["G17", "G18", "G19"])
@pytest.mark.parametrize("sign", [-1.0, 1.0])
def test_length_to_tip_along_infeed(plane_name, sign):
    pl = PLANES[plane_name]
    r, delta = 3.0, 0.004
    key = f"{pl.infeed}{'+' if sign > 0 else '-'}"
    probe = ProbeRecord(ball_diameter=2 * r, trigger=physical_probe(r, {key: delta}, to_tip=True,
                                                                    infeed=pl.infeed),
                        length_to_tip=True)
    j = "XYZ".index(pl.infeed)
    if sign < 0:  # manual §5.3.4: with L1 to the tip the −infeed trigger value is ≈ 0 (here −δ)
        assert probe.trigger[key] == pytest.approx(-delta)
    s = np.array([12.0, -7.0, 40.0])
    d = sign * pl.infeed_unit
    centre_true = s - d * (r - delta)
    tip = centre_true - r * pl.infeed_unit
    touch = make_touch(tip, d, probe, pl)
    assert np.allclose(touch.ball_centre, centre_true, atol=1e-12)
    assert touch.surface[j] == pytest.approx(s[j], abs=1e-12)
    assert trigger_radius(probe, d, pl) == pytest.approx(r - delta)


def test_length_to_tip_uncalibrated_and_lateral():
    probe = ProbeRecord(ball_diameter=6.0, length_to_tip=True)
    tip = np.array([0.0, 0.0, 10.0])
    down = make_touch(tip, [0, 0, -1], probe, PLANES["G17"])
    assert np.allclose(down.ball_centre, [0, 0, 13.0])
    assert down.surface[2] == pytest.approx(10.0)          # ideal ball: touches with the tip
    side = make_touch(tip, [1, 0, 0], probe, PLANES["G17"])
    assert side.surface[0] == pytest.approx(3.0)            # ideal t(X+) = −r


@FAST
@given(centre=st.tuples(coord, coord, coord), ang=st.floats(1.0, 89.0), rho=st.floats(0.5, 4.0),
       elev=st.floats(-30.0, 30.0))
def test_oblique_direction_uses_effective_radius(centre, ang, rho, elev):
    a, e = np.radians(ang), np.radians(elev)
    d = np.array([np.cos(a) * np.cos(e), np.sin(a) * np.cos(e), np.sin(e)])
    probe = ProbeRecord(ball_diameter=2 * rho + 0.2, effective_diameter=2 * rho,
                        trigger={"X+": -9.0, "Y+": -9.0})
    # surface normal to d: contact point lies rho from the centre along d
    c = np.array(centre)
    touch = make_touch(c, d * 3.0, probe, PLANES["G17"])
    assert np.allclose(touch.surface, c + rho * d, atol=1e-9)
    assert trigger_radius(probe, d) == pytest.approx(rho)


def test_uncalibrated_uses_nominal_ball():
    probe = ProbeRecord(ball_diameter=4.0)
    d = np.array([1.0, 1.0, 0.0]) / np.sqrt(2)
    touch = make_touch([0, 0, 0], d, probe, PLANES["G17"])
    assert np.allclose(touch.surface, 2.0 * d)
    minus_y = make_touch([5, 5, 5], [0, -1, 0], probe, PLANES["G17"])
    assert np.allclose(minus_y.surface, [5, 3, 5])           # t(Y−) = +r: surface r below centre


def test_parallel_tolerance():
    assert parallel_axis([0, 0, -1]) == (2, -1.0)
    assert parallel_axis([1, 5e-10, 0]) == (0, 1.0)
    assert parallel_axis([1, 1e-6, 0]) is None
    with pytest.raises(ValueError):
        centre_trigger_value(ProbeRecord(), [1, 1, 0])
    with pytest.raises(ValueError):
        make_touch([0, 0, 0], [0, 0, 0], ProbeRecord(), PLANES["G17"])

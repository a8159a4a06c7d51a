"""The start guard's reach check (issue 24 §1, measuring-math §1.3): a probing move whose braking
behind the switch would push the probe beyond its permissible deflection is refused before any
motion. Truth: the spec's worked examples and the formula s_b = 1000·v·t + 1000·v²/(2a) + v/Kv
(v in m/s, the last term in m/min) worked by hand here."""

from __future__ import annotations

import numpy as np
import pytest

from engine.guard import Body, Braking, Placement, ProtectionModel, Solid, braking_distance, check_program
from engine.guard_model import braking_from_data
from engine.types import Latch, MoveStep, ProbeStep

# a block whose top face is z = 0 (MCS = plan coordinates below)
BLOCK = Solid("workpiece", centre=np.array([0.0, 0.0, -30.0]),
              polygon=np.array([[-100.0, -60.0], [100.0, -60.0], [100.0, 60.0], [-100.0, 60.0]]),
              half_height=30.0)
MODEL = ProtectionModel((Body(BLOCK),), {})
R = 2.0
PLACEMENT = Placement(rotation=np.eye(3), ball_shift=np.zeros(3), axes_shift=np.array([0.0, 0.0, 100.0]),
                      ball_radius=R)


def test_the_spec_worked_examples():
    # 1.3-A: v = 6 m/min = 0.1 m/s, a = 1 m/s², t = 0.016 s, Kv = 1 -> 1.6 + 5 + 6 = 12.6 mm
    assert braking_distance(6000.0, 0.016, 1.0, 1.0) == pytest.approx(12.6, abs=1e-9)
    # 1.3-B: v = 300 mm/min = 0.005 m/s, t = 0.004 s, a = 2 m/s², Kv = 2 -> 0.02 + 0.00625 + 0.15
    assert braking_distance(300.0, 0.004, 2.0, 2.0) == pytest.approx(0.17625, abs=1e-12)


def test_a_feed_by_hand():
    feed, t, a, kv = 2400.0, 0.004, 1.0, 1.0             # 2.4 m/min = 0.04 m/s
    v = feed / 60.0 / 1000.0                             # m/s
    by_hand = 1000.0 * v * t + 1000.0 * v * v / (2.0 * a) + (feed / 1000.0) / kv
    assert by_hand == pytest.approx(0.16 + 0.8 + 2.4, abs=1e-12)
    assert braking_distance(feed, t, a, kv) == pytest.approx(by_hand, abs=1e-12)
    # the override scales the feed in effect: 120 % of 2000 mm/min is the same 2400 mm/min
    assert Braking(t, a, kv, 2.0, override=120.0).distance(2000.0) == pytest.approx(by_hand, abs=1e-12)


def _program(feed: float, distance: float = 10.0):
    """Down onto the top face from 5 above it (ball centre at z = 5 + R), then back up."""
    yield MoveStep(np.array([0.0, 0.0, 5.0 + R]), None, label="P1 up")
    latch: Latch | None = yield ProbeStep(np.array([0.0, 0.0, -1.0]), distance, feed, label="P1 -Z", expected=5.0)
    assert latch is not None and latch.triggered
    yield MoveStep(np.array([0.0, 0.0, 5.0 + R]), None, label="P1 retract")


def _run(feed: float, braking: Braking | None, distance: float = 10.0):
    return check_program(_program(feed, distance), np.array([0.0, 0.0, 20.0]), MODEL, PLACEMENT, braking)


def test_braking_within_the_deflection_is_clear():
    # 300 mm/min, t 0.004 s, a 1, Kv 1: 0.02 + 0.0125 + 0.3 = 0.3325 mm < 2 mm
    report = _run(300.0, Braking(0.004, 1.0, 1.0, 2.0))
    assert report.refusal is None and report.complete
    probe = [s for s in report.segments if s.kind == "probe"][0]
    assert probe.verdict == "contact"
    assert probe.braking == pytest.approx(0.02 + 0.0125 + 0.3, abs=1e-12)
    assert probe.deflection == pytest.approx(probe.braking, abs=1e-12)


def test_braking_beyond_the_deflection_is_refused_at_the_probing_move():
    # 3000 mm/min = 0.05 m/s: 0.2 + 1.25 + 3.0 = 4.45 mm > 2 mm; the stroke runs 5 mm past the face
    report = _run(3000.0, Braking(0.004, 1.0, 1.0, 2.0))
    seg = report.refusal
    assert seg is not None and seg.verdict == "overtravel" and seg.label == "P1 -Z"
    assert seg.braking == pytest.approx(4.45, abs=1e-12)
    assert seg.deflection == pytest.approx(4.45, abs=1e-12) and seg.max_deflection == 2.0
    assert seg.where is not None and seg.where[2] == pytest.approx(R, abs=1e-6)    # contact: the ball on z = 0
    assert not report.complete and report.segments[-1] is seg                   # nothing after it is planned


def test_the_stroke_end_bounds_the_deflection():
    # the same 4.45 mm braking, but the stroke ends 1.5 mm past the face: the axes stop there
    report = _run(3000.0, Braking(0.004, 1.0, 1.0, 2.0), distance=6.5)
    probe = [s for s in report.segments if s.kind == "probe"][0]
    assert report.refusal is None and probe.deflection == pytest.approx(1.5, abs=1e-9)


def test_the_pretravel_adds_to_the_braking():
    # 1.9 mm of braking (t 0, a large, Kv: 1.9 mm following error at 1900 mm/min) + 0.2 pre-travel > 2
    braking = Braking(0.0, 1e9, 1.0, 2.0, pretravel=0.2)
    assert braking.distance(1900.0) == pytest.approx(1.9, abs=1e-6)
    assert _run(1900.0, braking).refusal is not None
    assert _run(1900.0, Braking(0.0, 1e9, 1.0, 2.0)).refusal is None


def test_without_braking_data_nothing_is_checked():
    report = _run(9000.0, None)
    assert report.refusal is None
    probe = [s for s in report.segments if s.kind == "probe"][0]
    assert probe.braking is None and probe.deflection is None


def test_braking_data_per_probe():
    data = {"latency_s": 0.004, "decel": 1.0, "kv": 1.0, "max_deflection": {"workpiece": 2.0, "tool": None}}
    braking = braking_from_data(data, "workpiece", 110.0)
    assert braking is not None and braking.max_deflection == 2.0 and braking.override == 110.0
    assert braking_from_data(data, "tool") is None          # a tool probe overtravel does not break
    assert braking_from_data(None, "workpiece") is None

"""CYCLE961/998/997 listings of the manual (§5.7, §5.8, §5.9) as printed, against the scenario's truth.

Adapted: ``循环`` → ``CYCLE`` (the Chinese print's translation of the cycle names), nothing else in
the text; the part is placed (turned) so that the printed positions fit. Truth: the part's true
pose in the scenario (the corner and the edge angle), read back through ``GET /api/offsets/G55``
and ``_OVR`` after the run.
"""

from __future__ import annotations

import copy
import math

import pytest
from listing_kit import G54, Machine
from manual_listings import ECKE_EINRICHTEN_1_15334, ECKE_EINRICHTEN_14904

ARTEFACT = {"循环": "CYCLE"}   # the Chinese print translated the cycle names (issue 28)


def place(m: Machine, workpiece: dict) -> None:
    """The scenario of ``m`` with ``workpiece`` (MCS pose) in place of the kit's block."""
    scen = copy.deepcopy(m.scen)
    scen["workpiece"] = workpiece
    m.scen = scen
    m.ok(m.c.post("/api/sim/scenario", json={**scen, "reset_data": True}))
    m.put_offset("G54", G54["block"])


def test_corner_from_four_given_points_into_g55(client):
    """§5.8.3 %_N_ECKE_EINRICHTEN_1_MPF (lines 15334–15354): CYCLE961 _MVAR=118 (outer corner from
    the given points P1 (50, 20), P2 (150, 20), P3 (15, 40), P4 (15, 80) in G54, _ID=−60 below the
    start Z100, _KNUM=2): G55 becomes the corner, turned along the edge P1→P2, then N80 goes to its
    X0 Y0. Part (measuring-math worked example 12-A): a 200 × 120 × 60 block whose front-left
    corner lies at G54 (20, 30), top face Z60 (the measuring depth Z40 is on its sides), turned
    +2° about Z (the front edge at +2°, the left edge at 92°)."""
    m = Machine(client)
    corner_mcs = (G54["block"][0] + 20.0, G54["block"][1] + 30.0)
    place(m, {"pose": {"trans": [*corner_mcs, G54["block"][2] + 60.0], "rot": [0.0, 0.0, 2.0]},
              "features": [{"type": "block", "size": [200, 120, 60]}]})
    before = m.offset("G55")
    answer = m.run(ECKE_EINRICHTEN_1_15334, replace=ARTEFACT)
    assert answer["state"] == "done", answer
    g55 = m.offset("G55")
    assert [g55["trans"]["X"], g55["trans"]["Y"]] == pytest.approx(list(corner_mcs), abs=1e-6)
    assert [g55["fine"][a] for a in "XYZ"] == pytest.approx([0.0, 0.0, 0.0], abs=1e-12)   # coarse, fine cleared
    assert g55["rot"]["Z"] == pytest.approx(2.0, abs=1e-6)
    assert [g55["rot"]["X"], g55["rot"]["Y"]] == pytest.approx([0.0, 0.0], abs=1e-12)
    assert g55["trans"]["Z"] == pytest.approx(before["trans"]["Z"], abs=1e-12)            # p unchanged
    ovr = m.ovr()
    assert [ovr[4], ovr[5], ovr[6]] == pytest.approx([2.0, 20.0, 30.0], abs=1e-6)          # WCS (G54)
    assert [ovr[20], ovr[21], ovr[22]] == pytest.approx([2.0, *corner_mcs], abs=1e-6)      # MCS
    wcs = m.wcs()
    assert (wcs["X"], wcs["Y"]) == pytest.approx((0.0, 0.0), abs=1e-6)                    # N80 in G55


def _unit(deg: float) -> tuple[float, float]:
    return math.cos(math.radians(deg)), math.sin(math.radians(deg))


def test_corner_unknown_geometry_from_the_start_into_g55(client):
    """§5.8 %_N_ECKE_EINRICHTEN_MPF (lines 14904–14917): CYCLE961 _MVAR=108 (outer corner, unknown
    geometry) in G500 from the start where the operator jogged the probe ("测量头位于起始位置"):
    P1/P2 at 50/100 mm along _STA1=−35°, P3/P4 along _STA1+_INCA=45°, _ID=30 lifts over the
    corner, _KNUM=2: G55 becomes the corner (MCS), turned along the reference edge.
    Part: a prism whose corner K lies 10 mm +X of the start S (MCS 300, 150; measuring depth
    Z−110, top face Z−100), reference edge at −33°, second edge at 43° (a 76° corner: 2° off the
    setpoints each, within the cycle's 10°). Adapted: only the start (the operator's jog)."""
    m = Machine(client)
    start = (300.0, 150.0, -110.0)
    ref, second = -33.0, 43.0
    corner = (start[0] + 10.0, start[1])
    inca = math.radians(second - ref)
    wedge = [(0.0, 0.0), (160.0, 0.0), (160.0, 160.0 * math.tan(inca / 2.0)),
             (160.0 * math.cos(inca), 160.0 * math.sin(inca))]
    place(m, {"pose": {"trans": [*corner, -100.0], "rot": [0.0, 0.0, ref]},
              "features": [{"type": "prism", "polygon": wedge, "height": 60}]})
    m.ok(m.c.post("/api/machine/tool", json={"tool": m.scen["probe"]["t"]}))
    m.ok(m.c.post("/api/machine/activate", json={"offset": "G500"}))
    m.ok(m.c.post("/api/machine/goto", json={"X": start[0], "Y": start[1], "Z": start[2], "coords": "WCS"}))
    before = m.offset("G55")
    answer = m.run(ECKE_EINRICHTEN_14904, replace=ARTEFACT)
    assert answer["state"] == "done", answer
    g55 = m.offset("G55")
    assert [g55["trans"]["X"], g55["trans"]["Y"]] == pytest.approx(list(corner), abs=1e-6)
    assert [g55["fine"][a] for a in "XYZ"] == pytest.approx([0.0, 0.0, 0.0], abs=1e-12)
    assert g55["rot"]["Z"] == pytest.approx(ref, abs=1e-6)
    assert [g55["rot"]["X"], g55["rot"]["Y"]] == pytest.approx([0.0, 0.0], abs=1e-12)
    assert g55["trans"]["Z"] == pytest.approx(before["trans"]["Z"], abs=1e-12)
    ovr = m.ovr()
    assert [ovr[4], ovr[5], ovr[6]] == pytest.approx([ref, *corner], abs=1e-6)      # G500: WCS = MCS
    assert [ovr[20], ovr[21], ovr[22]] == pytest.approx([ref, *corner], abs=1e-6)
    # back at the start, seen from the new G55 (N40): S − K turned by −ref
    c, s = _unit(-ref)
    d = (start[0] - corner[0], start[1] - corner[1])
    wcs = m.wcs()
    assert (wcs["X"], wcs["Y"]) == pytest.approx((c * d[0] - s * d[1], s * d[0] + c * d[1]), abs=1e-6)

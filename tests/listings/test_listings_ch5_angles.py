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
from listing_kit import G54, PROBE_LENGTH, Machine
from manual_listings import (
    BESTIMME_KS_16181,
    ECKE_EINRICHTEN_1_15334,
    ECKE_EINRICHTEN_14904,
    SCHRAEGE_MESSEN_14059,
    WINKEL_MESSEN_13780,
)

ARTEFACT = {"循环": "CYCLE"}   # the Chinese print translated the cycle names (issue 28)


def place(m: Machine, workpiece: dict, g54=G54["block"], **extra) -> None:
    """The scenario of ``m`` with ``workpiece`` (MCS pose) in place of the kit's block; ``extra``:
    top-level scenario keys, ``machine_extra``: keys of its ``machine``."""
    scen = copy.deepcopy(m.scen)
    scen["workpiece"] = workpiece
    scen["machine"].update(extra.pop("machine_extra", {}))
    scen.update(extra)
    m.scen = scen
    m.ok(m.c.post("/api/sim/scenario", json={**scen, "reset_data": True}))
    m.put_offset("G54", g54)


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


TURN = 1.5      # deg: the part's true turn on the rotary table at C = 0 (measuring-math worked example 11.1-A)


def test_angle_onto_the_rotary_table_c(client):
    """§5.7 %—N-角度测量—MPF (lines 13780–13799): CYCLE998 _MVAR=105 _MA=102 (offset X, measuring Y)
    _SETVAL=−18 _ID=40 _STA1=0 _TSA=5 _RA=4 (the channel's 4th axis, the rotary table C) from
    X−20 Y−40 Z40 in G54: the angle goes into G54's C offset; N90 ``G54 C0`` then turns the table
    so that the edge lies along X. Part: a 200 × 120 × 60 block on a table C (centre G54 20, 40),
    top face Z60, its front edge through G54 (−20, −18) turned +1.5° about Z at C = 0 (the
    simulator's DIN 66217 table: C+ turns the part clockwise seen from +Z, measuring-math §11.1).
    Adapted: the machine gets the table the listing needs (axes X Y Z C), nothing in the text
    but the cycle name."""
    m = Machine(client)
    x0 = -80.0
    y0 = -18.0 - (-20.0 - x0) * math.tan(math.radians(TURN))
    org = [G54["block"][0] + x0, G54["block"][1] + y0, G54["block"][2] + 60.0]
    place(m, {"pose": {"trans": org, "rot": [0.0, 0.0, TURN]},
              "features": [{"type": "block", "size": [200, 120, 60]}]},
          rotary_axes={"C": {"limits": [-360, 360]}},
          machine_extra={"rotary_table": {"axis": "C", "center": [G54["block"][0] + 20.0, G54["block"][1] + 40.0]}})
    before = m.offset("G54")
    answer = m.run(WINKEL_MESSEN_13780, replace=ARTEFACT)
    assert answer["state"] == "done", answer
    after = m.offset("G54")
    assert after["trans"]["C"] == pytest.approx(before["trans"].get("C", 0.0) + TURN, abs=1e-6)
    assert [after["rot"][a] for a in "XYZ"] == pytest.approx([0.0, 0.0, 0.0], abs=1e-12)   # frame not turned
    assert [after["trans"][a] for a in "XYZ"] == pytest.approx([before["trans"][a] for a in "XYZ"], abs=1e-12)
    ovr = m.ovr()
    assert [ovr[0], ovr[4], ovr[16], ovr[20], ovr[28]] == pytest.approx([0.0, TURN, TURN, TURN, 5.0], abs=1e-6)
    status = m.ok(m.c.get("/api/machine"))
    # N90 G54 C0: the table at C = +1.5 in the MCS turns the part by −1.5°: its edge along X (truth)
    assert status["mcs"]["C"] == pytest.approx(TURN, abs=1e-6)
    assert TURN - status["mcs"]["C"] == pytest.approx(0.0, abs=1e-6)
    assert status["wcs"]["C"] == pytest.approx(0.0, abs=1e-9)
    assert status["wcs"]["Z"] == pytest.approx(160.0, abs=1e-6)                            # N80


def test_two_angle_plane_listing_is_refused_by_variant(client):
    """§5.7.2 %_N_斜面测量_MPF (lines 14059–14073): CYCLE998 _MVAR=106 (two angles, the inclined
    plane, setpoints _STA1=8° about X and _INCA=12° about Y). The 2-angle variants are not
    implemented in the NC (app/nc/cycles/workpiece.py ``_axes998``; the JOG task "Orient plane"
    measures planes): the run ends in alarm 61307 (wrong measuring variant) naming ``_MVAR=106``
    before any probing, and G54 is unchanged. Part: the kit's block (top Z20) moved so that the
    printed X70 Y−10 lies over it. Not a truth run: documents the refusal.

    As printed, the run stops earlier: N30 X70 Y−10 has neither G0 nor F, and the channel's reset
    state is G1 (app/nc/modal.py; the 840D's GCODE_RESET_VALUES default): alarm 10860 in line 4
    (N30), nothing moved. Adapted for the second run: ``N30 G0 X70`` (rapid, as N80 of §5.7)."""
    m = Machine(client, part={"origin": (0.0, -50.0, 20.0), "size": (200, 150, 60)})
    before = m.offset("G54")
    printed = m.run(SCHRAEGE_MESSEN_14059, replace=ARTEFACT)
    assert printed["state"] == "alarm" and printed["alarm"]["code"] == 10860, printed
    assert printed["block"]["number"] == 30 and "no feed programmed" in printed["alarm"]["message"], printed
    assert m.offset("G54") == before
    answer = m.run(SCHRAEGE_MESSEN_14059, replace={**ARTEFACT, "N30 X70": "N30 G0 X70"})
    assert answer["state"] == "alarm" and answer["alarm"]["code"] == 61307, answer
    assert "_MVAR=106" in answer["alarm"]["message"] and "2-angle" in answer["alarm"]["message"], answer["alarm"]
    after = m.offset("G54")
    assert after == before
    wcs = m.wcs()
    assert (wcs["X"], wcs["Y"]) == pytest.approx((70.0, -10.0), abs=1e-9)                   # N30, no probing


# the print's own marks, not NC (as test_listings_load.PRINT_MARKS): the _SETV expression wrapped
# over two lines is rejoined, the "..." for the blocks left out is dropped
SPHERE_MARKS = {"600, \n\n100,": "600, 100,", "\n  ...  \n": "\n"}
SPHERE_G54 = (0.0, 0.0, -200.0)
SPHERE_SHIFT = (0.3, -0.2, 0.1)     # the fixture's true pose: G54 + shift, turned by SPHERE_TURN about Z
SPHERE_TURN = 0.04                  # deg
SETPOINTS = ((100.0, 100.0, 100.0), (600.0, 100.0, 100.0), (1100.0, 1100.0, 100.0))


def _rz(deg: float, p) -> tuple[float, float, float]:
    c, s = _unit(deg)
    return c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]


def test_three_spheres_set_the_active_frame(client):
    """§5.9 %_N_ BESTIMME_KS _MPF (lines 16181–16208): CYCLE997 _MVAR=010109 (three spheres,
    paraxial) Ø50 (_SETVAL) at the setpoints _SETV = (100, 100, 100), (600, 100, 100),
    (1100, 1100, 100) in G54, _KNUM=9999 (the active frame, G54), _TNVL=1.2, probe T20: G54 gets
    translation and rotation so that the three true sphere centres lie at their setpoints.
    Truth: three Ø50 spheres (no block) whose centres are the setpoints in a fixture frame at
    G54 + (0.3, −0.2, 0.1) turned 0.04° about Z (sphere 3 lies 1.1 mm off its setpoint, inside
    the default _TSA and the _FA=5 path). Adapted: the print's wrapped ``_SETV`` line rejoined
    and its "..." dropped (as test_listings_load.PRINT_MARKS); T20's L1 = its true length (calibrated); the machine's X/Y limits widened
    to reach X1100 Y1100 and G54 = (0, 0, −200), so that Z200 and the spheres fit the Z travel."""
    m = Machine(client, probe_t=20)
    m.scen["probe"]["nominal"]["length"] = PROBE_LENGTH      # a length-calibrated probe (the kit types L1 0.2 long)
    origin = [g + d for g, d in zip(SPHERE_G54, SPHERE_SHIFT, strict=True)]
    place(m, {"pose": {"trans": origin, "rot": [0.0, 0.0, SPHERE_TURN]},
              "features": [{"type": "sphere", "center": list(q), "diameter": 50.0} for q in SETPOINTS]},
          g54=SPHERE_G54,
          machine_extra={"limits": {"X": [-300, 1400], "Y": [-300, 1400], "Z": [-400, 300]}})
    answer = m.run(BESTIMME_KS_16181, replace={**ARTEFACT, **SPHERE_MARKS})
    assert answer["state"] == "done", answer
    g54 = m.offset("G54")
    trans = [g54["trans"][a] + g54["fine"][a] for a in "XYZ"]
    assert [g54["rot"]["X"], g54["rot"]["Y"]] == pytest.approx([0.0, 0.0], abs=1e-9)
    assert g54["rot"]["Z"] == pytest.approx(SPHERE_TURN, abs=1e-9)
    for q in SETPOINTS:     # the new G54 maps each setpoint onto the true sphere centre (MCS)
        true_centre = [o + r for o, r in zip(origin, _rz(SPHERE_TURN, q), strict=True)]
        mapped = [t + r for t, r in zip(trans, _rz(g54["rot"]["Z"], q), strict=True)]
        assert mapped == pytest.approx(true_centre, abs=1e-6)
    ovr = m.ovr()
    assert [ovr[0], *ovr[1:4]] == pytest.approx([50.0, *SETPOINTS[0]], abs=1e-9)
    for d_slot in (4, 12, 20):                              # diameters; centres in the old G54 below
        assert ovr[d_slot] == pytest.approx(50.0, abs=1e-6)
    for c_slot, q in zip((5, 13, 21), SETPOINTS, strict=True):
        true_in_old = [o - g + r for o, g, r in zip(origin, SPHERE_G54, _rz(SPHERE_TURN, q), strict=True)]
        assert ovr[c_slot:c_slot + 3] == pytest.approx(true_in_old, abs=1e-6)

"""More chapter-5 listings (§5.4.1, §5.5.3, §5.6.2, §5.6.3) and CYCLE979 slot/web at an angle, run
against the scenario's truth.

Adapted: ``循环`` → ``CYCLE`` (the Chinese print's translation of the cycle names), nothing else in
the text. The part is placed so that the printed positions fit (listing_kit's G54 "block" frame;
for §5.6.3 the same values in G55, the listing's frame), a little off where the print expects
it: that error is what the cycles must find. The cutter T20 that the listings correct
(``_TNUM=20``) is added to the scenario's tools. Truth: the features as placed here (sizes,
centres); for tool offsets the correction that measuring-math §3.5/§2.3 gives for the chosen
deviation under the listing's own tolerances. The probe is noise-free, pre-travel 0, record 1
as reset, so every value is exact (1e-6 mm).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from listing_kit import G54, Machine, scenario
from manual_listings import (
    BOHRUNG_SEGMENT_12711,
    EIN_PUNKT_MESSUNG_11975,
    STEG_MESSEN_10756,
    VERSCHIEBUNG_NUT_12979,
)

ARTEFACT = {"循环": "CYCLE"}
T20 = {"t": 20, "type": 120, "length": 90.0, "radius": 8.0}


def _load(m: Machine, part: dict, rot_z: float = 0.0, tools: tuple = ()) -> None:
    """Post listing_kit's scenario with ``part``, the part turned by ``rot_z`` degrees about its
    origin and the extra ``tools``; G54 (and G55) = listing_kit's block frame."""
    scen = scenario(part=part)
    scen["workpiece"]["pose"]["rot"] = [0.0, 0.0, rot_z]
    scen["tools"].extend(dict(t) for t in tools)
    m.scen = scen
    m.ok(m.c.post("/api/sim/scenario", json={**scen, "reset_data": True}))
    m.put_offset("G54", G54["block"])
    m.put_offset("G55", G54["block"])


def _total(offset: dict) -> list[float]:
    return [offset["trans"][a] + offset["fine"][a] for a in "XYZ"]


def test_web_listing_measures_width_and_centre_without_correcting(client):
    """§5.4.1 %_N_STEG_MESSEN_MPF (lines 10756–10791): CYCLE977 _MVAR=104 (web in X, _MA=1,
    _SETVAL=132, _ID=−40 from the start Z101, _KNUM=0): the web's true width and centre come
    out, the centre difference is within _TSA=1.2, and nothing is corrected (_KNUM=0).
    Part: a web (boss) 131.98 wide in X, 200 long in Y, centred on G54 X220.3 Y130, top Z90 on a
    block whose top is Z20 (measuring height Z101 − 40 = Z61 lies on its flanks)."""
    width, centre_x = 131.98, 220.3
    web = {"type": "boss", "center": [centre_x, 130.0], "size": [width, 200.0], "height": 70.0}
    m = Machine(client)
    _load(m, {"origin": (0.0, 0.0, 20.0), "size": (400, 300, 60), "features": [web]})
    before = {n: _total(m.offset(n)) for n in ("G54", "G55")}
    answer = m.run(STEG_MESSEN_10756, replace=ARTEFACT)
    assert answer["state"] == "done", answer
    ovr = m.ovr()
    assert ovr[0] == pytest.approx(132.0)                          # setpoint width
    assert ovr[1] == pytest.approx(220.0)                          # setpoint centre = start X
    assert ovr[4] == pytest.approx(width, abs=1e-6)
    assert ovr[5] == pytest.approx(centre_x, abs=1e-6)
    assert ovr[16] == pytest.approx(width - 132.0, abs=1e-6)
    assert ovr[17] == pytest.approx(centre_x - 220.0, abs=1e-6)
    assert m.ovi()[2] == 977
    assert {n: _total(m.offset(n)) for n in ("G54", "G55")} == before   # _KNUM=0: no correction
    assert m.wcs()["Z"] == pytest.approx(160.0)                    # N80


@pytest.mark.parametrize(("deviation", "wear"), [
    (0.025, -0.025),    # |D| > _TMV 0.02, inside _TUL 0.03: 100 % of D, c = σ·D, σ = −1 (travel −X)
    (0.015, 0.0),       # |D| ≤ _TMV: mean Mv = 0.015/3 = 0.005 ≤ _TZL 0.01: no correction
])
def test_one_point_listing_corrects_the_radius_of_t20(client, deviation, wear):
    """§5.5.3 %_N_EIN_PUNKT_MESSUNG_MPF (lines 11975–11991): CYCLE978 _MVAR=0 on the face X100
    (_SETVAL=100, _MA=1, probe from X120 travelling −X), _KNUM=2001 (D1, radius, normal),
    _TNUM=20, mean value on (_CHBIT[4]=1, _K=3, _EVNUM=20), memory empty. Part: a block whose +X
    face lies at G54 X100 + deviation, top Z60 (the printed Z40 is on its side).
    measuring-math §3.5: |D| > _TMV → 100 % of D; else Mv = D/3 (memory 0), corrected only when
    |Mv| > _TZL. §9.1: c = σ·D, the whole position difference, on T20 D1's radius wear."""
    m = Machine(client)
    _load(m, {"origin": (100.0 + deviation - 200.0, 0.0, 60.0), "size": (200, 300, 100)}, tools=(T20,))
    before = m.tool(20)
    answer = m.run(EIN_PUNKT_MESSUNG_11975, replace=ARTEFACT)
    assert answer["state"] == "done", answer
    ovr = m.ovr()
    assert ovr[4] == pytest.approx(100.0 + deviation, abs=1e-6)
    assert ovr[16] == pytest.approx(deviation, abs=1e-6)
    assert ovr[20] == pytest.approx(wear, abs=1e-6)
    after = m.tool(20)
    assert after["wear"]["radius"] - before["wear"]["radius"] == \
        pytest.approx(wear, abs=1e-6)
    assert {k: v for k, v in after.items() if k != "wear"} == {k: v for k, v in before.items() if k != "wear"}
    assert {k: v for k, v in after["wear"].items() if k != "radius"} == \
        {k: v for k, v in before["wear"].items() if k != "radius"}
    if wear == 0.0:
        mv = m.ok(m.c.get("/api/nc/variables", params={"names": "_MV"}))["_MV"]
        assert mv[19] == pytest.approx(deviation / 3, abs=1e-6)     # stored mean, _EVNUM=20
    assert m.wcs()["Z"] == pytest.approx(160.0)


def test_hole_segment_listing_corrects_the_radius_of_t20(client):
    """§5.6.2 %_N_BOHRUNG_SEGMENT_MPF (lines 12711–12731): CYCLE979 _MVAR=1 (bore, 3 points at
    15°, 95°, 175°, _SETVAL=130, setpoint centre _CPA=180 _CPO=0), _KNUM=2001, _TNUM=20. Part: a
    bore Ø130.024 at G54 (180.02, −0.015), 40 deep from the top Z40 (measuring height Z20); the
    start X210 Y−20 lies inside it. D = 0.024 > _TMV, inside _TUL → 100 %: bore c = +D/2 on T20
    D1's radius wear (measuring-math §2.3, §3.5)."""
    diameter, centre = 130.024, (180.02, -0.015)
    origin = (0.0, -150.0, 40.0)
    hole = {"type": "hole", "center": [centre[0] - origin[0], centre[1] - origin[1]],
            "diameter": diameter, "depth": 40.0}
    m = Machine(client)
    _load(m, {"origin": origin, "size": (360, 300, 60), "features": [hole]}, tools=(T20,))
    before = m.tool(20)
    answer = m.run(BOHRUNG_SEGMENT_12711, replace=ARTEFACT)
    assert answer["state"] == "done", answer
    ovr = m.ovr()
    assert ovr[4] == pytest.approx(diameter, abs=1e-6)
    assert ovr[5:7] == pytest.approx(list(centre), abs=1e-6)
    assert ovr[16] == pytest.approx(diameter - 130.0, abs=1e-6)
    assert ovr[17:19] == pytest.approx([centre[0] - 180.0, centre[1]], abs=1e-6)
    assert ovr[20] == pytest.approx((diameter - 130.0) / 2, abs=1e-6)
    after = m.tool(20)
    assert after["wear"]["radius"] - before["wear"]["radius"] == \
        pytest.approx((diameter - 130.0) / 2, abs=1e-6)
    assert m.ovi()[2] == 979
    assert m.wcs()["Z"] == pytest.approx(160.0)


def _line(angle: float, cp, along: float = 0.0, across: float = 0.0):
    """û = (cos angle, sin angle), n̂ its normal (û turned +90°), and the point ``along`` û and
    ``across`` n̂ from ``cp`` (the feature's true middle): the truth of measuring-math §10.2."""
    u = np.array([math.cos(math.radians(angle)), math.sin(math.radians(angle))])
    n = np.array([-u[1], u[0]])
    return u, n, np.asarray(cp, float) + along * u + across * n


def _turned_block(centre: tuple[float, float], angle: float, size: tuple[float, float], top: float,
                  feature: dict) -> dict:
    """A block ``size`` (part x along û = (cos angle, sin angle)) turned by ``angle`` about Z with
    its centre at G54/G55 ``centre`` and ``feature`` in its middle; the part's top at Z ``top``."""
    u, n, _ = _line(angle, (0.0, 0.0))
    cx, cy = size[0] / 2, size[1] / 2
    origin = (centre[0] - (u[0] * cx + n[0] * cy), centre[1] - (u[1] * cx + n[1] * cy), top)
    return {"origin": origin, "size": (*size, 100), "features": [{**feature, "center": [cx, cy]}]}


def test_slot_at_70_degrees_listing_shifts_g55_along_the_line_by_the_slots_true_middle(client):
    """§5.6.3 %_N_VERSCHIEBUNG_NUT_MPF (lines 12979–12998): CYCLE979 _MVAR=103 (slot, ZO) along
    û = (cos 70°, sin 70°) through _CPA=150 _CPO=130, _SETVAL=130, _FA=2, _TSA=0.8, _KNUM=2 → G55.
    Part: the block turned 70° about Z with a slot 130.01 wide along û, 80 long, 40 deep from
    the top Z60 (the printed Z40 is measuring height); the slot's middle lies 0.3 along û and
    0.2 across it from (150, 130). measuring-math §10.2: only the middle's component along the
    line is known, so G55 += ((mid − CP)·û)·û = 0.3·û (both components within _TSA, manual
    §5.6.3); G54 is unchanged. The cycle ends with the ball _FA before P2's nominal wall
    (P2' = CP − (65 − ρ − _FA)·û, ρ = 2), N80 lifts to Z160, N90 reads it in the new G55."""
    along, across, width, angle = 0.3, 0.2, 130.01, 70.0
    cp = np.array([150.0, 130.0])
    u, n, mid = _line(angle, cp, along, across)
    m = Machine(client)
    _load(m, _turned_block(tuple(mid), angle, (200.0, 160.0), 60.0,
                           {"type": "pocket", "size": [width, 80.0], "depth": 40.0}), rot_z=angle)
    g54, g55 = _total(m.offset("G54")), _total(m.offset("G55"))
    answer = m.run(VERSCHIEBUNG_NUT_12979, replace=ARTEFACT)
    assert answer["state"] == "done", answer
    shift = along * u                                              # ((mid − CP)·û)·û
    assert _total(m.offset("G55")) == pytest.approx([g55[0] + shift[0], g55[1] + shift[1], g55[2]], abs=1e-6)
    assert _total(m.offset("G54")) == g54
    ovr = m.ovr()
    assert ovr[0] == pytest.approx(130.0)                          # setpoint width
    assert ovr[1:3] == pytest.approx(list(cp))                     # setpoint centre
    assert ovr[4] == pytest.approx(width, abs=1e-6)
    assert ovr[5:7] == pytest.approx(list(cp + shift), abs=1e-6)
    assert ovr[16] == pytest.approx(width - 130.0, abs=1e-6)
    assert ovr[17:19] == pytest.approx(list(shift), abs=1e-6)
    assert ovr[28] == pytest.approx(0.8)                           # _TSA
    assert m.ovi()[0] == 2 and m.ovi()[2] == 979 and m.ovi()[11] == 1
    end = cp - (65.0 - 2.0 - 2.0) * u - shift                      # P2', read in the corrected G55
    wcs = m.wcs()
    assert [wcs[a] for a in "XYZ"] == pytest.approx([end[0], end[1], 160.0], abs=1e-6)


def _at(point) -> str:
    return f"X{point[0]:.6f} Y{point[1]:.6f}"


def test_web_at_25_degrees_shifts_g54_along_the_line_by_the_webs_true_middle(client):
    """CYCLE979 _MVAR=104 (web, ZO into G54, _KNUM=1) along û = (cos 25°, sin 25°) through
    _CPA=120 _CPO=90, _SETVAL=40, _FA=2, _ID=50. Part: a web (boss) 39.98 wide along û, 120 long
    across it, from the block's top Z20 up to Z90, its middle 0.15 along û and 0.4 across it from
    (120, 90). The probe starts at measuring height Z50 on the +û side near P1 (manual §5.6.1);
    P1 travels −û, the probe lifts by _ID to Z100 (ball 8 above the web) to cross over to P2',
    P2 travels +û. measuring-math §10.2: W = (s2 − s1)·û, G54 += ((mid − CP)·û)·û = 0.15·û; the
    cycle ends at P2' = CP − (20 + ρ + _FA)·û, ρ = 2, at the measuring height."""
    along, across, width, angle = 0.15, 0.4, 39.98, 25.0
    cp = np.array([120.0, 90.0])
    u, n, mid = _line(angle, cp, along, across)
    m = Machine(client)
    _load(m, _turned_block(tuple(mid), angle, (200.0, 160.0), 20.0,
                           {"type": "boss", "size": [width, 120.0], "height": 70.0}), rot_z=angle)
    g54 = _total(m.offset("G54"))
    program = (f"G54 G17 G90 T9 D1\nM6\nG0 Z120\n{_at(cp + 30.0 * u)}\nZ50\n"
               "_TSA=1 _PRNUM=1 _VMS=0 _NMSP=1 _FA=2\n"
               "_MVAR=104 _SETVAL=40 _CPA=120 _CPO=90 _STA1=25 _ID=50 _KNUM=1\n"
               "CYCLE979\nG0 Z160\nG54\nM2")
    answer = m.mda(program)
    assert answer["state"] == "done", answer
    shift = along * u
    assert _total(m.offset("G54")) == pytest.approx([g54[0] + shift[0], g54[1] + shift[1], g54[2]], abs=1e-6)
    ovr = m.ovr()
    assert ovr[0] == pytest.approx(40.0)
    assert ovr[1:3] == pytest.approx(list(cp))
    assert ovr[4] == pytest.approx(width, abs=1e-6)
    assert ovr[5:7] == pytest.approx(list(cp + shift), abs=1e-6)
    assert ovr[16] == pytest.approx(width - 40.0, abs=1e-6)
    assert ovr[17:19] == pytest.approx(list(shift), abs=1e-6)
    assert m.ovi()[0] == 1 and m.ovi()[2] == 979 and m.ovi()[11] == 1
    end = cp - (20.0 + 2.0 + 2.0) * u - shift                      # P2', read in the corrected G54
    wcs = m.wcs()
    assert [wcs[a] for a in "XYZ"] == pytest.approx([end[0], end[1], 160.0], abs=1e-6)


def test_slot_at_minus_35_degrees_corrects_the_radius_of_t20(client):
    """CYCLE979 _MVAR=3 (slot, tool offset) along û = (cos −35°, sin −35°) through _CPA=120
    _CPO=60, _SETVAL=30, _KNUM=2001 (D1, radius), _TNUM=20, the tolerances of the §5.6.2 listing
    (_TUL=0.03 _TLL=−0.03 _TMV=0.02 _TZL=0.01, mean value on, _K=3, memory empty). Part: a slot
    30.024 wide along û, 100 long across it, 40 deep from the top Z40, its middle 0.1 along û
    and 0.3 across it from (120, 60); measuring height Z20. D = 0.024 > _TMV, inside _TUL →
    100 %: slot c = +D/2 on T20 D1's radius wear (measuring-math §2.3, §3.5); no ZO changes."""
    along, across, width, angle = 0.1, 0.3, 30.024, -35.0
    cp = np.array([120.0, 60.0])
    u, n, mid = _line(angle, cp, along, across)
    m = Machine(client)
    _load(m, _turned_block(tuple(mid), angle, (200.0, 160.0), 40.0,
                           {"type": "pocket", "size": [width, 100.0], "depth": 40.0}), rot_z=angle, tools=(T20,))
    g54, before = _total(m.offset("G54")), m.tool(20)
    program = (f"G54 G17 G90 T9 D1\nM6\nG0 {_at(cp)}\nZ20\n_CHBIT[4]=1\n"
               "_TUL=0.03 _TLL=-0.03 _EVNUM=20 _K=3 _TZL=0.01 _TMV=0.02 _TDIF=0.06 _TSA=1 _PRNUM=1 "
               "_VMS=0 _NMSP=1 _FA=2\n"
               "_MVAR=3 _SETVAL=30 _STA1=-35 _TNUM=20 _KNUM=2001 _CPA=120 _CPO=60\n"
               "CYCLE979\nG0 Z160\nM2")
    answer = m.mda(program)
    assert answer["state"] == "done", answer
    ovr = m.ovr()
    assert ovr[4] == pytest.approx(width, abs=1e-6)
    assert ovr[5:7] == pytest.approx(list(cp + along * u), abs=1e-6)
    assert ovr[16] == pytest.approx(width - 30.0, abs=1e-6)
    assert ovr[20] == pytest.approx((width - 30.0) / 2, abs=1e-6)
    after = m.tool(20)
    assert after["wear"]["radius"] - before["wear"]["radius"] == pytest.approx((width - 30.0) / 2, abs=1e-6)
    assert m.ovi()[0] == 1 and m.ovi()[8] == 20 and m.ovi()[2] == 979
    assert _total(m.offset("G54")) == g54
    end = cp - (15.0 - 2.0 - 2.0) * u                              # P2'
    wcs = m.wcs()
    assert [wcs[a] for a in "XYZ"] == pytest.approx([end[0], end[1], 160.0], abs=1e-6)


@pytest.mark.parametrize(("params", "named"), [
    ("_MVAR=103 _STA1=400 _ID=0", "_STA1 = 400"),       # _STA1 lies within −360..360 (manual §5.6)
    ("_MVAR=104 _STA1=25 _ID=0", "_ID = 0"),            # the web is crossed at measuring height + _ID
    ("_MVAR=104 _STA1=25 _ID=-10", "_ID = -10"),
])
def test_slot_or_web_with_a_parameter_out_of_range_is_refused_before_any_motion(client, params, named):
    """CYCLE979 slot/web refuses a start angle outside −360..360° and a web without a lift _ID > 0
    (65103 naming the parameter) before it moves: the probe stays where it was, G54 unchanged."""
    m = Machine(client)
    _load(m, {"origin": (0.0, 0.0, 20.0), "size": (300, 200, 60)})
    g54 = _total(m.offset("G54"))
    answer = m.mda(f"G54 G17 G90 T9 D1\nM6\nG0 X100 Y80 Z60\n_FA=2 _KNUM=1 _SETVAL=40 _CPA=100 _CPO=80 "
                   f"{params}\nCYCLE979\nM2")
    assert answer["state"] == "alarm" and answer["alarm"]["code"] == 65103, answer
    assert named in answer["alarm"]["message"], answer["alarm"]
    assert _total(m.offset("G54")) == g54
    wcs = m.wcs()
    assert [wcs[a] for a in "XYZ"] == pytest.approx([100.0, 80.0, 60.0], abs=1e-9)


@pytest.mark.parametrize(("along", "corrected"), [
    (0.82, True),       # d = 0.82·û = (0.280, 0.771): both axes < _TSA 0.8 though |d| > 0.8
    (0.9, False),       # d = (0.308, 0.846): Y beyond _TSA → 61303, nothing written
])
def test_slot_listing_checks_the_safe_area_on_each_axis(client, along, corrected):
    """§5.6.3 as printed (_TSA=0.8), the slot 130.01 wide with its middle ``along`` û from
    (150, 130): the manual's explanation (line 13001 ff.) corrects G55 when the centre's
    differences on both axes are below _TSA, else alarm "safe area exceeded" (61303) and G55 stays."""
    angle, width = 70.0, 130.01
    u, _n, mid = _line(angle, (150.0, 130.0), along)
    m = Machine(client)
    _load(m, _turned_block(tuple(mid), angle, (200.0, 160.0), 60.0,
                           {"type": "pocket", "size": [width, 80.0], "depth": 40.0}), rot_z=angle)
    g55 = _total(m.offset("G55"))
    answer = m.run(VERSCHIEBUNG_NUT_12979, replace=ARTEFACT)
    if corrected:
        assert answer["state"] == "done", answer
        shift = along * u
        assert _total(m.offset("G55")) == pytest.approx([g55[0] + shift[0], g55[1] + shift[1], g55[2]], abs=1e-6)
    else:
        assert answer["state"] == "alarm" and answer["alarm"]["code"] == 61303, answer
        assert answer["block"]["number"] == 70, answer["block"]
        assert _total(m.offset("G55")) == g55


def test_web_at_25_degrees_corrects_the_radius_of_t20(client):
    """CYCLE979 _MVAR=4 (web, tool offset) along û = (cos 25°, sin 25°) through _CPA=120 _CPO=90,
    _SETVAL=40, _ID=50, _KNUM=2001, _TNUM=20, the §5.6.2 listing's tolerances. Part: a web 40.024
    wide along û from Z20 up to Z90, its middle 0.05 along û from (120, 90). D = 0.024 > _TMV,
    inside _TUL → 100 %: web c = −D/2 on T20 D1's radius wear (measuring-math §2.3, §3.5)."""
    along, width, angle = 0.05, 40.024, 25.0
    cp = np.array([120.0, 90.0])
    u, _n, _mid = _line(angle, cp)
    m = Machine(client)
    _load(m, _turned_block(tuple(cp + along * u), angle, (200.0, 160.0), 20.0,
                           {"type": "boss", "size": [width, 120.0], "height": 70.0}), rot_z=angle, tools=(T20,))
    g54, before = _total(m.offset("G54")), m.tool(20)
    answer = m.mda(f"G54 G17 G90 T9 D1\nM6\nG0 Z120\n{_at(cp + 30.0 * u)}\nZ50\n_CHBIT[4]=1\n"
                   "_TUL=0.03 _TLL=-0.03 _EVNUM=20 _K=3 _TZL=0.01 _TMV=0.02 _TDIF=0.06 _TSA=1 _PRNUM=1 "
                   "_VMS=0 _NMSP=1 _FA=2\n"
                   "_MVAR=4 _SETVAL=40 _STA1=25 _ID=50 _TNUM=20 _KNUM=2001 _CPA=120 _CPO=90\n"
                   "CYCLE979\nG0 Z160\nM2")
    assert answer["state"] == "done", answer
    ovr = m.ovr()
    assert ovr[4] == pytest.approx(width, abs=1e-6)
    assert ovr[5:7] == pytest.approx(list(cp + along * u), abs=1e-6)
    assert ovr[20] == pytest.approx(-(width - 40.0) / 2, abs=1e-6)
    after = m.tool(20)
    assert after["wear"]["radius"] - before["wear"]["radius"] == pytest.approx(-(width - 40.0) / 2, abs=1e-6)
    assert _total(m.offset("G54")) == g54

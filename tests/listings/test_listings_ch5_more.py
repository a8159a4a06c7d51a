"""More chapter-5 listings (§5.4.1, §5.5.3, §5.6.2, §5.6.3) run as printed, against the scenario's truth.

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


def test_slot_at_70_degrees_listing_is_refused_and_changes_nothing(client):
    """§5.6.3 %_N_VERSCHIEBUNG_NUT_MPF (lines 12979–12998): CYCLE979 _MVAR=103 (slot, ZO) along
    û = (cos 70°, sin 70°) through _CPA=150 _CPO=130, _SETVAL=130, _KNUM=2 → G55. The control
    does not implement slot/web at an angle (variants 3/4/103/104): N70 ends in alarm 61307
    naming _MVAR=103, before any motion (the probe stays at N30/N40's X150 Y130 Z40 in G55) and
    with G54 and G55 unchanged. PRODUCT GAP (reported, not fixed): measuring-math §10.2 wants
    G55 += ((mid − CP)·û)·û; for the part below that is 0.3·û.
    Part (ready for that truth test): the block turned 70° about Z with a slot 130.01 wide
    across û, 80 long, 40 deep from the top Z60 (the printed Z40 is measuring height); the
    slot's middle lies 0.3 along û and 0.2 across it from (150, 130)."""
    along, across, width = 0.3, 0.2, 130.01
    u = (math.cos(math.radians(70)), math.sin(math.radians(70)))
    n = (-u[1], u[0])
    mid = (150.0 + along * u[0] + across * n[0], 130.0 + along * u[1] + across * n[1])
    size = (200.0, 160.0)                          # block; part x runs along û
    # part origin such that the block's centre (size/2 in part coords, turned by 70°) is at mid
    cx, cy = size[0] / 2, size[1] / 2
    origin = (mid[0] - (u[0] * cx + n[0] * cy), mid[1] - (u[1] * cx + n[1] * cy), 60.0)
    slot = {"type": "pocket", "center": [cx, cy], "size": [width, 80.0], "depth": 40.0}
    m = Machine(client)
    _load(m, {"origin": origin, "size": (*size, 100), "features": [slot]}, rot_z=70.0)
    g54, g55 = _total(m.offset("G54")), _total(m.offset("G55"))
    answer = m.run(VERSCHIEBUNG_NUT_12979, replace=ARTEFACT)
    assert answer["state"] == "alarm" and answer["alarm"]["code"] == 61307, answer
    assert answer["block"]["number"] == 70, answer["block"]
    assert "_MVAR=103" in answer["alarm"]["message"], answer["alarm"]
    assert "slot and web at an angle" in answer["alarm"]["message"], answer["alarm"]
    assert _total(m.offset("G54")) == g54 and _total(m.offset("G55")) == g55
    wcs = m.wcs()
    assert [wcs[a] for a in "XYZ"] == pytest.approx([150.0, 130.0, 40.0], abs=1e-9)

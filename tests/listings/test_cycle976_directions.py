"""CYCLE976 in a bore with one or two directions, and at an angle (manual §5.3 table of _MVAR,
§5.3.1 _MA/_MD/_STA1, §5.3.2; measuring-math §7.2–7.4), against the scenario's truth.

The machine is the ring listing's (tests/listings/listing_kit.py): a ring of Ø110.246 with its
centre at G54 X100 Y80, the calibration height Z10, probe T9 with a Ø4 ball whose centre is ``ECC``
off the spindle axis. The program is the manual's %_N_KALIBRIEREN_IN_X_Y_MPF (§5.3.1) with the
variant changed. Truth (measuring-math §5.1): the trigger value of a field is the ball centre the
NC believes (rec + stored skew) minus the surface, along the axis; on a diameter of the ring this
is ∓(r − δ); a ball that travels ``h`` off the diameter touches the wall at the distance
√(ρ² − h²) from the centre along its travel (ρ = D/2 − r).
"""

from __future__ import annotations

import math

import pytest
from listing_kit import RING_D, Machine

R = 2.0
DELTA = 0.004
ECC = (0.010, -0.006)
RHO = RING_D / 2.0 - R          # distance ring centre → ball centre at first contact on a diameter


def program(mvar: str, extra: str = "", prnum: int = 2, tsa: float = 4.0) -> str:
    """§5.3.1's listing (lines 8980–8998) with the variant ``mvar`` and ``extra`` parameters."""
    return ("G54 G90 G17 T9 D1\nM6\nG0 X100.000 Y80.000\nZ10\n_CBIT[14]=0\n"
            f"_TSA={tsa:g} _PRNUM={prnum} _VMS=0 _NMSP=1 _FA=1 _TZL=0\n"
            f"_MVAR={mvar} _SETVAL=110.246 {extra}\nCYCLE976\nM2")


def machine_with(client, pretravel: dict) -> Machine:
    return Machine(client, frame="ring", pretravel={**pretravel, "Z-": 0.002}, eccentricity=ECC)


def others_unchanged(m: Machine, prnum: int, before: dict) -> None:
    assert {n: m.probe(n) for n in (1, 2, 3) if n != prnum} == before


def snapshot(m: Machine, prnum: int) -> dict:
    return {n: m.probe(n) for n in (1, 2, 3) if n != prnum}


def test_two_directions_of_x_with_skew_and_ball_into_record_2(client):
    """_MVAR=012101 (§5.3 table: 2 directions of _MA, skew, ball): X+ and X− calibrated, the skew's
    X part measured (MP − mid of the recs = e_x), its Y part (the true one, stored) and the Y fields
    stay, d_eff = 2(r − δ): the probe's own trigger values ∓(r − δ)."""
    m = machine_with(client, {k: DELTA for k in ("X+", "X-", "Y+", "Y-")})
    m.put_probe(2, trigger={"X+": -3.0, "X-": 3.0, "Y+": -2.5, "Y-": 2.5}, skew=[0.0, ECC[1]])
    before = snapshot(m, 2)
    answer = m.mda(program("012101", "_MA=1"))
    assert answer["state"] == "done", answer
    record = m.probe(2)
    assert record["trigger"]["X+"] == pytest.approx(-(R - DELTA), abs=1e-6)
    assert record["trigger"]["X-"] == pytest.approx(R - DELTA, abs=1e-6)
    assert (record["trigger"]["Y+"], record["trigger"]["Y-"]) == (-2.5, 2.5)
    assert record["skew"] == pytest.approx(list(ECC), abs=1e-9)
    assert record["effective_diameter"] == pytest.approx(2 * (R - DELTA), abs=1e-6)
    others_unchanged(m, 2, before)
    ovr, ovi = m.ovr(), m.ovi()
    assert ovi[2:4] == [976, 12101] and ovi[5] == 2
    assert ovr[10] == pytest.approx(-(R - DELTA), abs=1e-6) and ovr[11] == pytest.approx(1.0 + DELTA, abs=1e-6)


def test_one_direction_minus_y_uses_the_stored_skew(client):
    """_MVAR=001001 _MA=2 _MD=1 (one direction, manual: no skew, no ball): only Y− changes. The
    stored skew is 0, so the NC's ball centre c is the spindle axis. The ball (at MP + e) travels
    e_x off the diameter and switches √(ρ² − e_x²) + δ(Y−) below MP; c_y = ball_y − e_y, so
    t(Y−) = c_y − s_y = D/2 − √(ρ² − e_x²) − δ(Y−) − e_y (the eccentricity absorbed)."""
    delta_y = 0.007
    m = machine_with(client, {"X+": DELTA, "X-": DELTA, "Y+": DELTA, "Y-": delta_y})
    m.put_probe(3, skew=[0.0, 0.0])
    before_record = m.probe(3)
    before = snapshot(m, 3)
    answer = m.mda(program("001001", "_MA=2 _MD=1", prnum=3))
    assert answer["state"] == "done", answer
    record = m.probe(3)
    expected = RING_D / 2.0 - math.sqrt(RHO ** 2 - ECC[0] ** 2) - delta_y - ECC[1]
    assert record["trigger"]["Y-"] == pytest.approx(expected, abs=1e-6)
    rest = {k: v for k, v in record["trigger"].items() if k != "Y-"}
    assert rest == {k: v for k, v in before_record["trigger"].items() if k != "Y-"}
    assert record["skew"] == before_record["skew"]
    assert record["effective_diameter"] == before_record["effective_diameter"]
    others_unchanged(m, 3, before)
    assert m.wcs()["X"] == pytest.approx(100.0) and m.wcs()["Y"] == pytest.approx(80.0)


def test_one_direction_at_an_angle_of_30_degrees(client):
    """_MVAR=101001 _MA=1 _MD=0 _STA1=30 (at an angle, §5.3.1): one touch along 30°, stored in the
    closest field X+ (measuring-math §7.4). The stored skew is the true one, so the NC knows the
    ball centre and the value is the probe's own −(r − δ) (δ the same in every plane direction)."""
    m = machine_with(client, {k: DELTA for k in ("X+", "X-", "Y+", "Y-")})
    m.put_probe(2, skew=list(ECC))
    before_record = m.probe(2)
    answer = m.mda(program("101001", "_MA=1 _MD=0 _STA1=30"))
    assert answer["state"] == "done", answer
    record = m.probe(2)
    assert record["trigger"]["X+"] == pytest.approx(-(R - DELTA), abs=1e-6)
    assert {k: v for k, v in record["trigger"].items() if k != "X+"} == \
        {k: v for k, v in before_record["trigger"].items() if k != "X+"}
    assert record["skew"] == before_record["skew"]
    assert m.ovr()[24] == pytest.approx(30.0)


def test_unknown_centre_at_an_angle_of_60_degrees_all_fields(client):
    """_MVAR=110108 _STA1=60 (§5.3.2 "at an angle, all 4 directions"): directions 60°, 240°, 150°,
    330° → fields Y+, Y−, X−, X+ (the closest axis directions); skew, ball and the ring centre as
    the axis-parallel variant finds them: t = ∓(r − δ), e = ECC, d_eff = 2(r − δ), MP = (100, 80)."""
    m = machine_with(client, {k: DELTA for k in ("X+", "X-", "Y+", "Y-")})
    before = snapshot(m, 2)
    answer = m.mda(program("110108", "_STA1=60"))
    assert answer["state"] == "done", answer
    record = m.probe(2)
    for key in ("X+", "Y+"):
        assert record["trigger"][key] == pytest.approx(-(R - DELTA), abs=1e-6)
    for key in ("X-", "Y-"):
        assert record["trigger"][key] == pytest.approx(R - DELTA, abs=1e-6)
    assert record["skew"] == pytest.approx(list(ECC), abs=1e-6)
    assert record["effective_diameter"] == pytest.approx(2 * (R - DELTA), abs=1e-6)
    others_unchanged(m, 2, before)
    ovr = m.ovr()
    assert ovr[6:8] == pytest.approx([100.0, 80.0], abs=1e-6)
    assert ovr[24] == pytest.approx(60.0)
    assert m.wcs()["X"] == pytest.approx(100.0 - ECC[0], abs=1e-6)    # the ball on the ring centre


def test_known_centre_four_directions_without_ball_and_skew(client):
    """_MVAR=000001 (4 directions, neither ball nor skew): the four trigger values with the stored
    skew 0 (c = spindle axis: they absorb the eccentricity along their axis); skew and effective Ø
    stay. Along X the ball travels e_y off the diameter: t(X±) = ±(√(ρ² − e_y²) + δ − D/2) − e_x."""
    m = machine_with(client, {k: DELTA for k in ("X+", "X-", "Y+", "Y-")})
    m.put_probe(2, skew=[0.0, 0.0])
    before_record = m.probe(2)
    answer = m.mda(program("000001"))
    assert answer["state"] == "done", answer
    record = m.probe(2)
    x_reach = math.sqrt(RHO ** 2 - ECC[1] ** 2) + DELTA - RING_D / 2
    y_reach = math.sqrt(RHO ** 2 - ECC[0] ** 2) + DELTA - RING_D / 2
    truth = {"X+": x_reach - ECC[0], "X-": -x_reach - ECC[0], "Y+": y_reach - ECC[1], "Y-": -y_reach - ECC[1]}
    for key, value in truth.items():
        assert record["trigger"][key] == pytest.approx(value, abs=1e-6), key
    assert record["skew"] == before_record["skew"]
    assert record["effective_diameter"] == before_record["effective_diameter"]


def test_known_centre_four_directions_at_30_degrees_with_skew_and_ball(client):
    """_MVAR=110101 _STA1=30 (§5.3.1 "有角度时校准", 4 directions, skew, ball): touches along 30°,
    210°, 120°, 300° from MP → fields X+, X−, Y+, Y− (closest axis directions); the skew from the
    two pairs is the true eccentricity, the values ∓(r − δ), d_eff = 2(r − δ)."""
    m = machine_with(client, {k: DELTA for k in ("X+", "X-", "Y+", "Y-")})
    m.put_probe(2, skew=[0.0, 0.0])
    before = snapshot(m, 2)
    answer = m.mda(program("110101", "_STA1=30"))
    assert answer["state"] == "done", answer
    record = m.probe(2)
    for key in ("X+", "Y+"):
        assert record["trigger"][key] == pytest.approx(-(R - DELTA), abs=1e-6), key
    for key in ("X-", "Y-"):
        assert record["trigger"][key] == pytest.approx(R - DELTA, abs=1e-6), key
    assert record["skew"] == pytest.approx(list(ECC), abs=1e-9)
    assert record["effective_diameter"] == pytest.approx(2 * (R - DELTA), abs=1e-6)
    others_unchanged(m, 2, before)
    assert m.ovr()[24] == pytest.approx(30.0)


def test_beyond_tsa_the_bore_variant_alarms_and_writes_nothing(client):
    """_MVAR=012101 with _TSA=0.5 and a stored X+ of −3 (the truth is −(r − δ) = −1.996):
    |Δt| = 1.004 > _TSA → 61303 naming _TSA, record 2 as it was."""
    m = machine_with(client, {k: DELTA for k in ("X+", "X-", "Y+", "Y-")})
    m.put_probe(2, trigger={"X+": -3.0, "X-": 3.0})
    before = m.probe(2)
    answer = m.mda(program("012101", "_MA=1", tsa=0.5))
    assert answer["state"] == "alarm" and answer["alarm"]["code"] == 61303, answer
    assert "_TSA" in answer["alarm"]["message"]
    assert m.probe(2) == before


@pytest.mark.parametrize(("mvar", "extra", "code", "words"), [
    ("012108", "_MA=1", 61307, ("xx0x08", "§5.3.2")),
    ("011101", "_MA=1 _MD=0", 61307, ("xx1x0x", "§5.3")),
    ("012101", "_MA=3", None, ("_MA", "§5.3.1")),
    ("001001", "_MA=1 _MD=2", None, ("_MD", "§5.3.1")),
    ("200101", "", 61307, ("digit 6", "§5.3")),
])
def test_refused_variants_name_the_parameter_and_change_nothing(client, mvar, extra, code, words):
    m = machine_with(client, {k: DELTA for k in ("X+", "X-", "Y+", "Y-")})
    before = {n: m.probe(n) for n in (1, 2, 3)}
    answer = m.mda(program(mvar, extra))
    assert answer["state"] == "alarm", answer
    if code is not None:
        assert answer["alarm"]["code"] == code, answer
    for word in words:
        assert word in answer["alarm"]["message"], answer["alarm"]
    assert {n: m.probe(n) for n in (1, 2, 3)} == before

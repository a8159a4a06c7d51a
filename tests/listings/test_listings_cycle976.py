"""CYCLE976 (calibrate the workpiece probe, manual §5.3) as printed in the manual, against truth.

Each listing of tests/listings/manual_listings.py runs unchanged as an MDA program; the machine
is built around it (scenario: a ring gauge of the printed Ø110.246 with its centre at the
printed X100 Y80 of G54, the surface at the printed Z20, the probe of the printed tool number).
Truth comes from the scenario: ball radius r, pre-travel δ, eccentricity e, true length L
(measuring-math §5.1 t = c − s: t(−) = r − δ, t(+) = −(r − δ); effective Ø = 2(r − δ)).
"""

from __future__ import annotations

import pytest
from listing_kit import Machine
from manual_listings import KALIBRIEREN2_IN_X_Y, KALIBRIEREN_IN_X_Y, KALIBRIEREN_IN_Z, KALIBRIEREN_Z_L

R = 2.0                      # ball radius of the scenario's probe (Ø4)
DELTA = 0.004                # pre-travel in the plane, every direction (symmetric: exact in the ring)
DELTA_Z = 0.002
ECC = (0.010, -0.006)
L1_ERROR = 0.2               # typed L1 100.2, true 100 (listing_kit)


PRETRAVEL = {"X+": DELTA, "X-": DELTA, "Y+": DELTA, "Y-": DELTA, "Z-": DELTA_Z}


@pytest.fixture
def machine(client):
    return Machine(client, pretravel=PRETRAVEL, eccentricity=ECC)


@pytest.fixture
def ring(client):
    return Machine(client, frame="ring", pretravel=PRETRAVEL, eccentricity=ECC)


def test_ring_listing_prnum3_calibrates_record_3_only(ring):
    """§5.3.1 (lines 8980–8998): _MVAR=010101, _PRNUM=3 → record 3 gets the trigger values, skew
    and effective Ø; records 1 and 2 are unchanged."""
    before = {n: ring.probe(n) for n in (1, 2)}
    answer = ring.run(KALIBRIEREN_IN_X_Y)
    assert answer["state"] == "done", answer
    record = ring.probe(3)
    assert record["effective_diameter"] == pytest.approx(2 * (R - DELTA), abs=1e-6)
    assert record["skew"] == pytest.approx(list(ECC), abs=1e-6)
    for key in ("X+", "Y+"):
        assert record["trigger"][key] == pytest.approx(-(R - DELTA), abs=1e-6)
    for key in ("X-", "Y-"):
        assert record["trigger"][key] == pytest.approx(R - DELTA, abs=1e-6)
    assert {n: ring.probe(n) for n in (1, 2)} == before
    ovr, ovi = ring.ovr(), ring.ovi()
    assert ovr[4] == pytest.approx(2 * (R - DELTA), abs=1e-6)
    assert ovr[20:22] == pytest.approx(list(ECC), abs=1e-6)
    assert ovi[2:4] == [976, 10101] and ovi[5] == 3
    assert ring.wcs()["Z"] == pytest.approx(40.0)                     # N80 Z40


def test_unknown_centre_listing_prnum2_with_fa_from_setval(ring):
    """§5.3.2 (lines 9303–9321): T10, _MVAR=010108, _FA=_SETVAL/2 (an expression), _PRNUM=2."""
    ring.load(probe_t=10)
    before = {n: ring.probe(n) for n in (1, 3)}
    answer = ring.run(KALIBRIEREN2_IN_X_Y)
    assert answer["state"] == "done", answer
    record = ring.probe(2)
    assert record["effective_diameter"] == pytest.approx(2 * (R - DELTA), abs=1e-6)
    assert record["skew"] == pytest.approx(list(ECC), abs=1e-6)
    assert record["tool"] == 10
    assert {n: ring.probe(n) for n in (1, 3)} == before
    ovr = ring.ovr()
    assert ovr[6:8] == pytest.approx([100.0, 80.0], abs=1e-6)            # the ring's centre in G54


def test_surface_listing_mvar0_calibrates_the_minus_z_trigger(machine):
    """§5.3.3 %_N_KALIBRIEREN_IN_Z_MPF (lines 9517–9535): _MVAR=0 _MA=3 _MD=1 on the surface
    Z20 → t(Z−) = c_z − 20 into record 1 (_WP[0,5]); L1 and the other records unchanged. The NC
    computes c with the typed L1 (100.2, true 100: the manual's "L1 must be known"), so
    t(Z−) = r − δ(Z−) − (L1_typed − L1_true)."""
    tool_before = machine.tool(9)
    others = {n: machine.probe(n) for n in (2, 3)}
    answer = machine.run(KALIBRIEREN_IN_Z)
    assert answer["state"] == "done", answer
    record = machine.probe(1)
    t_minus_z = R - DELTA_Z - L1_ERROR
    assert record["trigger"] == {"Z-": pytest.approx(t_minus_z, abs=1e-9)}
    assert machine.tool(9) == tool_before
    assert {n: machine.probe(n) for n in (2, 3)} == others
    ovr, ovi = machine.ovr(), machine.ovi()
    assert ovr[16] == pytest.approx(t_minus_z, abs=1e-9)
    assert ovi[2:4] == [976, 0] and ovi[9] == 0
    assert machine.wcs()["Z"] == pytest.approx(55.0)                     # N80 Z55


def test_surface_listing_beyond_tsa_alarms_and_writes_nothing(machine):
    """The listing with _TSA=1 (changed here) and a stored t(Z−) = 3.9, 2.1 mm off the truth:
    |Δt| > _TSA → 61303, the record stays as it was."""
    machine.put_probe(1, trigger={"Z-": 3.9})
    answer = machine.run(KALIBRIEREN_IN_Z, replace={"_TSA=4": "_TSA=1"})
    assert answer["state"] == "alarm" and answer["alarm"]["code"] == 61303, answer
    assert "_TSA" in answer["alarm"]["message"]
    assert machine.probe(1)["trigger"] == {"Z-": pytest.approx(3.9)}


def test_surface_calibration_in_plus_x_on_a_side_face(machine):
    """The same variant along the abscissa (_MA=1 _MD=0: travelling +X onto the block's left face
    at G54 X−100 from the front): t(X+) = c_x − s with c = rec + stored skew; record 1 has no
    skew yet, so the trigger value absorbs the eccentricity (measuring-math §5.2):
    t(X+) = −(r − δ(X+)) − e_x. The probe ends where it started."""
    program = ("G54 G90 G17 T9 D1\nM6\nG0 X-110 Y80\nZ10\n"
               "_TSA=4 _PRNUM=1 _VMS=0 _NMSP=1 _FA=2\n_MVAR=0 _SETVAL=-100 _MA=1 _MD=0\nCYCLE976\nM2")
    answer = machine.mda(program)
    assert answer["state"] == "done", answer
    assert machine.probe(1)["trigger"] == {"X+": pytest.approx(-(R - DELTA) - ECC[0], abs=1e-9)}
    assert machine.wcs()["X"] == pytest.approx(-110.0)


def test_length_listing_determines_l1(machine):
    """§5.3.4 %_N_KALIBRIEREN_Z_L_MPF (lines 9742–9763): the listing leaves the positioning to
    the operator ("; ..."): the probe stands 10 mm above the surface Z20 (L1 typed 100.2, true
    100). L1 = true length − δ(Z−) (pre-travel absorbed, measuring-math §7.5), t(Z−) = r."""
    machine.operator_positions_ball(z=30.0)
    answer = machine.run(KALIBRIEREN_Z_L)
    assert answer["state"] == "done", answer
    assert machine.tool(9)["length"] == pytest.approx(100.0 - DELTA_Z, abs=1e-9)
    assert machine.probe(1)["trigger"]["Z-"] == pytest.approx(R)

"""$AA_MW / $AA_MM after MEAS on the lathe, DIAMON and DIAMOF, against the scenario's truth.

With DIAMON the NC program reads the workpiece coordinate X as a diameter ($AA_MW[X], as $AA_IW[X]
and the X words); the machine axis stays a radius ($AA_MM[X], as $AA_IM: turning.md §0.3 "machine
axes ... stay radius values", the 840D's default with MD30460 bit 2 = 0). Z is never doubled.

Truth (tests/lathe/lathe_kit.py): the shaft Ø45.006 eccentric by +0.030 in X at spindle angle 0;
the probe T8's true ball radius 2.995 and its true L1 40.119, 0.004 shorter than the NC's nominal
40.123 (so the NC's ball centre lies 0.004 below the true one); no pretravel, no noise; G500.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "lathe"))
from lathe_kit import LATHE_SCENARIO, Lathe, make_client  # noqa: E402

WP = LATHE_SCENARIO["workpiece"]
PROBE = LATHE_SCENARIO["probe"]
SHAFT = WP["profile"][0]
NOMINAL_L1 = PROBE["nominal"]["l1"]
# the true ball centre touches the shaft's top line (spindle 0°: the eccentricity adds in +X) ...
TRUE_CENTRE_X = SHAFT["diameter"] / 2 + WP["eccentricity"][0] + PROBE["ball_diameter"] / 2
# ... where the NC's ball centre (F − nominal L1) is 0.004 lower
NC_TIP_X = TRUE_CENTRE_X - (NOMINAL_L1 - PROBE["l1"])
Z_AT = 30.0


@pytest.fixture
def lathe(tmp_path):
    with make_client(tmp_path) as client:
        lathe = Lathe(client)
        lathe.tool(PROBE["t"])
        lathe.ball_to(30.0, Z_AT)                # radius 30 (Ø60), over the shaft
        yield lathe


def measure(lathe, diameter_words: str, x_word: str) -> dict:
    program = (f"N10 G18 G90 {diameter_words}\n"
               f"N20 MEAS=1 G1 F100 {x_word}\n"
               "N30 R1=$AA_MW[X] R2=$AA_MM[X] R3=$AA_MW[Z] R4=$AA_MM[Z] R5=$AC_MEA[1]\n"
               "M2\n")
    answer = lathe.ok(lathe.c.post("/api/nc/run", json={"mda": program}))
    assert answer["state"] == "done", answer
    values = lathe.ok(lathe.c.get("/api/nc/variables", params={"names": "R1,R2,R3,R4,R5"}))
    return {k: float(v) for k, v in values.items()}


def test_diamon_gives_the_measured_x_as_a_diameter_in_the_wcs_and_a_radius_in_the_mcs(lathe):
    r = measure(lathe, "DIAMON", "X40")         # X40 = Ø40 = radius 20: below the shaft's top line
    assert r["R5"] == 1.0
    assert r["R1"] == pytest.approx(2.0 * NC_TIP_X, abs=1e-6)             # $AA_MW[X]: Ø
    assert r["R2"] == pytest.approx(NC_TIP_X + NOMINAL_L1, abs=1e-6)     # $AA_MM[X]: F, radius
    assert r["R3"] == pytest.approx(Z_AT, abs=1e-6)                        # Z as it is
    assert r["R4"] == pytest.approx(Z_AT + PROBE["nominal"]["l2"], abs=1e-6)


def test_diamof_gives_radii(lathe):
    r = measure(lathe, "DIAMOF", "X20")         # radius 20
    assert r["R5"] == 1.0
    assert r["R1"] == pytest.approx(NC_TIP_X, abs=1e-6)
    assert r["R2"] == pytest.approx(NC_TIP_X + NOMINAL_L1, abs=1e-6)


def test_the_measured_diameter_agrees_with_the_position_read_after_the_move(lathe):
    """$AA_MW[X] and $AA_IW[X] in the same unit: the probe stops a braking distance (tenths of a
    mm at F100) past the switch, so the position read after the move is a slightly smaller
    diameter, never the radius (half of it)."""
    program = ("N10 G18 G90 DIAMON\n"
               "N20 MEAS=1 G1 F100 X40\n"
               "N30 R1=$AA_MW[X] R2=$AA_IW[X]\n"
               "M2\n")
    assert lathe.ok(lathe.c.post("/api/nc/run", json={"mda": program}))["state"] == "done"
    values = lathe.ok(lathe.c.get("/api/nc/variables", params={"names": "R1,R2"}))
    assert float(values["R1"]) == pytest.approx(2.0 * NC_TIP_X, abs=1e-6)
    assert float(values["R1"]) - 0.5 < float(values["R2"]) < float(values["R1"])

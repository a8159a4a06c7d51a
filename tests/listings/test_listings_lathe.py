"""The manual's chapter-6 listings (the lathe) as printed, on the simulated lathe, against its truth.

The lathe is app/machine/lathe_demo_scenario.json (time_scale 0): the tool probe's faces, the
tools' true L1/L2, the probe's true ball and L1 (0.004 shorter than its nominal L1, the NC's),
the reference grooves, the part (a shaft Ø45.006 from the chuck face Z0 to Z60, a bore Ø35.004
from Z20). Every expected number below comes from that scenario (``TRUTH``), never from the code.

Adapted where the listing's positions do not fit this lathe (the manual allows positions and tool
numbers): each test names its replacements. Nothing else changes: the words, the parameters, the
cycle calls are the print's (seed line numbers with each listing in manual_listings.py).
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from manual_listings import KALIBRIEREN_IN_NUT_20537, NV_ERMITTLUNG_1_21058

SCENARIO = json.loads((Path(__file__).resolve().parents[2] / "app" / "machine" / "lathe_demo_scenario.json")
                      .read_text(encoding="utf-8"))
SCENARIO["machine"]["time_scale"] = 0
PROBE = SCENARIO["probe"]
R_TRUE = PROBE["ball_diameter"] / 2.0                         # 2.995
DL1 = PROBE["nominal"]["l1"] - PROBE["l1"]                    # the NC's ball centre lies 0.004 below the true one
GROOVE = SCENARIO["grooves"][0]["sl7"]
SHAFT = next(p for p in SCENARIO["workpiece"]["profile"] if p["type"] == "cylinder")
BORE = next(p for p in SCENARIO["workpiece"]["profile"] if p["type"] == "bore")
FACE_Z = SHAFT["z"][1]                                        # the shaft's end face (MCS, chuck face at 0)
NOISE = 1e-6                                                  # noise_sigma 0: the simulator's exact switch


class Lathe:
    def __init__(self, client):
        self.c = client
        self.ok(client.post("/api/sim/scenario", json={**SCENARIO, "reset_data": True}))
        assert self.ok(client.get("/api/machine"))["kind"] == "lathe"

    @staticmethod
    def ok(response, status: int = 200):
        assert response.status_code == status, response.text
        return response.json()

    def run(self, listing, replace: dict[str, str] | None = None) -> dict:
        text = listing.text
        for old, new in (replace or {}).items():
            assert old in text, old
            text = text.replace(old, new)
        answer = self.ok(self.c.post("/api/nc/run", json={"mda": text}))
        assert answer["state"] == "done" and answer["reason"] == "M2", answer
        return answer

    def var(self, name: str) -> list:
        return self.ok(self.c.get("/api/nc/variables", params={"names": name}))[name]

    def rough_probe_record(self) -> None:
        """What the operator enters before the first calibration: the nominal ball (the printed
        listings calibrate with _TSA=1, i.e. an existing record)."""
        r = PROBE["nominal"]["ball_diameter"] / 2.0
        self.ok(self.c.put("/api/probes/1", json={"tool": PROBE["t"], "ball_diameter": 2 * r,
                                                  "trigger": {"X-": r, "X+": -r, "Z-": r}}))

    def put_g54(self, x: float = 0.0, z: float = 0.0) -> None:
        self.ok(self.c.put("/api/offsets/G54", json={"trans": {"X": x, "Y": 0.0, "Z": z},
                                                     "rot": {"X": 0.0, "Y": 0.0, "Z": 0.0}}))

    def g54(self) -> dict[str, float]:
        frame = self.ok(self.c.get("/api/offsets/G54"))
        return {a: frame["trans"][a] + frame["fine"][a] for a in "XZ"}


@pytest.fixture
def lathe(client):
    return Lathe(client)


# the probe's start above groove 1 (MCS of the ball centre, X a radius): the printed Z125 X95
# lies elsewhere on the manual's machine
GROOVE_START = {"Z125 X95": "Z40 X80", "N70 G0 SUPA Z125": "N70 G0 SUPA Z140", "N80 SUPA X95": "N80 SUPA X100"}


def calibrate_in_groove(lathe: Lathe) -> None:
    lathe.rough_probe_record()
    lathe.run(KALIBRIEREN_IN_NUT_20537, replace=GROOVE_START)


def test_6_4_2_probe_calibrated_in_the_groove(lathe):
    """§6.4.2 %_N_KALIBRIEREN_IN_NUT_MPF (lines 20537–20555): CYCLE973 _MVAR=13 _MA=1 _MD=1
    (−Z onto the groove bottom), then _MVAR=02013 _MA=2 (X both walls), DIAMOF. Truth: the walls
    and the bottom of groove 1, the true ball radius, the NC's ball centre DL1 below the true one
    (the nominal L1): trigger = NC ball centre at the switch − the surface."""
    calibrate_in_groove(lathe)
    record = lathe.ok(lathe.c.get("/api/probes/1"))
    assert record["trigger"]["Z-"] == pytest.approx(R_TRUE, abs=NOISE)
    assert record["trigger"]["X-"] == pytest.approx(R_TRUE - DL1, abs=NOISE)
    assert record["trigger"]["X+"] == pytest.approx(-R_TRUE - DL1, abs=NOISE)
    ovi = lathe.var("_OVI")
    assert ovi[2] == 973 and ovi[3] == 2013 and ovi[5] == 1          # the last call: cycle, _MVAR, _PRNUM


def test_6_5_2_zero_offset_from_the_face(lathe):
    """§6.5.2 %_N_NV_ERMITTLUNG_1_MPF (lines 21058–21069): DIAMON, CYCLE974 _MVAR=100 _SETVAL=60
    _MA=1 _KNUM=1: G54 Z puts the shaft's end face at Z60. G54 starts 0.4 off. Adapted: X36 → X40
    (Ø, the ball on the face's ring between the bore Ø35.004 and the shaft Ø45.006)."""
    calibrate_in_groove(lathe)
    lathe.put_g54(z=-0.4)
    lathe.run(NV_ERMITTLUNG_1_21058, replace={"X36": "X40"})
    assert lathe.g54()["Z"] == pytest.approx(FACE_Z - 60.0, abs=NOISE)
    assert lathe.g54()["X"] == 0.0
    ovr = lathe.var("_OVR")
    assert ovr[0] == pytest.approx(60.0) and ovr[4] == pytest.approx(FACE_Z + 0.4, abs=NOISE)
    assert ovr[16] == pytest.approx(0.4, abs=NOISE)
    assert lathe.var("_OVI")[:4] == [1, 0, 974, 100]
    # N50/N60 positioned with DIAMON: the probe ends at WCS X114 (Ø), i.e. radius 57
    assert lathe.ok(lathe.c.get("/api/machine"))["wcs"]["X"] == pytest.approx(114.0)

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
import math
from pathlib import Path

import pytest
from manual_listings import (
    EIN_PUNKT_MESSEN_21272,
    INKR_KALIBRIEREN_19596,
    INKR_MESSEN_20039,
    KALIBRIEREN_IN_NUT_20537,
    KALIBRIEREN_IN_Z_20714,
    KALIBRIEREN_MTWZ_16812,
    KALIBRIEREN_MTWZ_WKS_17856,
    NV_ERMITTLUNG_1_21058,
    T3_MESSEN_17138,
    T3_MESSEN_FR_18606,
    TEIL_1_MESSEN_22159,
    UMSCHLAGMESSEN_21502,
    ZWEI_PUNKT_MESSUNG_22051,
)

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
FACES = SCENARIO["tool_probe"]["faces"]                        # the tool probe's true faces (MCS of the tip)
TOOLS = {t["t"]: t for t in SCENARIO["tools"]}
ECC = math.hypot(*SCENARIO["workpiece"]["eccentricity"])       # the part's clamping eccentricity (X at SPOS 0)
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

    def tool_probe(self) -> dict:
        return self.ok(self.c.get("/api/tool-probes/1"))

    def tool(self, t: int) -> dict:
        return self.ok(self.c.get(f"/api/tools/{t}"))

    def tip_to(self, t: int, x: float, z: float) -> None:
        """The operator turns the turret to T``t`` and jogs its tip (stored L1/L2) to MCS (x, z):
        up and away first, then Z, then X."""
        self.ok(self.c.post("/api/machine/tool", json={"tool": t}))
        row = self.tool(t)
        l1, l2 = row["l1"] + row["wear"]["l1"], row["l2"] + row["wear"]["l2"]
        for axes in ({"Z": 800.0}, {"X": 600.0}, {"Z": z + l2}, {"X": x + l1}):
            self.ok(self.c.post("/api/machine/goto", json={**axes, "coords": "MCS"}))

    def spos(self, angle: float) -> None:
        self.ok(self.c.post("/api/lathe/spos", json={"angle": angle}))

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


# --- CYCLE982: the tool probe and the turning tools (§6.2, §6.3) ----------------------------------------

# §6.2.2's positions on this lathe (MCS of T7's tip, X a radius): start above and right of the
# tool probe, then beside it (X350), below it (Z170), away (X350, Z520) -- the positions §6.2.4 prints
MTWZ_POSITIONS = {"Z300 X240": "Z240 X420", "SUPA Z60": "SUPA Z240", "SUPA X20": "SUPA X350", "SUPA Z0": "SUPA Z170",
                  "SUPA X240": "SUPA X350", "SUPA  Z300": "SUPA  Z520"}


def test_6_2_2_tool_probe_calibrated_machine_related(lathe):
    """§6.2.2 %_N_KALIBRIEREN_MTWZ_MPF (lines 16812–16835): CYCLE982 _MVAR=0 with the calibration
    tool T7, −X, −Z, +X, +Z: _TP holds the tool probe's true faces (stored 400/220/380/200, the
    rough values). Adapted: the positions (MTWZ_POSITIONS)."""
    assert lathe.tool_probe()["trigger"] == {"Z-": 220.0, "Z+": 200.0, "X-": 400.0, "X+": 380.0}
    lathe.run(KALIBRIEREN_MTWZ_16812, replace=MTWZ_POSITIONS)
    assert lathe.tool_probe()["trigger"] == pytest.approx(FACES, abs=NOISE)
    ovr = lathe.var("_OVR")
    # the manual's _OVR of the calibration: [8] Z−, [10] Z+, [12] X−, [14] X+, [11] the last one's difference
    assert [ovr[8], ovr[10], ovr[12], ovr[14]] == pytest.approx([FACES["Z-"], FACES["Z+"], FACES["X-"], FACES["X+"]],
                                                               abs=NOISE)
    assert ovr[11] == pytest.approx(FACES["Z+"] - 200.0, abs=NOISE)
    assert lathe.var("_OVI")[2:4] == [982, 0]


def test_6_2_4_tool_probe_calibrated_then_t3_measured_into_the_wear(lathe):
    """§6.2.4 %_N_T3_MESSEN_MPF (lines 17138–17175) as printed (its positions fit this lathe):
    the tool probe calibrated with T7, then T3 measured with _MVAR=1 _CHBIT[3]=1 (into the wear)
    in −X (L1) and −Z (L2). Truth: T3's true L1/L2 minus its stored nominal ones."""
    lathe.run(T3_MESSEN_17138)
    assert lathe.tool_probe()["trigger"] == pytest.approx(FACES, abs=NOISE)
    row = lathe.tool(3)
    true, nominal = TOOLS[3], TOOLS[3]["nominal"]
    assert (row["l1"], row["l2"]) == (nominal["l1"], nominal["l2"])
    assert row["wear"]["l1"] == pytest.approx(true["l1"] - nominal["l1"], abs=NOISE)
    assert row["wear"]["l2"] == pytest.approx(true["l2"] - nominal["l2"], abs=NOISE)
    ovr = lathe.var("_OVR")
    assert ovr[10] == pytest.approx(true["l2"], abs=NOISE)              # the last call: L2 actual, difference
    assert ovr[11] == pytest.approx(true["l2"] - nominal["l2"], abs=NOISE)
    assert ovr[29] == pytest.approx(0.8)                                 # _TDIF
    assert lathe.var("_OVI")[2:4] == [982, 1] and lathe.var("_OVI")[8] == 3


def test_6_3_2_tool_probe_calibrated_workpiece_related(lathe):
    """§6.3.2 %_N_KALIBRIEREN_MTWZ_WKS_MPF (lines 17856–17880): CYCLE982 _MVAR=10 in G54: _TPW
    holds the faces in G54 (Z shifted by G54's 20), _TP stays. Adapted: the positions (those of
    §6.2.4 in G54); the operator entered rough _TPW values first."""
    lathe.put_g54(z=20.0)
    lathe.ok(lathe.c.put("/api/tool-probes/1", json={"workpiece_trigger": {"Z-": 200.0, "Z+": 180.0, "X-": 400.0,
                                                                             "X+": 380.0}}))
    tp_before = lathe.tool_probe()["trigger"]
    lathe.run(KALIBRIEREN_MTWZ_WKS_17856, replace={
        "Z100 X120": "Z220 X420", "G0 Z80": "G0 Z220", "G0 X10": "G0 X350", "G0 Z-10": "G0 Z150", "G0  X10": "G0  X350",
        "N70 Z100": "N70 Z500", "N80 X120": "N80 X420"})
    record = lathe.tool_probe()
    expected = {k: v - (20.0 if k[0] == "Z" else 0.0) for k, v in FACES.items()}
    assert record["workpiece_trigger"] == pytest.approx(expected, abs=NOISE)
    assert record["trigger"] == tp_before
    assert lathe.var("_OVI")[2:4] == [982, 10]


def test_6_3_5_and_6_3_6_incremental_calibration_and_measurement(lathe):
    """§6.3.5 %_N_INKR_KALIBRIEREN_MPF (lines 19596–19606): _MVAR=100000 _MA=2 _MD=1 from where the
    operator put T7 (20 mm right of the X− face, at the probe's height): _TP X− is the true face;
    §6.3.6 %_N_INKR_MESSEN_MPF (lines 20039–20049): _MVAR=100001 with T3 the same way: its L1
    (geometry, _CHBIT[3]=0) becomes the true one. Adapted: the print lost §6.3.6's "；" before
    N10's comment (seed line 20040)."""
    lathe.tip_to(7, 415.0, 210.0)
    lathe.run(INKR_KALIBRIEREN_19596)
    trigger = lathe.tool_probe()["trigger"]
    assert trigger["X-"] == pytest.approx(FACES["X-"], abs=NOISE)
    assert trigger["Z-"] == 220.0                                       # the other faces stay
    lathe.tip_to(3, 415.0, 210.0)
    lathe.run(INKR_MESSEN_20039, replace={"G94  车刀": "G94  ；车刀"})
    row = lathe.tool(3)
    assert row["l1"] == pytest.approx(TOOLS[3]["l1"], abs=NOISE) and row["wear"]["l1"] == 0.0
    assert row["l2"] == TOOLS[3]["nominal"]["l2"]
    ovr = lathe.var("_OVR")
    assert ovr[8] == pytest.approx(TOOLS[3]["l1"], abs=NOISE)
    assert ovr[9] == pytest.approx(TOOLS[3]["l1"] - TOOLS[3]["nominal"]["l1"], abs=NOISE)


# --- CYCLE973 on a surface (§6.4.3) ---------------------------------------------------------------------

def test_6_4_2_the_nc_calibration_makes_the_probe_record_valid(lathe):
    """After the §6.4.2 listing's CYCLE973 calls, GET /api/probes/1 says valid (before: the rough,
    typed record read "not_calibrated", and so did the calibrated one) and holds the true values
    of the directions calibrated (the milling flags stay unset: no ring, no length calibration)."""
    lathe.rough_probe_record()
    typed = lathe.ok(lathe.c.get("/api/probes/1"))
    assert (typed["valid"], typed["invalid_reason"]) == (False, "not_calibrated")
    lathe.run(KALIBRIEREN_IN_NUT_20537, replace=GROOVE_START)
    record = lathe.ok(lathe.c.get("/api/probes/1"))
    assert record["valid"] is True and record["invalid_reason"] is None
    assert record["calibrated_directions"] == ["X+", "X-", "Z-"]
    assert record["calibrated_radius"] is False and record["calibrated_length"] is False
    assert record["trigger"]["Z-"] == pytest.approx(R_TRUE, abs=NOISE)
    assert record["trigger"]["X-"] == pytest.approx(R_TRUE - DL1, abs=NOISE)
    assert record["trigger"]["X+"] == pytest.approx(-R_TRUE - DL1, abs=NOISE)
    history = lathe.ok(lathe.c.get("/api/probes/1/history", params={"probe": "workpiece"}))
    assert history[0]["event"] == "calibration" and history[0]["id"] == record["calibration_id"]


def test_6_4_3_probe_calibrated_on_the_face(lathe):
    """§6.4.3 %_N_KALIBRIEREN_IN_Z_MPF (lines 20714–20727): DIAMON, CYCLE973 _MVAR=0 _SETVAL=−18
    _MA=1 _MD=1: the shaft's end face lies at G54 Z−18 (G54 Z = FACE_Z + 18): _WP Z− is the
    true ball radius. Adapted: T9 → T8 (this lathe's probe), X66 → X40 (Ø, on the face)."""
    lathe.rough_probe_record()
    lathe.put_g54(z=FACE_Z + 18.0)
    lathe.run(KALIBRIEREN_IN_Z_20714, replace={"T9 D1": "T8 D1", "X66": "X40"})
    record = lathe.ok(lathe.c.get("/api/probes/1"))
    assert record["trigger"]["Z-"] == pytest.approx(R_TRUE, abs=NOISE)
    assert record["trigger"]["X-"] == PROBE["nominal"]["ball_diameter"] / 2.0       # not this call's
    ovr = lathe.var("_OVR")
    assert ovr[8] == pytest.approx(R_TRUE, abs=NOISE)
    assert ovr[9] == pytest.approx(R_TRUE - PROBE["nominal"]["ball_diameter"] / 2.0, abs=NOISE)
    assert lathe.ok(lathe.c.get("/api/machine"))["wcs"]["X"] == pytest.approx(146.0)   # N50 X146 (Ø)


# --- CYCLE974 and CYCLE994: the part (§6.5, §6.6, §6.7) -------------------------------------------------

def one_point_diameter(diameter: float, outside: bool) -> float:
    """What one point along X measures at SPOS 90 (the eccentricity then lies across X): the ball
    (true radius) touches the cylinder off its crest; the calibrated trigger is a flat wall's."""
    big_r = diameter / 2.0
    if outside:
        return 2.0 * (math.sqrt((big_r + R_TRUE) ** 2 - ECC ** 2) - R_TRUE)
    return 2.0 * (math.sqrt((big_r - R_TRUE) ** 2 - ECC ** 2) + R_TRUE)


def band(setval: float, tul: float, tll: float) -> float:
    """The symmetrised setpoint of a tool offset (manual §2.3.11): _SETVAL + (_TUL + _TLL)/2."""
    return setval + (tul + tll) / 2.0


def test_6_5_3_one_point_outside_and_inside_into_two_tools(lathe):
    """§6.5.3 %_N_EIN_PUNKT_MESSEN_MPF (lines 21272–21296): DIAMON, _CHBIT[4]=1, CYCLE974 _MVAR=0
    on the shaft Ø45 (−0/−0.01, _K=2) into T7's L1, then in the bore Ø35 (+0.015/0) into T8's L1.
    Truth: the shaft's and the bore's diameters seen by one point at SPOS 90 (the operator turns
    the clamping eccentricity across X: at SPOS 0 it would double into the diameter). Shaft: D =
    Ø − 44.995 is beyond the band (oversize, 62304) and within _TDIF: the whole D corrects
    (L1 wear −D/2, X a radius). Bore: D within the mean-value range: no correction, the mean
    D/_K in MV[14]. Adapted: T9 → T8 (the probe), _TNUM 7/8 → 3/1 (this lathe's turning tools; T7
    is the calibration tool, T8 the probe), N50 Z60 → Z70 (clear of this part's end face Z60)."""
    calibrate_in_groove(lathe)
    lathe.spos(90.0)
    lathe.run(EIN_PUNKT_MESSEN_21272, replace={"T9 D1": "T8 D1", "_TNUM=7": "_TNUM=3", "_TNUM=8": "_TNUM=1",
                                               "N50 G0 Z60": "N50 G0 Z70"})
    shaft_d = one_point_diameter(SHAFT["diameter"], outside=True)
    bore_d = one_point_diameter(BORE["diameter"], outside=False)
    d_shaft = shaft_d - band(45.0, 0.0, -0.01)
    assert lathe.tool(3)["wear"]["l1"] == pytest.approx(-d_shaft / 2.0, abs=NOISE)
    assert lathe.tool(1)["wear"] == {"length": 0.0, "radius": 0.0, "l1": 0.0, "l2": 0.0}
    ovr = lathe.var("_OVR")                             # the last call: the bore
    d_bore = bore_d - band(35.0, 0.015, 0.0)
    assert ovr[0] == pytest.approx(band(35.0, 0.015, 0.0)) and ovr[4] == pytest.approx(bore_d, abs=NOISE)
    assert ovr[16] == pytest.approx(d_bore, abs=NOISE)
    assert ovr[31] == pytest.approx(d_bore / 2.0, abs=NOISE)
    assert lathe.var("_MV")[14 - 1] == pytest.approx(d_bore / 2.0, abs=NOISE)
    assert lathe.var("_OVI")[2:4] == [974, 0] and lathe.var("_OVI")[8] == 1


def test_6_5_reversal_measurement_cancels_the_eccentricity(lathe):
    """§6.5 %_N_UMSCHLAGMESSEN_MPF (lines 21502–21516): CYCLE974 _MVAR=1000 _STA1=0: the shaft at
    SPOS 0 and 180, the mean: the true Ø45.006 whatever the clamping eccentricity; D beyond the
    band (oversize, 62304) corrects T3's L1 wear by −D/2. Adapted: T9 → T8, _TNUM=7 → 3."""
    calibrate_in_groove(lathe)
    lathe.run(UMSCHLAGMESSEN_21502, replace={"T9 D1": "T8 D1", "_TNUM=7": "_TNUM=3"})
    ovr = lathe.var("_OVR")
    d = SHAFT["diameter"] - band(45.0, 0.0, -0.01)
    assert ovr[4] == pytest.approx(SHAFT["diameter"], abs=NOISE)
    assert ovr[16] == pytest.approx(d, abs=NOISE)
    assert lathe.tool(3)["wear"]["l1"] == pytest.approx(-d / 2.0, abs=NOISE)
    ovi = lathe.var("_OVI")
    assert ovi[2:4] == [974, 1000] and ovi[9] == 62304


def test_6_6_two_points_outside_with_zone_and_inside(lathe):
    """§6.6 %_N_ZWEI_PUNKT_MESSUNG_MPF (lines 22051–22080): CYCLE994 _MVAR=2 on the shaft (over the
    protection zone _SZA/_SZO to the far side) into T3's L1, then in the bore into T1's: two
    opposite points cancel the eccentricity: the true diameters. Shaft oversize: L1 wear −D/2;
    bore within _TZL: no correction. Adapted: T1 → T8 (the probe), _TNUM 8/9 → 3/1, _SZA 55 → 70
    and N50 Z55 → Z70 (this part's end face is at Z60)."""
    calibrate_in_groove(lathe)
    lathe.run(ZWEI_PUNKT_MESSUNG_22051, replace={"T1 D1": "T8 D1", "_TNUM=8": "_TNUM=3", "_TNUM=9": "_TNUM=1",
                                                 "_SZA=55": "_SZA=70", "N50 G0 Z55": "N50 G0 Z70"})
    d = SHAFT["diameter"] - band(45.0, 0.0, -0.01)
    assert lathe.tool(3)["wear"]["l1"] == pytest.approx(-d / 2.0, abs=NOISE)
    assert lathe.tool(1)["wear"]["l1"] == 0.0
    ovr = lathe.var("_OVR")
    assert ovr[4] == pytest.approx(BORE["diameter"], abs=NOISE)
    assert ovr[16] == pytest.approx(BORE["diameter"] - band(35.0, 0.015, -0.01), abs=NOISE)
    assert lathe.var("_OVI")[2:4] == [994, 2]


def test_6_7_part_1_calibrate_then_four_points(lathe):
    """§6.7 %_N_TEIL_1_MESSEN_MPF (lines 22159–22211): CYCLE973 in the groove (−Z, then −X), then
    CYCLE974 at four points of the part into four tool lengths. This lathe's part: P1 the shaft
    (X, Ø45), P2 the end face (Z60), P3 the bore (X, Ø35), P4 the bore's bottom (Z20); G54 lies
    0.05 off in Z, so the faces read 0.05 short: L2 wear +0.05 (the tip cut 0.05 too deep: its
    true L2 is 0.05 longer). Adapted: the positions and setpoints of this part (the printed part
    is Ø200/Ø150 with faces at Z50/Z100), _TNUM 1..4 → 3, 3, 1, 1 (this lathe's turning tools),
    N160's move into the bore split in two (out over the face, then down). The probe's X+ trigger
    comes from §6.4.2 before (the listing calibrates −X only)."""
    calibrate_in_groove(lathe)
    lathe.put_g54(z=0.05)
    lathe.spos(90.0)
    lathe.run(TEIL_1_MESSEN_22159, replace={
        "X300 Z150": "X160 Z40", "N80 X220": "N80 X90", "_SETVAL=200": "_SETVAL=45", "_MA=2 _TNUM=1": "_MA=2 _TNUM=3",
        "N130 X175": "N130 X40", "_SETVAL=50": "_SETVAL=60", "_TUL=0.01 _TNUM=2": "_TUL=0.01 _TNUM=3",
        "N160 G0 Z180": "N160 G0 X0 Z70\nN165 Z40", "_SETVAL=150": "_SETVAL=35", "_TNUM=3 _KNUM=1  ": "_TNUM=1 _KNUM=1  ",
        "N190 G0 Z150": "N190 G0 Z30", "N200 X50": "N200 X20", "_SETVAL=100": "_SETVAL=20", "_TNUM=4": "_TNUM=1"})
    record = lathe.ok(lathe.c.get("/api/probes/1"))
    assert record["trigger"]["Z-"] == pytest.approx(R_TRUE, abs=NOISE)
    assert record["trigger"]["X-"] == pytest.approx(R_TRUE - DL1, abs=NOISE)
    p1 = one_point_diameter(SHAFT["diameter"], outside=True) - band(45.0, 0.0, -0.01)       # oversize
    p3 = one_point_diameter(BORE["diameter"], outside=False) - band(35.0, 0.005, -0.003)    # in the band
    t3, t1 = lathe.tool(3)["wear"], lathe.tool(1)["wear"]
    assert t3["l1"] == pytest.approx(-p1 / 2.0, abs=NOISE)
    assert t3["l2"] == pytest.approx(0.05, abs=NOISE)
    assert t1["l1"] == pytest.approx(-p3 / 2.0, abs=NOISE)         # beyond _TZL, within the band: _K=1, all of D
    assert t1["l2"] == pytest.approx(0.05, abs=NOISE)
    ovr = lathe.var("_OVR")                                        # P4
    assert ovr[4] == pytest.approx(20.0 - 0.05, abs=NOISE) and ovr[16] == pytest.approx(-0.05, abs=NOISE)


# --- DIAMON / DIAMOF and the turret (the words the listings use) --------------------------------------

def test_diamon_diamof_and_the_turret_position_the_tool_tip(lathe):
    """T turns the turret at once (no M6: "N10 T7 D1" of §6.2.2); the tool offset is L1 on X and
    L2 on Z; DIAMOF: X a radius; DIAMON: X a diameter, G90 and G91 alike, and $AA_IW[X] reads
    a diameter. Truth: the turret's MCS = the tip + (L1, L2) of the stored T8 (nominal data)."""
    l1, l2 = PROBE["nominal"]["l1"], PROBE["nominal"]["l2"]
    lathe.ok(lathe.c.post("/api/nc/run", json={"mda": "N10 T8 D1 G54 G90 DIAMOF\nN20 G0 Z100\nN30 X50\nN40 M2"}))
    mcs = lathe.ok(lathe.c.get("/api/machine"))["mcs"]
    assert lathe.ok(lathe.c.get("/api/machine"))["tool"] == 8
    assert (mcs["X"], mcs["Z"]) == pytest.approx((50.0 + l1, 100.0 + l2))
    lathe.ok(lathe.c.post("/api/nc/run", json={"mda": "N10 G91 DIAMON X20\nN20 R1=$AA_IW[X]\nN30 M2"}))
    assert lathe.ok(lathe.c.get("/api/machine"))["mcs"]["X"] == pytest.approx(60.0 + l1)
    assert lathe.var("R1") == pytest.approx(120.0)
    lathe.ok(lathe.c.post("/api/nc/run", json={"mda": "N10 G90 X30 Z90 DIAMOF\nN20 G91 X5\nN30 M2"}))
    mcs = lathe.ok(lathe.c.get("/api/machine"))["mcs"]
    assert (mcs["X"], mcs["Z"]) == pytest.approx((35.0 + l1, 90.0 + l2))


def test_6_3_3_a_mill_on_the_lathe_is_refused_with_a_turning_tool(lathe):
    """§6.3.3 %_N_T3_MESSEN_FR_MPF (lines 18606–18626): CYCLE982 _MVAR=12001 measures a milling
    cutter (L2 and R, radial, _STA1=15). The simulated lathe holds turning tools only (scenario
    tools type 5xy), so T3 here is a turning tool: the cycle refuses the mill digits with 61307
    at the call, nothing is written; the listing's words themselves all run (no syntax error).
    Adapted: the start position (Z285 X450 → Z240 X420, above the tool probe)."""
    before = lathe.tool(3)
    text = T3_MESSEN_FR_18606.text.replace("Z285 X450", "Z240 X420")
    answer = lathe.ok(lathe.c.post("/api/nc/run", json={"mda": text}))
    assert answer["state"] == "alarm" and answer["block"]["number"] == 140
    assert answer["alarm"]["code"] == 61307 and "mill digits with a turning tool" in answer["alarm"]["message"]
    assert lathe.tool(3) == before
    assert lathe.var("_OVI")[9] == 61307


@pytest.mark.parametrize(("call", "code", "text"), [
    ("_MVAR=5 _MA=2 _SETVAL=45\nN30 CYCLE974", 61307, "CYCLE974 measures 0"),
    ("_MVAR=3 _MA=2 _SETVAL=45\nN30 CYCLE994", 61307, "CYCLE994 measures 1"),
    ("_MVAR=0 _MA=4 _SETVAL=45\nN30 CYCLE974", 61325, "_MA = 4"),
    ("_MVAR=13 _MA=1 _MD=1 _CALNUM=0\nN30 CYCLE973", 65103, "_CALNUM = 0"),
])
def test_a_wrong_parameter_alarms_at_the_call_and_nothing_moves(lathe, call, code, text):
    """A variant or parameter the cycle does not have stops the program at the call with the
    cycle's alarm naming the parameter; the probe stays where the program put it."""
    answer = lathe.ok(lathe.c.post("/api/nc/run", json={"mda": f"N10 T8 D1 G54 G90 DIAMON G0 Z100 X160\nN20 {call}"}))
    assert answer["state"] == "alarm" and answer["block"]["number"] == 30, answer
    assert answer["alarm"]["code"] == code
    assert text in answer["alarm"]["message"]
    assert lathe.ok(lathe.c.get("/api/machine"))["wcs"]["X"] == pytest.approx(160.0)
    assert lathe.ok(lathe.c.get("/api/machine"))["wcs"]["Z"] == pytest.approx(100.0)

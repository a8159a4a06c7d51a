"""The spec's worked examples run as part programs on the simulator (``POST /api/nc/run``):
8.5-A (CYCLE977 bore, probe with direction-dependent pre-travel), 3.7-A (CYCLE977 bore with
tool offset, EV/MV memories set by the program), 9-A (CYCLE978 surface, tool offset),
12-A (CYCLE961 from 4 given points, G55 set absolutely), 11.1-A (CYCLE998, edge at 1.5°).

The scenarios are built so that the simulator's physics reproduces the example's numbers: a ball
of r = 3 whose pre-travel per direction makes the calibrated trigger values of the example
(t(−X) = 3 − δ(X−), ...), no latency and no noise; the probe record holds those trigger values
(as a calibration would leave them). Expected values are the spec's.
"""

from __future__ import annotations

import copy
import math

import pytest
from flowkit import make_client, ok

from engine import alarms

R = 3.0
PROBE = {"t": 9, "ball_diameter": 2 * R, "length": 100.0, "max_deflection": 5.0, "noise_sigma": 0.0,
         "pretravel": {"X+": 0.006, "X-": 0.010, "Y+": 0.004, "Y-": 0.008, "Z-": 0.010}}
TRIGGER = {"X-": 2.990, "X+": -2.994, "Y-": 2.992, "Y+": -2.996, "Z-": 2.990}


def scene(features, trans=(0.0, 0.0, -100.0), rot=(0.0, 0.0, 0.0), size=(400.0, 300.0, 60.0), tools=(),
          pretravel=True):
    probe = copy.deepcopy(PROBE)
    if not pretravel:
        probe.pop("pretravel")
    return {
        "seed": 1,
        "machine": {"limits": {"X": [-100, 800], "Y": [-100, 600], "Z": [-400, 100]}, "rapid": 10000,
                    "latency_s": 0.0, "time_scale": 0},
        "probe": probe,
        "workpiece": {"pose": {"trans": list(trans), "rot": list(rot)},
                      "features": [{"type": "block", "size": list(size)}, *features]},
        "tools": [{"t": 1, "type": 120, "length": 85.0, "radius": 5.0}, *tools],
        "start": {"X": 0.0, "Y": 0.0, "Z": 50.0},
    }


class Channel:
    def __init__(self, client):
        self.c = client

    def calibrated(self, trigger=TRIGGER) -> None:
        record = ok(self.c.get("/api/probes/1"))
        ok(self.c.put("/api/probes/1", json={**record, "trigger": trigger, "skew": [0.0, 0.0],
                                             "effective_diameter": 2 * R, "calibrated_radius": True,
                                             "tool": 9}))

    def run(self, text: str, state: str = "done") -> dict:
        answer = ok(self.c.post("/api/nc/run", json={"mda": text}))
        assert answer["state"] == state, answer
        return answer

    def ovr(self):
        return ok(self.c.get("/api/nc/variables", params={"names": "_OVR"}))["_OVR"]

    def ovi(self):
        return ok(self.c.get("/api/nc/variables", params={"names": "_OVI"}))["_OVI"]


# --- 8.5-A ------------------------------------------------------------------------------------------

def test_worked_example_8_5_a(tmp_path):
    """True bore (180.040, 129.970) Ø132.020 (WCS = part: G54 at the part's origin), start
    (180, 130), _SETVAL 132 → D_act 132.020, centre (180.040, 129.970), _OVR[16..18] = 0.020,
    0.040, −0.030; _MVAR=101 _KNUM=1: G54 += (0.040, −0.030)."""
    bore = {"type": "hole", "center": [180.040, 129.970], "diameter": 132.020, "depth": 40.0}
    with make_client(tmp_path, scene([bore])) as client:
        ch = Channel(client)
        ch.calibrated()
        ok(client.put("/api/offsets/G54", json={"trans": {"X": 0.0, "Y": 0.0, "Z": -100.0}}))
        ch.run("G54 G17 G90 G0 Z20\nX180 Y130\nZ-10\n_MVAR=101 _SETVAL=132 _KNUM=1 _FA=1\nCYCLE977\nG0 Z20\nM30")
        ovr = ch.ovr()
        assert ovr[4] == pytest.approx(132.020, abs=1e-9)
        assert ovr[5:7] == pytest.approx([180.040, 129.970], abs=1e-9)
        assert ovr[16:19] == pytest.approx([0.020, 0.040, -0.030], abs=1e-9)
        assert ovr[0] == 132.0 and ovr[1:3] == [180.0, 130.0]
        g54 = ok(client.get("/api/offsets/G54"))
        assert (g54["trans"]["X"], g54["trans"]["Y"]) == pytest.approx((0.040, -0.030), abs=1e-9)


# --- 3.7-A -------------------------------------------------------------------------------------------

BORE_37 = """G500 G17 G90 G0 Z-80
X100 Y100
Z-108
_MVAR=1 _SETVAL=132 _TUL=0.03 _TLL=-0.03 _TZL=0.01 _TMV=0.02 _TDIF=0.06 _TSA=1 _K=3 _EVNUM=10
_CHBIT[4]=1 _KNUM=2001 _TNUM=20 _FA=1
CYCLE977
G0 Z-80
"""


def bore_part(diameter: float) -> dict:
    return scene([{"type": "hole", "center": [100.0, 100.0], "diameter": diameter, "depth": 40.0}],
                 tools=[{"t": 20, "type": 120, "length": 90.0, "radius": 10.0}])


def test_worked_example_3_7_a(tmp_path):
    with make_client(tmp_path, bore_part(132.020)) as client:
        ch = Channel(client)
        ch.calibrated()

        def part(diameter, state="done"):
            ok(client.post("/api/sim/scenario", json=bore_part(diameter)))     # the next part; data stays
            return ch.run(BORE_37, state)

        def wear():
            return ok(client.get("/api/tools/20"))["wear"]["radius"]

        def mv():
            return ok(client.get("/api/nc/variables", params={"names": "_MV[9]"}))["_MV[9]"]

        # the memories set by the program (_EV[9] is memory 10, the same JOG and the API use)
        ch.run("_EV[9]=0.004 _MV[9]=0.006")
        assert ok(client.get("/api/memories/ev/10"))["value"] == 0.004
        # 1. 132.020: D = 0.016 -> Mv = 0.009333 <= _TZL: no correction, _MV[9] = 0.009333
        part(132.020)
        assert mv() == pytest.approx(0.028 / 3.0, abs=1e-9) and wear() == 0.0
        assert ch.ovr()[4] == pytest.approx(132.020, abs=1e-9) and ch.ovr()[20] == 0.0
        assert ch.ovr()[30] == pytest.approx(0.004) and ch.ovr()[31] == pytest.approx(0.028 / 3.0, abs=1e-9)
        # 2. 132.021: D = 0.017 -> Mv = 0.011889 > _TZL: radius wear += 0.005944, _MV[9] = 0
        part(132.021)
        assert wear() == pytest.approx(0.107 / 18.0, abs=1e-9) and mv() == 0.0
        assert ch.ovr()[20] == pytest.approx(0.107 / 18.0, abs=1e-9)
        # 3. 132.050: D = 0.046 > TUL_eff -> 62304 oversize, c = +0.023; the program goes on
        part(132.050)
        assert ch.ovi()[9] == alarms.OVERSIZE.number
        assert wear() == pytest.approx(0.107 / 18.0 + 0.023, abs=1e-9)
        assert ok(client.get("/api/nc"))["message"].startswith("62304")
        # 4. 132.070: D = 0.066 > _TDIF -> 62306, no correction
        part(132.070)
        assert ch.ovi()[9] == alarms.DIMENSION_DIFFERENCE.number
        assert wear() == pytest.approx(0.107 / 18.0 + 0.023, abs=1e-9)
        # 5. 133.2: D = 1.196 > _TSA -> 61303, the cycle aborts, nothing written
        answer = part(133.2, state="alarm")
        assert answer["alarm"]["code"] == alarms.SAFE_AREA.number and answer["alarm"]["line"] == 6
        assert ch.ovi()[9] == alarms.SAFE_AREA.number
        assert wear() == pytest.approx(0.107 / 18.0 + 0.023, abs=1e-9)
        log = ok(client.get("/api/log"))
        failed, measured = log[0], log[1:]                 # the aborted 5th part is logged as an attempt
        assert failed["status"].startswith(f"alarm {alarms.SAFE_AREA.number}")
        assert [e["result"]["decision"] for e in measured[:4]] == ["dimension_difference", "oversize", "mean", "none"]
        assert {e["program"] for e in measured} == {"MDA"} and all("CYCLE977" in e["block"] for e in measured)


def test_cbit2_stops_after_an_oversize(tmp_path):
    with make_client(tmp_path, bore_part(132.050)) as client:
        ch = Channel(client)
        ch.calibrated()
        answer = ch.run("_CBIT[2]=1\n" + BORE_37 + "M30", state="stopped")
        assert answer["block"]["text"] == "CYCLE977" and ch.ovi()[9] == alarms.OVERSIZE.number


# --- 9-A ----------------------------------------------------------------------------------------------

def test_worked_example_9_a(tmp_path):
    """Surface X = 100 machined by T20, probed from X120 travelling −X (t(−X) = 2.990): latched
    102.998 → s = 100.008, D = 0.008 ≤ _TZL (k = 1): no correction; latched 103.015 → D = 0.025 >
    _TMV: c = σ·D = −0.025 on the radius wear of T20 (measuring-math §9.3)."""
    program = ("G500 G17 G90 G0 Z-80\nX120 Y50\nZ-110\n_MVAR=0 _MA=1 _SETVAL=100 _KNUM=2001 _TNUM=20 _TUL=0.03 "
               "_TLL=-0.03 _TMV=0.02 _TZL=0.01 _TDIF=0.06 _TSA=1 _K=1 _EVNUM=0 _CHBIT[4]=0 _FA=5\nCYCLE978\nG0 Z-80")

    def part(face):    # the block's +X face at ``face``: surface s = latched − t(−X) = face
        return scene([], trans=(face - 400.0, 0.0, -100.0),
                     tools=[{"t": 20, "type": 120, "length": 90.0, "radius": 10.0}])

    with make_client(tmp_path, part(100.008)) as client:
        ch = Channel(client)
        ch.calibrated()
        ch.run(program)
        assert ch.ovr()[4] == pytest.approx(100.008, abs=1e-9) and ch.ovr()[20] == 0.0
        assert ok(client.get("/api/tools/20"))["wear"]["radius"] == 0.0
        ok(client.post("/api/sim/scenario", json=part(100.025)))
        ch.run(program)
        assert ch.ovr()[16] == pytest.approx(0.025, abs=1e-9)
        assert ch.ovr()[20] == pytest.approx(-0.025, abs=1e-9)
        assert ok(client.get("/api/tools/20"))["wear"]["radius"] == pytest.approx(-0.025, abs=1e-9)


# --- 12-A ---------------------------------------------------------------------------------------------

def test_worked_example_12_a(tmp_path):
    """P1 (50, 20), P2 (150, 20), P3 (15, 40), P4 (15, 80) in G54 = (100, 50, 0); true corner
    (20, 30) WCS, reference edge at +2°, second edge at 92° → K = (20, 30), φ = 2°; MCS corner
    (120, 80); G55 := trans (120, 80), rot Z 2°."""
    corner_mcs = (120.0, 80.0)
    # the outer corner of a block whose front-left corner is K, turned +2°
    with make_client(tmp_path, scene([], trans=(*corner_mcs, -100.0), rot=(0.0, 0.0, 2.0), size=(300, 200, 60),
                                   pretravel=False)) \
            as client:
        ch = Channel(client)
        ch.calibrated({"X-": R, "X+": -R, "Y-": R, "Y+": -R, "Z-": R})      # ideal: ρ = r
        ok(client.put("/api/offsets/G54", json={"trans": {"X": 100.0, "Y": 50.0, "Z": 0.0}}))
        ch.run("G54 G17 G90 G0 Z-80\nX50 Y20\n_MVAR=118 _SETV[0]=50 _SETV[1]=20 _SETV[2]=150 _SETV[3]=20 "
               "_SETV[4]=15 _SETV[5]=40 _SETV[6]=15 _SETV[7]=80 _ID=-30 _KNUM=2 _FA=5\nCYCLE961\nM30")
        ovr = ch.ovr()
        assert ovr[5:7] == pytest.approx([20.0, 30.0], abs=1e-9)
        assert ovr[4] == pytest.approx(2.0, abs=1e-9) and ovr[20] == pytest.approx(2.0, abs=1e-9)
        assert ovr[21:23] == pytest.approx(list(corner_mcs), abs=1e-9)
        g55 = ok(client.get("/api/offsets/G55"))
        assert (g55["trans"]["X"], g55["trans"]["Y"], g55["rot"]["Z"]) == pytest.approx((120.0, 80.0, 2.0), abs=1e-9)


# --- 11.1-A -------------------------------------------------------------------------------------------

def test_worked_example_11_1_a(tmp_path):
    """G17, _MA=102, _ID=40, _SETVAL=−18, _STA1=0, start (X−20, Y−40) → travel +Y; true edge through
    (−20, −18) turned +1.5° → α_act = 1.500°; _RA=0: G54 rotation about Z += 1.5°."""
    edge_at = (-20.0, -18.0)
    # the block's front face (part y = 0) through edge_at at 1.5°: the pose puts part (0, 0) there
    with make_client(tmp_path, scene([], trans=(edge_at[0] - 100 * math.cos(math.radians(1.5)),
                                                edge_at[1] - 100 * math.sin(math.radians(1.5)), -100.0),
                                     rot=(0.0, 0.0, 1.5), size=(300, 100, 60))) as client:
        ch = Channel(client)
        ch.calibrated()
        ok(client.put("/api/offsets/G54", json={"trans": {"X": 0.0, "Y": 0.0, "Z": 0.0}}))
        ch.run("G54 G17 G90 G0 Z-80\nX-20 Y-40\nZ-110\n_MVAR=105 _MA=102 _ID=40 _SETVAL=-18 _STA1=0 _TSA=2 "
               "_KNUM=1 _RA=0 _FA=3\nCYCLE998\nG0 Z-80")
        ovr = ch.ovr()
        assert ovr[4] == pytest.approx(1.5, abs=1e-9) and ovr[16] == pytest.approx(1.5, abs=1e-9)
        assert ok(client.get("/api/offsets/G54"))["rot"]["Z"] == pytest.approx(1.5, abs=1e-9)


def test_cycle978_top_face_corrects_the_length_wear(tmp_path):
    """measuring-math §2.3 worked check: a top face probed in −Z is 0.02 too high (D = +0.02,
    σ = −1) → c = −0.02 on L1 (_KNUM=1001: D1, length in the measuring axis Z = L1)."""
    with make_client(tmp_path, scene([], trans=(0.0, 0.0, -99.98),
                                     tools=[{"t": 20, "type": 120, "length": 90.0, "radius": 10.0}])) as client:
        ch = Channel(client)
        ch.calibrated()
        ch.run("G500 G17 G90 G0 Z-80\nX100 Y100\n_MVAR=0 _MA=3 _SETVAL=-100 _KNUM=1001 _TNUM=20 _TMV=0.01 _TUL=0.05 "
               "_TLL=-0.05 _FA=5\nCYCLE978\nG0 Z-80")
        ovr = ch.ovr()
        assert ovr[4] == pytest.approx(-99.98, abs=1e-9) and ovr[16] == pytest.approx(0.02, abs=1e-9)
        assert ovr[20] == pytest.approx(-0.02, abs=1e-9)
        tool = ok(client.get("/api/tools/20"))
        assert tool["wear"]["length"] == pytest.approx(-0.02, abs=1e-9) and tool["wear"]["radius"] == 0.0


def test_zo_variants_refuse_a_difference_beyond_the_safe_area(tmp_path):
    bore = {"type": "hole", "center": [180.0, 130.0], "diameter": 40.0, "depth": 40.0}
    with make_client(tmp_path, scene([bore])) as client:
        ch = Channel(client)
        ch.calibrated()
        ok(client.put("/api/offsets/G54", json={"trans": {"X": 0.0, "Y": 0.0, "Z": -100.0}}))
        before = ok(client.get("/api/offsets/G54"))
        answer = ch.run("G54 G0 Z20\nX181.5 Y130\nZ-10\n_MVAR=101 _SETVAL=40 _KNUM=1 _TSA=1 _FA=3\nCYCLE977",
                        state="alarm")
        assert answer["alarm"]["code"] == alarms.SAFE_AREA.number
        assert ok(client.get("/api/offsets/G54")) == before
        log = ok(client.get("/api/log"))                    # only the failed attempt, nothing written
        assert [e["status"] for e in log] == [f"alarm {alarms.SAFE_AREA.number}"] and log[0]["correction"] is None
        assert ch.ovi()[9] == alarms.SAFE_AREA.number

"""Worked example 16-A (measuring-math §16) end to end: MDA programs through ``POST /api/nc/run``
on the simulator, the machine positions read from ``GET /api/machine``.

The scene (as tests/nc/nc_scenes.py): an axis-parallel block whose left face is at MCS X 252.116
and back face at Y 127.956, probe ball r = 2 with pre-travel X+ 4 µm, Y− 6 µm, no latency, G54 =
(200, 100, −150). G100 X50 switches at WCS X 50.12 (Δx = +0.12), G100 Y30 at Y 29.95
(Δy = −0.05): the truth below is written out from those faces, never taken from the product.
"""

from __future__ import annotations

import pytest
from flowkit import make_client, ok

BALL_R, LENGTH = 2.0, 100.0
PRE = {"X+": 0.004, "X-": 0.005, "Y+": 0.003, "Y-": 0.006, "Z-": 0.002}
G54 = (200.0, 100.0, -150.0)
LEFT_FACE, BACK_FACE, TOP = 252.116, 127.956, -150.0
SIZE = (200.0, 120.0, 60.0)
SWITCH_X = LEFT_FACE - BALL_R + PRE["X+"] - G54[0]          # 50.12
SWITCH_Y = BACK_FACE + BALL_R - PRE["Y-"] - G54[1]          # 29.95
DX, DY = 0.12, -0.05           # the manual's Δx, Δy (16a); the scene above is built to switch there
Z20 = 20.0 + G54[2] + LENGTH                                # MCS Z of the spindle, ball at WCS Z20

SCENE = {
    "seed": 5,
    "machine": {"limits": {"X": [-50, 900], "Y": [-50, 600], "Z": [-400, 200]}, "rapid": 10000,
                "latency_s": 0.0, "decel": 1.0, "kv": 1.0, "time_scale": 0},
    "probe": {"t": 9, "ball_diameter": 2 * BALL_R, "length": LENGTH, "max_deflection": 5.0, "pretravel": PRE,
              "noise_sigma": 0.0},
    "workpiece": {"pose": {"trans": [LEFT_FACE, BACK_FACE - SIZE[1], TOP], "rot": [0.0, 0.0, 0.0]},
                  "features": [{"type": "block", "size": list(SIZE)}]},
    "tools": [{"t": 1, "length": 85.0, "radius": 5.0}],
    "start": {"X": 0.0, "Y": 0.0, "Z": 150.0},
}

MEASURE = """\
N10 G54 G17 G90 G0 Z20
N20 X45 Y0
N30 Z-10
N40 F100 G100 X50          ; towards X50 and on through _FA
N50 G0 X45
N60 Z20
N70 X100 Y35
N80 Z-10
N90 G100 Y30
N100 G0 Y35
N110 Z20
"""


@pytest.fixture
def c(tmp_path):
    with make_client(tmp_path, SCENE) as client:
        ok(client.put("/api/offsets/G54", json={"trans": {"X": G54[0], "Y": G54[1], "Z": G54[2]}}))
        yield client


def run(c, text, status=200):
    return ok(c.post("/api/nc/run", json={"mda": text}), status)


def axes(c):
    mcs = ok(c.get("/api/machine"))["mcs"]
    return mcs["X"], mcs["Y"], mcs["Z"]


def test_worked_example_16a_in_one_program_with_m0(c):
    answer = run(c, MEASURE + "N120 G101 X1 Y7\nN130 G1 X10 Y10\nN140 M0\nN150 G102 X1\nN160 G1 X10 Y10\nN170 M0\n"
                              "N180 G102\nN190 G1 X10 Y10\nN200 M30\n")
    assert (answer["state"], answer["block"]["number"]) == ("stopped", 140), answer
    assert axes(c) == pytest.approx((G54[0] + 10.0 + DX, G54[1] + 10.0 + 7 * DY, Z20), abs=1e-9)   # (10.12, 9.65)
    wcs = ok(c.get("/api/machine"))["wcs"]
    assert (wcs["X"], wcs["Y"]) == pytest.approx((10.12, 9.65), abs=1e-9)
    assert ok(c.get("/api/nc"))["mode"] == "MDA" and ok(c.get("/api/machine"))["mode"] == "MDA"
    answer = ok(c.post("/api/nc/start", json={}))                         # NC Start after M0
    assert (answer["state"], answer["block"]["number"]) == ("stopped", 170)
    assert axes(c) == pytest.approx((G54[0] + 10.0, G54[1] + 10.0 + 7 * DY, Z20), abs=1e-9)   # X10.00, Y9.65
    answer = ok(c.post("/api/nc/start", json={}))
    assert (answer["state"], answer["block"]["number"], answer["alarm"]) == ("done", 200, None)
    assert axes(c) == pytest.approx((G54[0] + 10.0, G54[1] + 10.0, Z20), abs=1e-9)
    assert ok(c.get("/api/machine"))["mode"] == "JOG"
    m = ok(c.get("/api/nc/variables", params={"names": "$AA_MW[Y],$AA_MM"}))
    assert m["$AA_MW[Y]"] == pytest.approx(SWITCH_Y, abs=1e-9)
    assert m["$AA_MM"]["Y"] == pytest.approx(SWITCH_Y + G54[1], abs=1e-9)


def test_worked_example_16a_as_separate_mda_runs_and_the_error_cases(c):
    assert run(c, MEASURE + "M30")["state"] == "done"
    assert run(c, "G101 X1 Y7\nG1 X10 Y10")["state"] == "done"
    assert axes(c) == pytest.approx((G54[0] + 10.0 + DX, G54[1] + 10.0 + 7 * DY, Z20), abs=1e-9)
    assert run(c, "G102 X1\nG1 X10 Y10")["state"] == "done"
    assert axes(c) == pytest.approx((G54[0] + 10.0, G54[1] + 10.0 + 7 * DY, Z20), abs=1e-9)
    # G102 Z1: nothing included for Z -> alarm at its word, nothing extracted, nothing moved
    answer = run(c, "N10 G102 Z1\nN20 G1 X20 Y20")
    assert answer["state"] == "alarm" and answer["block"]["number"] == 10
    assert answer["alarm"]["code"] == 65101 and (answer["alarm"]["line"], answer["alarm"]["column"]) == (1, 10)
    assert ok(c.get("/api/nc"))["modal"]["measuring_offsets"]["included"] == pytest.approx({"Y": 7 * DY})
    assert axes(c) == pytest.approx((G54[0] + 10.0, G54[1] + 10.0 + 7 * DY, Z20), abs=1e-9)
    # G101 Z1 without a Z measurement -> alarm
    answer = run(c, "G101 Z1")
    assert answer["state"] == "alarm" and answer["alarm"]["code"] == 65100
    assert "no measured value for axis Z" in answer["alarm"]["message"]
    assert run(c, "G102\nG1 X10 Y10")["state"] == "done"
    assert axes(c) == pytest.approx((G54[0] + 10.0, G54[1] + 10.0, Z20), abs=1e-9)
    # NC Reset clears the measured values: G101 X1 is an error then
    ok(c.post("/api/nc/reset"))
    assert run(c, "G101 X1")["alarm"]["code"] == 65100


def test_a_g100_that_does_not_switch_alarms_at_its_block(c):
    answer = run(c, "N10 G54 G0 Z20\nN20 X45 Y0\nN30 Z-10\nN40 F100 G100 X46")
    assert answer["state"] == "alarm" and answer["alarm"]["code"] == 61301
    assert (answer["alarm"]["line"], answer["alarm"]["column"]) == (4, 15)
    assert ok(c.get("/api/machine"))["wcs"]["X"] == pytest.approx(48.0, abs=1e-9)

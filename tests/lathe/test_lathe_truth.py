"""The lathe tasks through the API against the simulated lathe's truth (turning.md §10.2, §11).

Every number measured comes from the product (engine + workflow + simulator); the assertions
compare it with the scenario's truth: the tool probe faces, the tools' true L1/L2, the probe's
true ball centre and radius, the shaft's true diameter, the face's true position.
"""

from __future__ import annotations

import pytest
from lathe_kit import LATHE_SCENARIO, TRUE_FACES, Lathe, lathe_scenario, make_client

UM = 1e-3


@pytest.fixture
def lathe(tmp_path):
    with make_client(tmp_path) as client:
        yield Lathe(client)


def test_tool_probe_calibrated_with_the_exact_calibration_tool(lathe):
    """1-B: rough _TP 220/200/400/380 (seeded from the cube's rounded faces), the exact T7: each
    call stores its face at the truth (no pre-travel, no latency: the face itself)."""
    assert lathe.ok(lathe.c.get("/api/tool-probes/1"))["trigger"] == {"Z-": 220.0, "Z+": 200.0, "X-": 400.0,
                                                                      "X+": 380.0}
    out = lathe.calibrate_tool_probe()
    for key, answer in out.items():
        assert answer["result"]["trigger"][key] == pytest.approx(TRUE_FACES[key], abs=1e-9)
        assert answer["correction"]["target"] == "TP1"
    faces = lathe.ok(lathe.c.get("/api/tool-probes/1"))["trigger"]
    assert faces == pytest.approx(TRUE_FACES, abs=1e-9)
    assert out["X-"]["result"]["difference"]["X-"] == pytest.approx(0.25, abs=1e-9)        # 1-B's table
    assert out["Z+"]["result"]["difference"]["Z+"] == pytest.approx(-0.35, abs=1e-9)


def test_turning_tool_with_nominal_data_measured_to_its_true_lengths(lathe):
    """2-B: T3 stored 100.65/60.32, true 100.70/60.30: automatic, first measurement (geometry)."""
    lathe.calibrate_tool_probe()
    lathe.tool(3)
    lathe.tip_to(3, 420.0, 240.0)
    answer = lathe.task("lathe.tool.auto", {"measuring_path": 1, "tolerance": {"safe_area": 1, "dim_difference": 0.8}})
    length = answer["result"]["length"]
    assert length["L1"]["actual"] == pytest.approx(100.70, abs=2 * UM)
    assert length["L2"]["actual"] == pytest.approx(60.30, abs=2 * UM)
    assert length["L1"]["difference"] == pytest.approx(0.05, abs=1e-9)
    row = lathe.ok(lathe.c.get("/api/tools/3"))
    assert row["l1"] == pytest.approx(100.70, abs=1e-9) and row["l2"] == pytest.approx(60.30, abs=1e-9)
    assert row["wear"]["l1"] == row["wear"]["l2"] == 0.0 and row["sl"] == 3
    assert answer["correction"]["before"]["l1"] == 100.65


def test_one_length_as_a_re_measurement_into_the_wear(lathe):
    """2-A: _MVAR=1, _CHBIT[3]=1: L1 −X then L2 −Z, each wear += Δ (0.050, −0.020)."""
    lathe.calibrate_tool_probe()
    lathe.tool(3)
    params = {"measuring_path": 1, "compensation": "wear", "tolerance": {"safe_area": 1, "dim_difference": 0.8}}
    lathe.tip_to(3, 420.0, 240.0)
    first = lathe.task("lathe.tool.measure", {**params, "axis": "X"})
    assert first["result"]["length"]["L1"]["actual"] == pytest.approx(100.70, abs=1e-9)
    lathe.tip_to(3, 420.0, 240.0)
    second = lathe.task("lathe.tool.measure", {**params, "axis": "Z"})
    assert second["result"]["length"]["L2"]["actual"] == pytest.approx(60.30, abs=1e-9)
    row = lathe.ok(lathe.c.get("/api/tools/3"))
    assert (row["l1"], row["l2"]) == (100.65, 60.32)
    assert row["wear"]["l1"] == pytest.approx(0.050, abs=1e-9) and row["wear"]["l2"] == pytest.approx(-0.020, abs=1e-9)
    assert lathe.status()["tool_lengths"] == pytest.approx({"L1": 100.70, "L2": 60.30}, abs=1e-9)


def test_probe_calibrated_in_the_groove(lathe):
    """4-A: the ball centre 0.004 higher than the nominal L1 says, effective radius 2.995."""
    out = lathe.calibrate_probe_in_groove()
    record = lathe.ok(lathe.c.get("/api/probes/1"))
    assert record["position_deviation"]["X"] == pytest.approx(0.004, abs=1e-9)
    assert record["trigger"]["X-"] == pytest.approx(2.995, abs=1e-9)
    assert record["trigger"]["X+"] == pytest.approx(-2.995, abs=1e-9)
    assert record["trigger"]["Z-"] == pytest.approx(2.995, abs=1e-9)
    assert record["effective_diameter"] == pytest.approx(5.990, abs=1e-9)
    assert out["X"]["result"]["probe"]["wp"][8] == pytest.approx(0.004, abs=1e-9)
    assert out["X"]["correction"]["target"] == "WP1"


def _shaft_at(lathe: Lathe, target=None, **params) -> dict:
    lathe.ball_to(60.0, 30.0, coords="WCS")          # Ø60 in the WCS (DIAMON), Z30 over the shaft
    return lathe.task("lathe.point", {"axis": "X", "setpoint": 45, "measuring_path": 2, **params}, target=target)


def test_eccentric_shaft_with_reversal_reads_its_true_diameter(lathe):
    """5-C: Ø45.006 clamped 0.030 off centre: with reversal 45.006; without, at SPOS 0, 45.066
    (twice the eccentricity's X component), at SPOS 180 44.946."""
    lathe.calibrate_probe_in_groove()
    answer = _shaft_at(lathe, reversal=True, start_angle=0)
    assert answer["result"]["actual"] == pytest.approx(45.006, abs=2 * UM)
    assert answer["result"]["unit"] == "diameter"
    lathe.retract()
    lathe.spos(0)
    off = _shaft_at(lathe)["result"]["actual"]
    assert off == pytest.approx(45.006 + 2 * 0.030, abs=1e-9)
    lathe.retract()
    lathe.spos(180)
    assert _shaft_at(lathe)["result"]["actual"] == pytest.approx(45.006 - 2 * 0.030, abs=1e-9)


def test_eccentricity_in_y_leaves_only_the_second_order_residual(tmp_path):
    """5-C's remark: e = 0.030 in Y changes s by −e²/(2ρ) only (ρ = R + r = 25.498): −1.8e-5."""
    scenario = lathe_scenario(workpiece__eccentricity=[0.0, 0.030])
    with make_client(tmp_path, scenario) as client:
        lathe = Lathe(client, scenario)
        lathe.calibrate_probe_in_groove()
        actual = _shaft_at(lathe, reversal=True)["result"]["actual"]
    rho = 22.503 + 2.995
    assert actual == pytest.approx(45.006 - 2 * 0.030 ** 2 / (2 * rho), abs=2e-7)


def test_face_set_into_g54_z(lathe):
    """5-A-like: the face at MCS Z 60 (part z 60 from the chuck face), G54 Z 0.5 -> measured 59.5,
    100 % into G54: Z 0.000, and the face reads Z 60 afterwards."""
    lathe.calibrate_probe_in_groove()
    lathe.ok(lathe.c.put("/api/offsets/G54", json={"trans": {"Z": 0.5}}))
    lathe.ok(lathe.c.post("/api/machine/activate", json={"offset": "G54"}))
    lathe.ball_to(40.0, 80.0, coords="WCS")               # Ø40: over the face ring between the bore and the OD
    answer = lathe.task("lathe.point", {"axis": "Z", "setpoint": 60, "measuring_path": 2}, target="G54")
    assert answer["result"]["actual"] == pytest.approx(59.5, abs=1e-9)
    assert answer["result"]["decision"] == "full"
    g54 = lathe.ok(lathe.c.get("/api/offsets/G54"))
    assert g54["trans"]["Z"] == pytest.approx(0.0, abs=1e-9)
    assert answer["activated"] is True
    lathe.ball_to(40.0, 80.0, coords="WCS")
    again = lathe.task("lathe.point", {"axis": "Z", "setpoint": 60, "measuring_path": 2})
    assert again["result"]["actual"] == pytest.approx(60.0, abs=1e-9)


def test_two_point_diameter_cancels_the_eccentricity(lathe):
    """CYCLE994 (6-A): both points at the same spindle angle, the X eccentricity cancels."""
    lathe.calibrate_probe_in_groove()
    lathe.ball_to(60.0, 30.0, coords="WCS")
    answer = lathe.task("lathe.two_point", {"axis": "X", "setpoint": 45, "zone": {"Z": 70, "X": 60},
                                            "measuring_path": 2})
    assert answer["result"]["diameter"] == pytest.approx(45.006, abs=1e-9)
    assert lathe.status()["wcs"]["X"] < 0                      # ends below the turning centre (P2)


def test_the_hidden_check_scenario(tmp_path):
    """The issue's check: exact calibration tool, a turning tool with nominal lengths, a probe with
    a wrong nominal L1, a shaft 0.030 off centre: L1/L2 within 2 µm, the diameter within 2 µm."""
    scenario = lathe_scenario(probe__nominal={"l1": 40.2, "l2": 100.456, "ball_diameter": 6.0})
    with make_client(tmp_path, scenario) as client:
        lathe = Lathe(client, scenario)
        lathe.calibrate_tool_probe()
        lathe.tool(3)
        lathe.tip_to(3, 420.0, 240.0)
        lathe.task("lathe.tool.auto", {"measuring_path": 1, "tolerance": {"safe_area": 1, "dim_difference": 0.8}})
        l1, l2 = lathe.lengths(3)
        assert abs(l1 - 100.70) <= 2 * UM and abs(l2 - 60.30) <= 2 * UM
        lathe.calibrate_probe_in_groove(fa=2.0)
        diameter = _shaft_at(lathe, reversal=True)["result"]["actual"]
        assert abs(diameter - 45.006) <= 2 * UM


def test_a_part_series_corrected_by_the_strategy(tmp_path):
    """turning.md §11 closed loop: T1 cuts the OD against its stored L1 (0.010 too long: Ø+0.020)
    and wears 2 µm per part; each part is measured with reversal and T1's L1 wear corrected
    (c = −D/2, §0.11): the series stays in a ±5 µm band on the diameter after the first part."""
    profile = [{"type": "cylinder", "z": [0, 60], "diameter": 45.0, "machined_by": {"t": 1}},
               {"type": "bore", "z": [20, 60], "diameter": 35.0}]
    scenario = lathe_scenario(workpiece__profile=profile)
    scenario["tools"][2] = {"t": 1, "type": 500, "sl": 3, "l1": 60.0, "l2": 30.0, "radius": 0.8,
                            "nominal": {"l1": 60.010}, "wear_per_part": {"l1": 0.002}}
    target = {"tool": 1, "correct": "length", "mode": "wear"}
    tolerance = {"upper": 0.005, "lower": -0.005, "zero_range": 0.001, "mean_range": 0.002,
                 "dim_difference": 0.2, "safe_area": 0.5}
    with make_client(tmp_path, scenario) as client:
        lathe = Lathe(client, scenario)
        lathe.calibrate_probe_in_groove()
        made, decisions = [], []
        for _ in range(12):
            lathe.retract()
            lathe.ok(client.post("/api/sim/machine-part", json={}))
            made.append(client.app.state.services.machine.machine.part_diameters[0])
            answer = _shaft_at(lathe, target, reversal=True, tolerance=tolerance)
            decisions.append(answer["result"]["decision"])
            assert answer["result"]["actual"] == pytest.approx(made[-1], abs=1e-9)
    assert made[0] == pytest.approx(45.020, abs=1e-9)
    assert decisions[0] == "oversize"
    assert all(abs(d - 45.0) <= 0.005 + 1e-9 for d in made[1:]), made
    assert "mean" in decisions or "full" in decisions


def test_without_groove_calibration_the_wrong_l1_shows_in_the_diameter(tmp_path):
    """A probe calibrated only by hand-entered ball radius (trigger X− = r) carries its L1 error
    into the radius: the groove calibration is what removes it."""
    scenario = lathe_scenario(probe__nominal={"l1": 40.2, "l2": 100.456, "ball_diameter": 6.0})
    with make_client(tmp_path, scenario) as client:
        lathe = Lathe(client, scenario)
        lathe.ok(client.put("/api/probes/1", json={"tool": 8, "ball_diameter": 6.0, "trigger": {"X-": 3.0}}))
        lathe.tool(8)
        actual = _shaft_at(lathe, reversal=True)["result"]["actual"]
    # the NC puts the ball centre 0.081 lower than it is (L1 40.2 vs 40.119): the latched centre and the
    # radius read 0.081 small, and the entered radius 3.0 (true 2.995) takes another 0.005 off
    assert actual == pytest.approx(45.006 - 2 * (40.2 - 40.119) - 2 * 0.005, abs=1e-9)
    assert LATHE_SCENARIO["probe"]["l1"] == 40.119


def test_a_radial_probe_sl8_calibrated_in_the_radial_groove(tmp_path):
    """SL 8 (stylus towards the axis): the radial groove's Z walls with position deviation and
    ball diameter, its bottom travelling −X (the trigger absorbs the L1 error), then the shaft."""
    scenario = lathe_scenario(probe__sl=8)
    with make_client(tmp_path, scenario) as client:
        lathe = Lathe(client, scenario)
        lathe.tool(8)
        params = {"groove": {"number": 1}, "measuring_path": 2, "tolerance": {"safe_area": 4}}
        lathe.ball_to(140.0, 40.0)
        z = lathe.task("lathe.probe.groove", {**params, "axis": "Z", "direction": "both", "skew": True,
                                              "ball_diameter": True})
        assert z["result"]["probe"]["trigger"]["Z-"] == pytest.approx(2.995, abs=1e-9)
        assert z["result"]["effective_diameter"] == pytest.approx(5.99, abs=1e-9)
        lathe.goto(X=140.0 + 40.123)                         # out of the radial groove upwards first
        lathe.ball_to(140.0, 40.0)
        x = lathe.task("lathe.probe.groove", {**params, "axis": "X", "direction": "-"})
        assert x["result"]["trigger"]["X-"] == pytest.approx(2.995 - 0.004, abs=1e-9)
        lathe.goto(X=140.0 + 40.123)
        assert _shaft_at(lathe, reversal=True)["result"]["actual"] == pytest.approx(45.006, abs=2 * UM)


def test_a_bore_series_corrects_l1_with_the_lathe_sign(tmp_path):
    """turning.md §0.11 / §12 Q4: a bore measured travelling +X: the boring bar's L1 0.010 too long
    makes the bore 0.020 large; the correction is c = −D/2 on L1 (MM §2.3's σ·D would be +D/2 and
    make the next bore 0.040 large): the second bore is right."""
    profile = [{"type": "cylinder", "z": [0, 60], "diameter": 45.006},
               {"type": "bore", "z": [20, 60], "diameter": 35.0, "machined_by": {"t": 2}}]
    scenario = lathe_scenario(workpiece__profile=profile)
    scenario["tools"].append({"t": 2, "type": 500, "sl": 2, "l1": 70.0, "l2": 90.0, "radius": 0.4,
                              "nominal": {"l1": 70.010}})
    target = {"tool": 2, "correct": "length", "mode": "wear"}
    tolerance = {"upper": 0.005, "lower": -0.005, "mean_range": 0.002, "dim_difference": 0.2, "safe_area": 0.5}
    with make_client(tmp_path, scenario) as client:
        lathe = Lathe(client, scenario)
        lathe.calibrate_probe_in_groove()
        lathe.ball_to(80.0, 40.0)                           # X+ trigger: the groove's +X wall
        lathe.task("lathe.probe.groove", {"groove": {"number": 1}, "axis": "X", "direction": "+", "measuring_path": 2,
                                          "tolerance": {"safe_area": 4}})
        made, compensations = [], []
        for _ in range(3):
            lathe.retract()
            lathe.ok(client.post("/api/sim/machine-part", json={}))
            made.append(client.app.state.services.machine.machine.part_diameters[1])
            lathe.retract()
            lathe.goto(Z=100.0 + 100.456)
            lathe.goto(X=0.0 + 40.123)
            lathe.goto(Z=40.0 + 100.456)                    # on the axis inside the bore
            answer = lathe.task("lathe.point", {"axis": "X", "setpoint": 35, "measuring_path": 2, "reversal": True,
                                                "tolerance": tolerance}, target=target)
            assert answer["result"]["actual"] == pytest.approx(made[-1], abs=1e-9)
            compensations.append(answer["result"]["compensation"])
            lathe.goto(X=0.0 + 40.123)
            lathe.goto(Z=100.0 + 100.456)
    assert made[0] == pytest.approx(35.020, abs=1e-9)
    assert compensations[0] == pytest.approx(-0.010, abs=1e-9)
    assert made[1] == pytest.approx(35.0, abs=1e-9) and made[2] == pytest.approx(35.0, abs=1e-9)


@pytest.mark.parametrize("zone", [None, {"Z": 80}])
def test_two_point_inside_diameter(lathe, zone):
    """CYCLE994 on the bore: _MVAR=2 without a zone crosses at the measuring Z, _MVAR=1 leaves the
    bore via zone.Z; the eccentricity cancels."""
    lathe.calibrate_probe_in_groove()
    lathe.retract()
    lathe.goto(Z=100.0 + 100.456)
    lathe.goto(X=10.0 + 40.123)
    lathe.goto(Z=40.0 + 100.456)                       # inside the bore, above the axis
    params = {"axis": "X", "setpoint": 35, "inside": True, "measuring_path": 2}
    if zone:
        params["zone"] = zone
    answer = lathe.task("lathe.two_point", params)
    assert answer["result"]["diameter"] == pytest.approx(35.004, abs=1e-9)
    assert answer["session"]["params"]["inside"] is True


def test_a_groove_record_off_its_truth_shows_in_the_calibration(tmp_path):
    """turning.md §11: the true groove may differ from the _KB the HMI holds: the trigger values
    follow the entered surfaces (here x_plus entered 0.010 too large: t(X+) 0.010 more negative)."""
    kb = {"x_minus": 50.054, "x_plus": 60.133, "bottom_z": 15.021}
    scenario = lathe_scenario()
    scenario["grooves"][0]["nominal"] = kb
    with make_client(tmp_path, scenario) as client:
        lathe = Lathe(client, scenario)
        assert lathe.ok(client.get("/api/lathe/grooves/1")) == {"number": 1, **kb}
        lathe.tool(8)
        lathe.ball_to(80.0, 40.0)
        answer = lathe.task("lathe.probe.groove", {"groove": {"number": 1}, "axis": "X", "direction": "+",
                                                   "measuring_path": 2, "tolerance": {"safe_area": 4}})
    assert answer["result"]["trigger"]["X+"] == pytest.approx(-2.995 - 0.004 - 0.010, abs=1e-9)

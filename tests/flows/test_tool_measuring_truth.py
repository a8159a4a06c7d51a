"""Tool measuring end to end (spec/jog-measuring.md §7, measuring-math §14) against the scenario.

Driven only through the JSON API. Truth is the scenario: the cutters' true length/radius, the
tool probe's top-face centre, disc diameter and pre-travel, the machine's latch delay (design.md
§5: latched = switch + v·latency along the travel). The tool table starts from the cutters'
nominal values (tens of µm off); after calibrating with an exact calibration tool the measured
length and radius must match the truth within 2 µm. Nothing is copied from the product's output.
"""

from __future__ import annotations

import copy
import json

import pytest
from fastapi.testclient import TestClient

TOL = 0.002                     # mm: the bar of the issue (2 µm)
LATENCY = 0.004                 # s
TP_CENTER = (700.0, 400.0, -140.0)
TP_DISC, TP_HEIGHT, TP_PRETRAVEL = 20.0, 40.0, 0.001
CAL_T, CUTTER_T, WIDE_T, DRILL_T = 5, 1, 2, 3

SCENARIO = {
    "seed": 3,
    "machine": {"limits": {"X": [-10, 800], "Y": [-10, 500], "Z": [-400, 10]}, "rapid": 10000,
                "jog_feed": 1000, "latency_s": LATENCY, "decel": 1.0, "kv": 1.0, "time_scale": 0},
    "probe": {"t": 9, "ball_diameter": 4.0, "length": 100.0, "max_deflection": 5.0},
    "workpiece": {"pose": {"trans": [250.0, 150.0, -120.0], "rot": [0.0, 0.0, 0.0]},
                  "features": [{"type": "block", "size": [200, 120, 60]}]},
    "tool_probe": {"center": list(TP_CENTER), "disc_diameter": TP_DISC, "height": TP_HEIGHT,
                   "pretravel": TP_PRETRAVEL},
    "tools": [
        {"t": CAL_T, "type": 120, "length": 100.0, "radius": 6.0},                    # exact data
        {"t": CUTTER_T, "type": 120, "length": 85.0, "radius": 5.0,
         "nominal": {"length": 85.037, "radius": 5.024}},
        {"t": WIDE_T, "type": 120, "length": 120.5, "radius": 14.0,                   # 2R > disc
         "nominal": {"length": 120.46, "radius": 13.97}},
        {"t": DRILL_T, "type": 200, "length": 110.2, "radius": 4.0,
         "nominal": {"length": 110.25, "radius": 3.985}},
    ],
    "start": {"X": 400.0, "Y": 300.0, "Z": 0.0},
}
TRUE = {t["t"]: t for t in SCENARIO["tools"]}


def scenario(**machine) -> dict:
    data = copy.deepcopy(SCENARIO)
    data["machine"].update(machine)
    return data


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    from app.config import Settings
    from app.main import create_app

    root = tmp_path_factory.mktemp("toolmeasure")
    path = root / "scenario.json"
    path.write_text(json.dumps(SCENARIO))
    with TestClient(create_app(Settings(db_path=root / "hmi.db", scenario_path=path, time_scale=0))) as c:
        yield c


@pytest.fixture
def api(client):
    """Fresh machine and data for every test."""
    ok(client.post("/api/sim/scenario", json={**SCENARIO, "reset_data": True}))
    return Api(client)


def ok(response, status: int = 200) -> dict:
    assert response.status_code == status, response.text
    return response.json()


class Api:
    def __init__(self, client: TestClient):
        self.c = client

    def tool(self, t: int) -> dict:
        return ok(self.c.get(f"/api/tools/{t}"))

    def goto_mcs(self, **axes) -> None:
        ok(self.c.post("/api/machine/goto", json={**axes, "coords": "MCS"}))

    def load(self, t: int) -> None:
        self.goto_mcs(Z=0.0)
        ok(self.c.post("/api/machine/tool", json={"tool": t}))

    def place(self, t: int, dx: float, dy: float, above: float) -> None:
        """The operator puts T``t`` with its tip ``above`` mm over the probe top (as the tool
        table believes its length), ``dx``/``dy`` off the probe centre: up, across, down."""
        self.load(t)
        length = self.tool(t)["length"]
        self.goto_mcs(X=TP_CENTER[0] + dx, Y=TP_CENTER[1] + dy)
        self.goto_mcs(Z=TP_CENTER[2] + length + above)

    def measure(self, task: str, params: dict | None = None, status: int = 200) -> dict:
        session = ok(self.c.post("/api/measure", json={"task": task, "params": params or {}}))
        return ok(self.c.post(f"/api/measure/{session['id']}/start", json={}), status)

    def create_error(self, task: str, params: dict) -> dict:
        return ok(self.c.post("/api/measure", json={"task": task, "params": params}), 400)["error"]

    def calibrate(self, mode: str = "length_diameter", above: float = 6.0) -> dict:
        self.place(CAL_T, 0.8, -0.6, above)           # roughly above the centre
        return self.measure("toolprobe.calibrate", {"mode": mode})

    def length(self, t: int, status: int = 200, **params) -> dict:
        self.place(t, 0.4, 0.3, 7.0)
        return self.measure("tool.length", params, status)

    def diameter(self, t: int, status: int = 200, **params) -> dict:
        self.place(t, 35.0, 0.0, 5.0)                 # beside and above the probe
        return self.measure("tool.diameter", params, status)

    def settings(self, **values) -> None:
        ok(self.c.put("/api/settings", json=values))


ERRORS: dict[str, float] = {}


def _record(name: str, error: float) -> None:
    ERRORS[name] = error
    print(f"{name}: error {error * 1000:+.4f} µm")


# --- calibration --------------------------------------------------------------------------------

def test_calibration_stores_trigger_values_of_the_true_probe(api):
    answer = api.calibrate("length_diameter")
    record = answer["result"]["tool_probe"]
    tp = record["trigger"]
    v = 100.0 / 60.0                               # E_MESS_MT_FM default, mm/s
    late = TP_PRETRAVEL + v * LATENCY              # switch behind contact + latch delay path
    cx, cy, top = TP_CENTER
    assert tp["Z-"] == pytest.approx(top - late, abs=1e-6)
    assert tp["X-"] == pytest.approx(cx + TP_DISC / 2 - late, abs=1e-6)   # probe's +X face
    assert tp["X+"] == pytest.approx(cx - TP_DISC / 2 + late, abs=1e-6)
    assert tp["Y-"] == pytest.approx(cy + TP_DISC / 2 - late, abs=1e-6)
    assert tp["Y+"] == pytest.approx(cy - TP_DISC / 2 + late, abs=1e-6)
    assert answer["result"]["center"] == pytest.approx({"X": cx, "Y": cy}, abs=1e-6)
    stored = ok(api.c.get("/api/tool-probes/1"))
    assert stored["trigger"] == pytest.approx(tp)
    assert stored["calibrated_length"] and stored["calibrated_diameter"]
    assert stored["calibration_tool"] == CAL_T and stored["calibration_feed"] == 100.0
    assert stored["calibrated_at"]
    assert answer["correction"]["target"] == "TP1"
    # the calibration tool's data stay untouched
    assert api.tool(CAL_T)["length"] == TRUE[CAL_T]["length"]


def test_length_only_calibration_then_length_but_no_diameter(api):
    answer = api.calibrate("length")
    assert set(answer["result"]["tool_probe"]["trigger"]) == {"Z-"}
    result = api.length(CUTTER_T)["result"]
    _record("T1 length (length-only calibration)", result["length"] - TRUE[CUTTER_T]["length"])
    assert abs(api.tool(CUTTER_T)["length"] - TRUE[CUTTER_T]["length"]) <= TOL
    failed = api.diameter(CUTTER_T, status=409)
    assert "61341" in failed["error"]["message"] and "calibrat" in failed["error"]["message"]


def test_first_calibration_searches_from_further_above(api):
    """No rough trigger value yet: the first −Z touch searches over E_MESS_D_M (50 mm)."""
    tp = api.calibrate("length", above=35.0)["result"]["tool_probe"]["trigger"]
    late = TP_PRETRAVEL + 100.0 / 60.0 * LATENCY
    assert tp["Z-"] == pytest.approx(TP_CENTER[2] - late, abs=1e-6)


# --- measuring against truth --------------------------------------------------------------------

@pytest.mark.parametrize("t", [CUTTER_T, WIDE_T, DRILL_T])
def test_length_and_radius_within_2_um_of_truth(api, t):
    api.calibrate("length_diameter")
    nominal = api.tool(t)
    assert abs(nominal["length"] - TRUE[t]["length"]) > 0.02        # the table is only nominal
    length = api.length(t)
    diameter = api.diameter(t)
    tool = api.tool(t)
    _record(f"T{t} length", tool["length"] - TRUE[t]["length"])
    _record(f"T{t} radius", tool["radius"] - TRUE[t]["radius"])
    assert abs(tool["length"] - TRUE[t]["length"]) <= TOL
    assert abs(tool["radius"] - TRUE[t]["radius"]) <= TOL
    assert tool["wear"] == {"length": 0.0, "radius": 0.0}
    assert length["result"]["length"] == pytest.approx(tool["length"])
    assert diameter["result"]["radius"] == pytest.approx(tool["radius"])
    assert diameter["result"]["diameter"] == pytest.approx(2 * tool["radius"])   # shows both
    assert diameter["correction"]["target"] == f"T{t}"
    assert diameter["correction"]["before"]["radius"] == pytest.approx(nominal["radius"])
    # the NC's offset length follows the table
    assert ok(api.c.get("/api/machine"))["tool_length"] == pytest.approx(tool["length"])


def test_rotating_stationary_rule(api):
    """Spec §7.3: length stationary and centred if 2R ≤ E_MESS_MT_DL, else rotating and offset
    by R; radius always rotating (speed n = min(E_MESS_MAX_S, E_MESS_MAX_V/(2πr)))."""
    api.calibrate("length_diameter")
    narrow = api.length(CUTTER_T)["result"]["spindle"]
    wide = api.length(WIDE_T)["result"]
    assert narrow["rotating"] is False and narrow["speed"] == 0.0
    assert wide["spindle"]["rotating"] is True
    assert wide["lateral_offset"] == pytest.approx(13.97)            # the table's R (nominal)
    assert wide["spindle"]["speed"] == pytest.approx(min(1000.0, 100.0 / (2 * 3.141592653589793 * 0.01397)))
    radius = api.diameter(CUTTER_T)["result"]["spindle"]
    assert radius["rotating"] is True and radius["speed"] == pytest.approx(1000.0)
    # E_MESS_MT_DL narrower than the cutter: T1 is measured rotating and offset, still true
    api.settings(mt_dl=8.0)
    offset = api.length(CUTTER_T)["result"]
    assert offset["spindle"]["rotating"] is True
    assert abs(api.tool(CUTTER_T)["length"] - TRUE[CUTTER_T]["length"]) <= TOL


def test_latch_delay_is_compensated_between_calibration_and_rotating_feed(api):
    """Calibration at 100 mm/min, rotating measuring at n·Δ = 10 mm/min: the latch delay alone
    would leave (10 − 100)/60·t = −6 µm; the result refers both to feed 0."""
    api.calibrate("length_diameter")
    latch = api.diameter(CUTTER_T)["result"]["latch"]
    assert latch["delay_s"] == pytest.approx(LATENCY, rel=1e-3)
    assert latch["correction"] == pytest.approx((10.0 - 100.0) / 60.0 * LATENCY, abs=1e-7)


def test_the_log_keeps_the_tool_point_with_its_data(api):
    """The logged P1 of a tool measurement carries its touch, not only its kind: the tool tip at
    the latch as the NC computed it (with the nominal L1), pre-travel + latch path below the top."""
    api.calibrate("length_diameter")
    answer = api.length(CUTTER_T)
    point = ok(api.c.get(f"/api/log/{answer['log_id']}"))["points"]["P1"]
    feeds = answer["result"]["spindle"]["feeds"]
    assert point["type"] == "ToolPoint" and point["kind"] == "length"
    assert point["feeds"] == pytest.approx(feeds) and point["touch"]["key"] == "Z-"
    late = TP_PRETRAVEL + feeds[-1] / 60.0 * LATENCY
    nominal_error = TRUE[CUTTER_T]["length"] - TRUE[CUTTER_T]["nominal"]["length"]
    assert point["touch"]["rec"][2] == pytest.approx(TP_CENTER[2] - late + nominal_error, abs=1e-6)


def test_offset_v_special_cutting_edges(api):
    """Offset V moves the contact (length: in the plane; diameter: up): flat-end cutters stay true."""
    api.calibrate("length_diameter")
    length = api.length(CUTTER_T, offset_v=2.0)["result"]
    assert length["offset_v"] == 2.0 and length["lateral_offset"] == pytest.approx(2.0)
    radius = api.diameter(CUTTER_T, offset_v=1.5)["result"]
    tool = api.tool(CUTTER_T)
    assert abs(tool["length"] - TRUE[CUTTER_T]["length"]) <= TOL
    assert abs(tool["radius"] - TRUE[CUTTER_T]["radius"]) <= TOL
    assert radius["offset_v"] == 1.5


# --- geometry / wear bookkeeping (spec §7.3 _JM_B[0]) ------------------------------------------

def test_geometry_mode_writes_geometry_and_clears_that_wear(api):
    api.calibrate("length_diameter")
    ok(api.c.put(f"/api/tools/{CUTTER_T}", json={"wear": {"length": 0.011, "radius": -0.007}}))
    api.length(CUTTER_T, compensation="geometry")
    tool = api.tool(CUTTER_T)
    assert abs(tool["length"] - TRUE[CUTTER_T]["length"]) <= TOL
    assert tool["wear"] == {"length": 0.0, "radius": -0.007}        # only the measured component
    api.diameter(CUTTER_T, compensation="geometry")
    tool = api.tool(CUTTER_T)
    assert abs(tool["radius"] - TRUE[CUTTER_T]["radius"]) <= TOL and tool["wear"]["radius"] == 0.0


def test_wear_mode_keeps_geometry_and_writes_the_difference(api):
    api.calibrate("length_diameter")
    nominal = TRUE[CUTTER_T]["nominal"]
    api.settings(tool_offset_mode="wear")                           # _JM_B[0] = 1
    answer = api.length(CUTTER_T)
    tool = api.tool(CUTTER_T)
    assert answer["result"]["mode"] == "wear"
    assert tool["length"] == pytest.approx(nominal["length"])
    assert abs(tool["length"] + tool["wear"]["length"] - TRUE[CUTTER_T]["length"]) <= TOL
    assert abs(tool["wear"]["length"] - (TRUE[CUTTER_T]["length"] - nominal["length"])) <= TOL
    api.diameter(CUTTER_T)
    tool = api.tool(CUTTER_T)
    assert tool["radius"] == pytest.approx(nominal["radius"])
    assert abs(tool["radius"] + tool["wear"]["radius"] - TRUE[CUTTER_T]["radius"]) <= TOL
    # a second measurement in wear mode: wear := measured − geometry (not accumulated)
    api.diameter(CUTTER_T)
    again = api.tool(CUTTER_T)
    assert again["wear"]["radius"] == pytest.approx(tool["wear"]["radius"], abs=1e-6)
    # the API parameter overrides the setting
    api.length(CUTTER_T, compensation="geometry")
    tool = api.tool(CUTTER_T)
    assert tool["wear"]["length"] == 0.0 and abs(tool["length"] - TRUE[CUTTER_T]["length"]) <= TOL


# --- refusals -----------------------------------------------------------------------------------

@pytest.mark.parametrize(("task", "params", "field"), [
    ("tool.length", {"offset_v": -1.0}, "offset_v"),
    ("tool.diameter", {"offset_v": "abc"}, "offset_v"),
    ("tool.length", {"compensation": "both"}, "compensation"),
    ("toolprobe.calibrate", {"mode": "diameter"}, "mode"),
])
def test_bad_inputs_name_the_field(api, task, params, field):
    error = api.create_error(task, params)
    assert error.get("field") == field and field in error["message"]


def test_missing_calibration_is_a_clear_alarm(api):
    failed = api.length(CUTTER_T, status=409)
    assert "61341" in failed["error"]["message"] and "calibrate the tool probe" in failed["error"]["message"]
    alarms = ok(api.c.get("/api/machine"))["alarms"]
    assert any(a["code"] == 61341 for a in alarms)
    assert api.tool(CUTTER_T)["length"] == TRUE[CUTTER_T]["nominal"]["length"]     # nothing written


def test_missing_probe_width_is_alarm_61230(api):
    api.calibrate("length")
    ok(api.c.post("/api/machine/reset"))
    record = ok(api.c.get("/api/tool-probes/1"))
    ok(api.c.put("/api/tool-probes/1", json={**record, "disc_diameter": 0.0}))
    failed = api.length(CUTTER_T, status=409)["error"]["message"]
    assert "61230" in failed and "E_MESS_MT_DL" in failed
    ok(api.c.post("/api/machine/reset"))
    api.settings(mt_dl=20.0)                                   # the GUD value is enough
    api.length(CUTTER_T)
    assert abs(api.tool(CUTTER_T)["length"] - TRUE[CUTTER_T]["length"]) <= TOL


def test_probe_in_spindle_is_refused(api):
    api.calibrate("length_diameter")
    api.load(9)
    failed = api.measure("tool.length", {}, status=409)["error"]["message"]
    assert "61314" in failed and "probe" in failed


def test_tool_below_the_probe_top_is_refused(api):
    api.calibrate("length_diameter")
    api.place(CUTTER_T, 30.0, 0.0, -5.0)                       # beside the probe, tip below its top
    failed = api.measure("tool.length", {}, status=409)["error"]["message"]
    assert "61332" in failed


# --- tool-probe data (API and screen) -----------------------------------------------------------

def test_tool_probe_screen_shows_and_validates(api):
    api.calibrate("length_diameter")
    page = api.c.get("/tool-probes")
    assert page.status_code == 200
    assert f"T{CAL_T}" in page.text and "calibrated" in page.text
    record = ok(api.c.get("/api/tool-probes/1"))
    assert f"{record['trigger']['Z-']:.4f}" in page.text
    form = {f"trigger.{k}": str(v) for k, v in record["trigger"].items()}
    form.update({"disc_diameter": "20", "dz": "2", "type": "101", "axes": "134"})
    bad = api.c.post("/tool-probes/1", data=form)
    assert "Not saved" in bad.text and "each digit" in bad.text
    form.update({"axes": "133", "trigger.X-": "600"})              # below X+: faces swapped
    bad = api.c.post("/tool-probes/1", data=form)
    assert "must be greater than X+" in bad.text
    assert ok(api.c.get("/api/tool-probes/1"))["trigger"] == record["trigger"]   # nothing lost
    form["trigger.X-"] = str(record["trigger"]["X-"])
    form["dz"] = "3"
    good = api.c.post("/tool-probes/1", data=form)
    assert "saved" in good.text
    assert ok(api.c.get("/api/tool-probes/1"))["dz"] == 3.0 and \
        ok(api.c.get("/api/tool-probes/1"))["type"] == 101
    assert ok(api.c.put("/api/tool-probes/1", json={"trigger": {"Q+": 1}}), 422)["error"]["field"]


def test_zero_latency_machine_needs_no_correction(client):
    ok(client.post("/api/sim/scenario", json={**scenario(latency_s=0.0), "reset_data": True}))
    api = Api(client)
    api.calibrate("length_diameter")
    result = api.diameter(WIDE_T)["result"]
    assert abs(result["latch"]["correction"]) < 1e-9
    assert abs(api.tool(WIDE_T)["radius"] - TRUE[WIDE_T]["radius"]) <= TOL

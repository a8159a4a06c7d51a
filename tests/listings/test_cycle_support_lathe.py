"""Cycle support of the program editor on a lathe (issue 28 item 6, design.md §10.2, manual
§7.2–7.3): the lathe offers CYCLE982, CYCLE973, CYCLE974 and CYCLE994 with the parameters the
NC's lathe cycles read (app/nc/cycles/lathe.py, manual ch. 6); the milling machine does not offer
them, and the lathe does not offer the milling cycles. The round trip is exact, reading the
manual's listing gives the values as printed, and the text a form writes runs on the simulated
lathe and measures its truth (app/machine/lathe_demo_scenario.json)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from manual_listings import KALIBRIEREN_IN_NUT_20537, ZWEI_PUNKT_MESSUNG_22051

SCENARIO = json.loads((Path(__file__).resolve().parents[2] / "app" / "machine" / "lathe_demo_scenario.json")
                      .read_text(encoding="utf-8"))
SCENARIO["machine"]["time_scale"] = 0
PROBE = SCENARIO["probe"]
R_TRUE = PROBE["ball_diameter"] / 2.0                         # the ball's true radius
DL1 = PROBE["nominal"]["l1"] - PROBE["l1"]                    # the NC's ball centre lies DL1 below the true one

# the parameters each lathe cycle reads (manual ch. 6 parameter tables; app/nc/cycles/lathe.py)
_AUX = {"_PRNUM", "_VMS", "_NMSP", "_FA", "_TSA", "_TZL"}
_BANDS = {"_TUL", "_TLL", "_TMV", "_TDIF", "_K", "_EVNUM", "_KNUM", "_TNUM", "_CHBIT[4]", "_CHBIT[6]"}
READ = {
    "CYCLE982": {"_MVAR", "_MA", "_MD", "_STA1", "_CORA", "_CHBIT[3]", "_TDIF", "_EVNUM"} | _AUX,
    "CYCLE973": {"_MVAR", "_MA", "_MD", "_SETVAL", "_CALNUM"} | _AUX,
    "CYCLE974": {"_MVAR", "_SETVAL", "_MA", "_STA1"} | _AUX | _BANDS,
    "CYCLE994": {"_MVAR", "_SETVAL", "_MA", "_SZA", "_SZO", "_CHBIT[7]"} | _AUX | _BANDS,
}
# a variant of each cycle other than its default (turning.md §3.1, §4.1; manual §6.5, §6.6)
NOT_DEFAULT_VARIANT = {"CYCLE982": 1, "CYCLE973": 12113, "CYCLE974": 1000, "CYCLE994": 2}
MILLING = {"CYCLE976", "CYCLE977", "CYCLE978", "CYCLE979", "CYCLE998", "CYCLE961", "CYCLE997", "CYCLE971"}


def ok(response, status: int = 200):
    assert response.status_code == status, response.text
    return response.json()


@pytest.fixture
def lathe(client):
    ok(client.post("/api/sim/scenario", json={**SCENARIO, "reset_data": True}))
    assert ok(client.get("/api/machine"))["kind"] == "lathe"
    return client


def _values(form: dict) -> dict:
    """Values that are not the defaults, inside each field's range, with a fraction on the reals."""
    params = {}
    for k, field in enumerate(form["fields"]):
        if field["kind"] == "int":
            params[field["name"]] = int(min(field["max"], field["min"] + (k + 1) % 3))
        else:
            params[field["name"]] = min(field["max"], field["min"] + 0.1 * (k + 1) + 1e-7 * k)
    return params


def test_the_lathe_offers_its_four_cycles_with_the_parameters_they_read(lathe):
    cycles = {c["cycle"]: c for c in ok(lathe.get("/api/cycles"))["cycles"]}
    assert set(cycles) == set(READ)
    for name, form in cycles.items():
        names = [f["name"] for f in form["fields"]]
        assert len(names) == len(set(names)), name
        assert set(names) == READ[name], name
        assert all(f["text"] and f["text"] != f["name"] for f in form["fields"])


@pytest.mark.parametrize("cycle", sorted(READ))
def test_each_lathe_form_round_trips_exactly(lathe, cycle):
    form = next(c for c in ok(lathe.get("/api/cycles"))["cycles"] if c["cycle"] == cycle)
    params = {**_values(form), "_MVAR": NOT_DEFAULT_VARIANT[cycle]}
    text = ok(lathe.post("/api/cycles/render", json={"cycle": cycle, "params": params}))["text"]
    assert text.splitlines()[-1] == cycle
    back = ok(lathe.post("/api/cycles/read", json={"text": text}))
    assert back == {"cycle": cycle, "params": params}
    assert all(type(back["params"][k]) is type(v) for k, v in params.items())


def test_the_milling_machine_does_not_offer_the_lathe_cycles(client):
    offered = {c["cycle"] for c in ok(client.get("/api/cycles"))["cycles"]}
    assert offered == MILLING
    refused = ok(client.post("/api/cycles/render", json={"cycle": "CYCLE973", "params": {"_MVAR": 13}}), 422)
    assert refused["error"]["field"] == "cycle" and "lathe cycle" in refused["error"]["message"]
    text = ok(client.post("/api/cycles/read", json={"text": KALIBRIEREN_IN_NUT_20537.text}), 422)
    assert text["error"]["field"] == "text"


def test_the_lathe_does_not_offer_the_milling_cycles(lathe):
    refused = ok(lathe.post("/api/cycles/render", json={"cycle": "CYCLE977", "params": {"_MVAR": 101}}), 422)
    assert refused["error"]["field"] == "cycle" and "milling cycle" in refused["error"]["message"]


def test_reading_the_manuals_lathe_listings_gives_the_printed_values(lathe):
    """§6.4.2 %_N_KALIBRIEREN_IN_NUT_MPF (lines 20537–20555): the last call N60 with N30/N31/N50 as
    printed; §6.6 %_N_ZWEI_PUNKT_MESSUNG_MPF (lines 22051–22080): the second call N90."""
    back = ok(lathe.post("/api/cycles/read", json={"text": KALIBRIEREN_IN_NUT_20537.text}))
    assert back == {"cycle": "CYCLE973", "params": {"_TZL": 0.0, "_TSA": 1.0, "_VMS": 0.0, "_NMSP": 1, "_FA": 3.0,
                                                    "_PRNUM": 1, "_MVAR": 2013, "_MA": 2, "_MD": 1, "_CALNUM": 1}}
    two = ok(lathe.post("/api/cycles/read", json={"text": ZWEI_PUNKT_MESSUNG_22051.text}))
    printed = {"_CHBIT[4]": 1, "_CHBIT[7]": 0, "_TLL": -0.01, "_MA": 2, "_SZA": 55.0, "_SZO": 55.0, "_KNUM": 1,
               "_K": 3, "_TZL": 0.002, "_TMV": 0.005, "_TDIF": 0.04, "_TSA": 0.5, "_VMS": 0.0, "_NMSP": 1,
               "_FA": 1.0, "_MVAR": 2, "_SETVAL": 35.0, "_TUL": 0.015, "_TNUM": 9, "_EVNUM": 4}
    assert two == {"cycle": "CYCLE994", "params": printed}


@pytest.mark.parametrize("cycle, params, field", [
    ("CYCLE994", {"_MVAR": 3}, "params._MVAR"),
    ("CYCLE982", {"_MA": 3}, "params._MA"),
    ("CYCLE973", {"_CALNUM": 0}, "params._CALNUM"),
    ("CYCLE974", {"_CHBIT[6]": 2}, "params._CHBIT[6]"),
    ("CYCLE994", {"_SETVAL": "45"}, "params._SETVAL"),
    ("CYCLE973", {"_MD": 0.5}, "params._MD"),
    ("CYCLE974", {"_SZA": 55}, "params._SZA"),
])
def test_a_bad_value_is_refused_naming_the_field(lathe, cycle, params, field):
    error = ok(lathe.post("/api/cycles/render", json={"cycle": cycle, "params": params}), 422)["error"]
    assert error["field"] == field and field.removeprefix("params.") in error["message"]


def test_the_written_calibration_measures_the_truth(lathe):
    """The §6.4.2 listing's two calls read into the form and written back by it, run in place of the
    printed N30–N60 (positions adapted as in test_listings_lathe): _WP holds the groove's truth
    and the record is valid."""
    r = PROBE["nominal"]["ball_diameter"] / 2.0          # the operator's rough record before the first calibration
    ok(lathe.put("/api/probes/1", json={"tool": PROBE["t"], "ball_diameter": 2 * r,
                                        "trigger": {"X-": r, "X+": -r, "Z-": r}}))
    printed = KALIBRIEREN_IN_NUT_20537.text
    first = ok(lathe.post("/api/cycles/read", json={"text": printed[:printed.index("N50")]}))
    second = ok(lathe.post("/api/cycles/read", json={"text": printed}))
    calls = [ok(lathe.post("/api/cycles/render", json=c))["text"] for c in (first, second)]
    program = "\n".join(["T8 D1", "G0 SUPA G90 DIAMOF Z40 X80", calls[0], calls[1], "G0 SUPA Z140", "SUPA X100",
                         "M2"])
    answer = ok(lathe.post("/api/nc/run", json={"mda": program}))
    assert answer["state"] == "done" and answer["reason"] == "M2", answer
    record = ok(lathe.get("/api/probes/1"))
    assert record["trigger"]["Z-"] == pytest.approx(R_TRUE, abs=1e-6)
    assert record["trigger"]["X-"] == pytest.approx(R_TRUE - DL1, abs=1e-6)
    assert record["trigger"]["X+"] == pytest.approx(-R_TRUE - DL1, abs=1e-6)
    assert record["valid"] is True


# the _MVAR values of turning.md §3.1 (CYCLE982, digits units first), §4.1 (CYCLE973), manual §6.5 (CYCLE974)
VARIANTS = {
    "CYCLE982": [0, 10, 100000, 100010,                        # calibrate (_TP / _TPW, incremental)
                 1, 11, 101, 1001, 2001, 10001, 100001, 101001,  # measure: turning tool, mill digits, incremental
                 2, 12, 102],                                   # automatic
    "CYCLE973": [0, 13, 1013, 2013, 2113, 12013, 12113],
    "CYCLE974": [0, 100, 1000],
}
NOT_VARIANTS = {
    "CYCLE982": [3, 20, 100, 1010, 3001, 5001, 20001, 100002, 102001, 112001, 200001],
    "CYCLE973": [1, 14, 113, 3013, 2213, 20013, 99999],
    "CYCLE974": [1, 10, 101, 110, 999],
}


@pytest.mark.parametrize("cycle, mvar", [(c, v) for c, values in VARIANTS.items() for v in values])
def test_the_lathe_forms_write_every_variant_of_the_manual(lathe, cycle, mvar):
    text = ok(lathe.post("/api/cycles/render", json={"cycle": cycle, "params": {"_MVAR": mvar}}))["text"]
    assert text == f"_MVAR={mvar}\n{cycle}"


@pytest.mark.parametrize("cycle, mvar", [(c, v) for c, values in NOT_VARIANTS.items() for v in values])
def test_an_mvar_the_cycle_does_not_have_is_refused_naming_the_field_and_its_digits(lathe, cycle, mvar):
    error = ok(lathe.post("/api/cycles/render", json={"cycle": cycle, "params": {"_MVAR": mvar, "_FA": 2.0}}),
               422)["error"]
    assert error["field"] == "params._MVAR"
    assert error["message"].startswith(f"_MVAR={mvar} is not a {cycle} variant: ")
    assert "turning.md" not in error["message"]              # the operator's words, no spec reference


@pytest.mark.parametrize("mvar", [11013, 1113, 10113, 11113])
def test_one_direction_with_ball_diameter_or_position_deviation_says_why(lathe, mvar):
    """turning.md §4.1 [L20293]: in one direction neither can be determined."""
    error = ok(lathe.post("/api/cycles/render", json={"cycle": "CYCLE973", "params": {"_MVAR": mvar}}), 422)["error"]
    assert error["field"] == "params._MVAR" and "both directions" in error["message"]

"""Cycle support of the program editor (design.md §10.2): GET /api/cycles, POST /api/cycles/render
and /api/cycles/read. The round trip is exact; reading the manual's listing gives the values as
printed; the text a form writes runs on the simulator and measures the truth."""

from __future__ import annotations

import pytest
from listing_kit import Machine
from manual_listings import KALIBRIEREN_IN_X_Y, KALIBRIEREN_IN_Z, NV_RECHTECK_11315


def ok(response, status: int = 200):
    assert response.status_code == status, response.text
    return response.json()


def test_every_form_round_trips_exactly(client):
    cycles = ok(client.get("/api/cycles"))["cycles"]
    assert {c["cycle"] for c in cycles} >= {"CYCLE976", "CYCLE977", "CYCLE978", "CYCLE979", "CYCLE998",
                                            "CYCLE961", "CYCLE997", "CYCLE971"}
    for form in cycles:
        params = {}
        for k, field in enumerate(form["fields"]):     # values that are not the defaults, in range
            if field["kind"] == "int":
                params[field["name"]] = int(min(field["max"], field["min"] + k % 3))
            else:
                params[field["name"]] = min(field["max"], field["min"] + 0.1 * (k + 1) + 1e-7 * k)
        text = ok(client.post("/api/cycles/render", json={"cycle": form["cycle"], "params": params}))["text"]
        assert text.splitlines()[-1] == form["cycle"]
        back = ok(client.post("/api/cycles/read", json={"text": text}))
        assert back == {"cycle": form["cycle"], "params": params}
        assert all(type(back["params"][k]) is type(v) for k, v in params.items())


def test_reading_the_manuals_listing_gives_the_printed_values(client):
    """§5.3.3 %_N_KALIBRIEREN_IN_Z_MPF: N60/N61 as printed (lines 9517–9535)."""
    back = ok(client.post("/api/cycles/read", json={"text": KALIBRIEREN_IN_Z.text}))
    assert back == {"cycle": "CYCLE976", "params": {"_TSA": 4.0, "_PRNUM": 1, "_VMS": 0.0, "_NMSP": 1, "_FA": 2.0,
                                                    "_MVAR": 0, "_SETVAL": 20.0, "_MA": 3, "_MD": 1, "_TZL": 0.0}}
    ring = ok(client.post("/api/cycles/read", json={"text": KALIBRIEREN_IN_X_Y.text}))
    assert ring["params"]["_MVAR"] == 10101 and ring["params"]["_SETVAL"] == 110.246 and ring["params"]["_PRNUM"] == 3
    rect = ok(client.post("/api/cycles/read", json={"text": NV_RECHTECK_11315.text.replace("循环", "CYCLE")}))
    assert rect["cycle"] == "CYCLE977"
    printed = {"_MVAR": 106, "_SETV[0]": 100.0, "_SETV[1]": 200.0, "_ID": -30.0, "_KNUM": 1, "_TSA": 1.8, "_FA": 6.0}
    assert {k: rect["params"][k] for k in printed} == printed


def test_the_written_cycle_measures_the_truth(client):
    """The form's text in place of the listing's N60–N70 measures the same trigger value."""
    m = Machine(client)
    params = ok(client.post("/api/cycles/read", json={"text": KALIBRIEREN_IN_Z.text}))["params"]
    text = ok(client.post("/api/cycles/render", json={"cycle": "CYCLE976", "params": params}))["text"]
    answer = m.mda("G54 G90 G17 T9 D1\nM6\nG0 X100 Y80\nZ55\n" + text + "\nZ55\nM2")
    assert answer["state"] == "done", answer
    assert m.probe(1)["trigger"] == {"Z-": pytest.approx(2.0 - 0.2, abs=1e-9)}     # r − (L1 typed − true)


@pytest.mark.parametrize("body, field", [
    ({"cycle": "CYCLE999", "params": {}}, "cycle"),
    ({"cycle": "CYCLE977", "params": {"_NOPE": 1}}, "params._NOPE"),
    ({"cycle": "CYCLE977", "params": {"_MVAR": 1.5}}, "params._MVAR"),
    ({"cycle": "CYCLE977", "params": {"_MVAR": True}}, "params._MVAR"),
    ({"cycle": "CYCLE977", "params": {"_PRNUM": 7}}, "params._PRNUM"),
])
def test_bad_forms_are_refused_naming_the_field(client, body, field):
    assert ok(client.post("/api/cycles/render", json=body), 422)["error"]["field"] == field


@pytest.mark.parametrize("text", ["G0 X10\nM2", "N10 X=", "_MVAR=1\nCYCLE800"])
def test_texts_without_a_readable_call_are_refused(client, text):
    assert ok(client.post("/api/cycles/read", json={"text": text}), 422)["error"]["field"] == "text"

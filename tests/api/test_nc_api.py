"""The NC API of design.md §9.4: programs, runs, the channel's state, variables, bad inputs.

The test scenario (tests/hmi_testdata.py): ideal probe T9 (L 100, Ø4) in the spindle, block top at
MCS Z −120, a Ø20 hole at part (40, 30) = MCS (290, 180)."""

from __future__ import annotations

import threading

import pytest
from waiting import wait_until

HOLE = (290.0, 180.0)
BORE = """N10 G500 G17 G90 G0 Z-100
N20 X291 Y179.5
N30 Z-128
N40 _MVAR=1 _SETVAL=20 _KNUM=0 _FA=2
N50 CYCLE977
N60 R1=_OVR[4] R2=_OVR[5]
N70 G0 Z-100
N80 M30
"""


def ok(response, status=200):
    assert response.status_code == status, response.text
    return response.json()


def mcs(client):
    m = ok(client.get("/api/machine"))["mcs"]
    return m["X"], m["Y"], m["Z"]


# --- programs ------------------------------------------------------------------------------------------

def test_program_crud(client):
    assert ok(client.get("/api/programs")) == []
    created = ok(client.post("/api/programs", json={"name": "BORE1", "text": BORE}), 201)
    assert created["name"] == "BORE1" and created["text"] == BORE and created["syntax"] is None
    listed = ok(client.get("/api/programs"))
    assert [(p["name"], p["lines"]) for p in listed] == [("BORE1", 8)]
    assert ok(client.post("/api/programs", json={"name": "BORE1", "text": "M30"}), 409)["error"]["code"] == "exists"
    changed = ok(client.put("/api/programs/BORE1", json={"text": "G0 X\nM30"}))
    assert changed["syntax"]["line"] == 1 and changed["syntax"]["column"] == 4        # stored, flagged
    assert ok(client.put("/api/programs/NEW", json={"text": "M30"}), 201)["name"] == "NEW"
    assert ok(client.get("/api/programs/BORE1"))["text"] == "G0 X\nM30"
    assert client.delete("/api/programs/BORE1").status_code == 204
    assert ok(client.get("/api/programs/BORE1"), 404)["error"]["code"] == "unknown_program"
    assert ok(client.delete("/api/programs/BORE1"), 404)


@pytest.mark.parametrize("body, field", [
    ({"name": "9X", "text": "M30"}, "name"),
    ({"name": "A B", "text": "M30"}, "name"),
    ({"name": "X" * 33, "text": "M30"}, "name"),
    ({"name": "OK", "text": 5}, "text"),
    ({"name": "OK"}, "text"),
    ({"name": "OK", "text": "M30", "extra": 1}, "extra"),
])
def test_bad_programs_are_refused(client, body, field):
    error = ok(client.post("/api/programs", json=body), 422)["error"]
    assert error["field"] == field
    assert ok(client.get("/api/programs")) == []


def test_a_stored_program_runs_and_is_logged_with_its_name(client):
    ok(client.post("/api/programs", json={"name": "BORE1", "text": BORE}), 201)
    answer = ok(client.post("/api/nc/run", json={"program": "BORE1"}))
    assert answer["state"] == "done" and answer["block"]["number"] == 80 and answer["alarm"] is None
    v = ok(client.get("/api/nc/variables", params={"names": "_OVR[4],R1,R2,_OVI[2]"}))
    assert v["_OVR[4]"] == pytest.approx(20.0, abs=1e-9) and v["R1"] == v["_OVR[4]"]
    assert v["R2"] == pytest.approx(HOLE[0], abs=1e-9) and v["_OVI[2]"] == 977
    entry = ok(client.get("/api/log"))[0]
    assert (entry["program"], entry["block"], entry["task"]) == ("BORE1", "L5: N50 CYCLE977", "hole.1")
    state = ok(client.get("/api/nc"))
    assert state["program"] == "BORE1" and state["state"] == "done" and state["mode"] == "JOG"


def test_unknown_program_is_404(client):
    assert ok(client.post("/api/nc/run", json={"program": "NONE"}), 404)["error"]["code"] == "unknown_program"


# --- runs ------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("text, line, column", [
    ("N10 G0 X10\nN20 G1 X Y2", 2, 8),
    ("G0 X10\nCYCLE999", 2, 1),
    ("R1=(2+", 1, 7),
    ("G0 Q5", 1, 4),
    ("_NOPE=1", 1, 1),
])
def test_a_syntax_error_names_line_and_column_and_nothing_moves(client, text, line, column):
    before = mcs(client)
    error = ok(client.post("/api/nc/run", json={"mda": text}), 422)["error"]
    assert error["code"] == "nc_syntax" and error["field"] == "mda"
    assert (error["line"], error["column"]) == (line, column), error
    assert f"line {line}, column {column}" in error["message"]
    assert mcs(client) == before


@pytest.mark.parametrize("body", [{}, {"mda": "M30", "program": "X"}, {"mda": 5}, {"mda": "M30", "wait": 1},
                                  {"mda": "M30", "single_block": "yes"}, {"mda": "M30", "speed": 1}])
def test_bad_run_bodies(client, body):
    assert client.post("/api/nc/run", json=body).status_code == 422


def test_an_alarm_stops_at_its_block(client):
    answer = ok(client.post("/api/nc/run", json={"mda": "N10 G500 G0 Z-100\nN20 X291 Y180\nN30 G1 F500 Z-150\n"
                                                          "N40 X0"}))
    assert answer["state"] == "alarm" and answer["block"]["number"] == 30
    assert answer["alarm"]["code"] == 61302 and answer["alarm"]["line"] == 3     # probe collision: below the hole's bottom
    assert ok(client.get("/api/nc"))["mode"] == "MDA"
    assert ok(client.post("/api/nc/start", json={}), 409)["error"]["code"] == "alarm"
    ok(client.post("/api/nc/reset"))
    state = ok(client.get("/api/nc"))
    assert state["mode"] == "JOG" and state["state"] == "idle"
    assert ok(client.get("/api/machine"))["alarms"] == []


def test_single_block_and_nc_start(client):
    answer = ok(client.post("/api/nc/run", json={"mda": "N10 G500 G0 Z-100\nN20 X300\nN30 Y200\nN40 M30",
                                                 "single_block": True}))
    assert (answer["state"], answer["reason"], answer["block"]["number"]) == ("stopped", "single_block", 10)
    assert ok(client.get("/api/machine"))["mode"] == "MDA"
    assert ok(client.get("/api/nc"))["block"]["number"] == 20                  # the block that runs next
    assert ok(client.post("/api/nc/start", json={}))["block"]["number"] == 20
    assert mcs(client)[0] == pytest.approx(300.0)
    answer = ok(client.post("/api/nc/start", json={"single_block": False}))
    assert answer["state"] == "done" and mcs(client)[1] == pytest.approx(200.0)
    assert ok(client.get("/api/machine"))["mode"] == "JOG"
    # NC Start after the end runs it again from the start
    assert ok(client.post("/api/nc/start", json={}))["state"] == "done"


def test_run_without_waiting_and_stop(client):
    # a long program: NC Stop ends it at a block boundary, NC Start continues it
    text = "N10 G500 G0 Z-100\n" + "".join(f"N{20 + i} X{200 + (i % 2) * 50} Y100\n" for i in range(400)) + "N9999 M30"
    answer = ok(client.post("/api/nc/run", json={"mda": text, "wait": False}), 202)
    assert answer["state"] in ("running", "stopped", "done")
    stopped = ok(client.post("/api/nc/stop"))
    assert stopped["state"] in ("running", "stopped", "done")
    services = client.app.state.services
    result = services.nc.wait(10)
    assert result["state"] in ("stopped", "done")
    if result["state"] == "stopped":
        assert result["reason"] == "stop_request"
        assert ok(client.post("/api/nc/start", json={}))["state"] == "done"


def test_a_run_while_running_is_409(client):
    services = client.app.state.services
    gate = threading.Event()
    original = services.nc.runtime.move

    def slow(target, feed):
        gate.wait(5)
        original(target, feed)

    services.nc.runtime.move = slow
    try:
        ok(client.post("/api/nc/run", json={"mda": "G500 G0 Z-100", "wait": False}), 202)
        wait_until(lambda: ok(client.get("/api/nc"))["state"] == "running", "the program runs")
        assert ok(client.post("/api/nc/run", json={"mda": "M30"}), 409)["error"]["code"] == "busy"
        assert ok(client.put("/api/nc/variables/R1", json={"value": 1}), 409)
        assert ok(client.get("/api/nc"))["state"] == "running"
        assert ok(client.get("/api/machine"))["mode"] == "MDA"
    finally:
        gate.set()
        services.nc.wait(5)
        services.nc.runtime.move = original


# --- variables -------------------------------------------------------------------------------------------

def test_variables_read_and_write(client):
    assert ok(client.put("/api/nc/variables/R1", json={"value": 2.5})) == {"R1": 2.5}
    assert ok(client.put("/api/nc/variables/_EV[9]", json={"value": 0.004})) == {"_EV[9]": 0.004}
    assert ok(client.get("/api/memories/ev/10"))["value"] == 0.004                # _EV[9] is memory 10
    v = ok(client.get("/api/nc/variables", params={"names": "R1,_OVR,$AA_MM,_WP[0,1],_KNUM"}))
    assert v["R1"] == 2.5 and len(v["_OVR"]) == 32 and set(v["$AA_MM"]) >= {"X", "Y", "Z"}
    assert v["_WP[0,1]"] == 3.0 and v["_KNUM"] == 0
    ok(client.post("/api/nc/run", json={"mda": "R2=R1*2 _TUL=0.05"}))
    assert ok(client.get("/api/nc/variables", params={"names": "R2,_TUL"})) == {"R2": 5.0, "_TUL": 0.05}


@pytest.mark.parametrize("name, body, status", [
    ("NOPE", {"value": 1}, 404), ("R1", {"value": True}, 422), ("R1", {"value": [1]}, 422),
    ("R[500]", {"value": 1}, 422), ("$AA_MM[X]", {"value": 1}, 422), ("_OVR", {"value": 1}, 422),
    ("_TNAME", {"value": 5}, 422), ("R1", {}, 422),
])
def test_bad_variable_writes(client, name, body, status):
    assert client.put(f"/api/nc/variables/{name}", json=body).status_code == status


def test_unknown_variable_read_is_404(client):
    assert ok(client.get("/api/nc/variables", params={"names": "R1,NOPE"}), 404)["error"]["field"] == "names"


def test_cycle_errors_are_alarms_at_the_call(client):
    answer = ok(client.post("/api/nc/run", json={"mda": "N10 _MVAR=7\nN20 CYCLE977"}))
    assert answer["state"] == "alarm" and answer["alarm"]["code"] == 61307
    assert (answer["alarm"]["line"], answer["alarm"]["column"]) == (2, 5)
    assert ok(client.get("/api/nc/variables", params={"names": "_OVI[9]"}))["_OVI[9]"] == 61307
    ok(client.post("/api/nc/reset"))
    answer = ok(client.post("/api/nc/run", json={"mda": "_MVAR=101 _KNUM=77 _SETVAL=20\nCYCLE977"}))
    assert answer["alarm"]["code"] == 61321                     # G577 is not configured
    ok(client.post("/api/nc/reset"))
    answer = ok(client.post("/api/nc/run", json={"mda": "_MVAR=1 _KNUM=2001 _TNUM=0 _SETVAL=20\nCYCLE977"}))
    assert answer["alarm"]["code"] == 61320


def test_select_for_automatic_and_nc_start(client):
    ok(client.post("/api/programs", json={"name": "BORE1", "text": BORE}), 201)
    state = ok(client.post("/api/nc/select", json={"program": "BORE1"}))
    assert (state["mode"], state["program"], state["state"]) == ("AUTO", "BORE1", "ready")
    assert ok(client.get("/api/machine"))["mode"] == "AUTO"
    assert ok(client.put("/api/programs/BORE1", json={"text": "M30"}))          # ready, not running: allowed
    ok(client.post("/api/nc/select", json={"program": "BORE1"}))
    assert ok(client.post("/api/nc/start", json={}))["state"] == "done"
    assert ok(client.post("/api/nc/select", json={"program": "NONE"}), 404)
    assert client.post("/api/nc/select", json={}).status_code == 422
    ok(client.post("/api/programs", json={"name": "BAD", "text": "G0 X"}), 201)
    error = ok(client.post("/api/nc/select", json={"program": "BAD"}), 422)["error"]
    assert (error["line"], error["column"]) == (1, 4)

"""One channel (issue 24 items 3-4): one Reset ends whatever runs (program, cycle, JOG
measurement); NC Stop holds the axes and NC Start lets them go on; the mode group refuses JOG
motion, a JOG measurement, a tool change and a scenario load while a program runs, and a program
while a JOG measurement runs (409 ``mode`` naming what runs). Every refusal leaves the position
and the stored data as they were.

The test scenario (tests/hmi_testdata.py): probe T9 in the spindle at MCS (100, 100, 0), block
top at MCS Z −120, a Ø20 hole at MCS (290, 180)."""

from __future__ import annotations

import threading

import pytest
from hmi_testdata import test_scenario
from waiting import wait_until


def ok(response, status=200):
    assert response.status_code == status, response.text
    return response.json()


def machine(client) -> dict:
    return ok(client.get("/api/machine"))


def real_time(client) -> None:
    scenario = test_scenario()
    scenario["machine"]["time_scale"] = 1.0
    ok(client.post("/api/sim/scenario", json=scenario))


def refused_by_mode(response, program: str) -> dict:
    assert response.status_code == 409, response.text
    error = response.json()["error"]
    assert error["code"] == "mode" and error["program"] == program, error
    assert program in error["message"] or "MDA" in error["message"]
    return error


# --- one Reset --------------------------------------------------------------------------------------

# X100 -> X600 at 300 mm/min: 100 s unless something ends it
LONG = "N10 G91 G1 F300 X500\nN20 M30"


@pytest.mark.parametrize("reset", ["/api/machine/reset", "/api/nc/reset"])
def test_every_reset_ends_a_running_program(client, reset):
    real_time(client)
    ok(client.post("/api/nc/run", json={"mda": LONG, "wait": False}), 202)
    wait_until(lambda: machine(client)["mcs"]["X"] > 100.2, "the program moves X")
    ok(client.post(reset))
    nc = client.app.state.services.nc
    assert not nc.running                                   # the program's thread has ended
    state = ok(client.get("/api/nc"))
    assert (state["state"], state["mode"], state["program"]) == ("idle", "JOG", None)
    assert state["modal"]["distance"] == "G90"              # the program's G91 reset to the default
    m = machine(client)
    assert m["busy"] is False and m["alarms"] == [] and m["mode"] == "JOG"
    stopped_at = m["mcs"]["X"]
    assert 100.0 < stopped_at < 600.0
    assert machine(client)["mcs"]["X"] == stopped_at         # nothing runs that could move it on


def test_reset_ends_a_measuring_cycle_between_its_moves(client):
    real_time(client)
    bore = ("N10 G500 G17 G90 G0 Z-100\nN20 X291 Y179.5\nN30 Z-128\nN40 _MVAR=1 _SETVAL=20 _KNUM=0 _FA=2\n"
            "N50 CYCLE977\nN60 G0 Z-100\nN70 M30")
    ok(client.post("/api/nc/run", json={"mda": bore, "wait": False}), 202)
    wait_until(lambda: (ok(client.get("/api/nc"))["block"] or {}).get("number") == 50 and machine(client)["busy"],
               "the cycle probes")
    ok(client.post("/api/machine/reset"))
    assert not client.app.state.services.nc.running
    m = machine(client)
    assert m["busy"] is False and m["mode"] == "JOG"
    assert machine(client)["mcs"] == m["mcs"]
    assert ok(client.get("/api/log")) == [] or all(e["status"] != "ok" for e in ok(client.get("/api/log")))


def test_nc_stop_holds_the_axes_and_nc_start_goes_on(client):
    real_time(client)
    override = machine(client)["feed_override"]
    ok(client.post("/api/nc/run", json={"mda": "N10 G500 G90 G1 F6000 X300\nN20 G0 Y150\nN30 M30",
                                        "wait": False}), 202)
    wait_until(lambda: machine(client)["mcs"]["X"] > 100.2, "the program moves X")
    ok(client.post("/api/nc/stop"))
    state = ok(client.get("/api/nc"))
    assert (state["state"], state["reason"], state["mode"]) == ("stopped", "feed_hold", "MDA")
    held = machine(client)
    assert held["feed_hold"] is True and held["feed_override"] == 0.0
    assert held["mcs"]["X"] < 300.0
    refused_by_mode(client.post("/api/machine/jog", json={"axis": "Y", "distance": 1}), "MDA")
    answer = ok(client.post("/api/nc/start", json={}))
    assert answer["state"] == "done"
    m = machine(client)
    assert (m["mcs"]["X"], m["mcs"]["Y"]) == (pytest.approx(300.0), pytest.approx(150.0))
    assert m["feed_hold"] is False and m["feed_override"] == override


def test_nc_stop_between_blocks_and_nc_start_continue(client):
    """At time scale 0 the block is done before the hold: the program stops at the block's end."""
    text = "N10 G500 G0 Z-100\n" + "".join(f"N{20 + i} X{200 + (i % 2) * 50} Y100\n" for i in range(300)) + "N9999 M30"
    ok(client.post("/api/nc/run", json={"mda": text, "wait": False}), 202)
    ok(client.post("/api/nc/stop"))
    result = client.app.state.services.nc.wait(30)
    assert machine(client)["feed_hold"] is False              # JOG moves at its override again
    if result["state"] == "stopped":
        assert result["reason"] == "stop_request"
        assert ok(client.post("/api/nc/start", json={}))["state"] == "done"
    assert machine(client)["mcs"]["X"] == pytest.approx(250.0)   # the last X block (i = 299)


# --- the mode group ---------------------------------------------------------------------------------

@pytest.fixture
def held_program(client):
    """An MDA program held inside its first block (the runtime's move waits on a gate)."""
    nc = client.app.state.services.nc
    gate = threading.Event()
    original = nc.runtime.move

    def gated(target, feed):
        gate.wait(30)
        original(target, feed)

    nc.runtime.move = gated
    ok(client.post("/api/nc/run", json={"mda": "G500 G0 Z-100\nM30", "wait": False}), 202)
    wait_until(lambda: ok(client.get("/api/nc"))["state"] == "running", "the program runs")
    try:
        yield gate
    finally:
        gate.set()
        nc.wait(10)
        nc.runtime.move = original


REFUSED_WHILE_A_PROGRAM_RUNS = [
    ("post", "/api/machine/jog", {"axis": "X", "distance": 5}),
    ("post", "/api/machine/jog/continuous", {"axis": "X", "direction": 1}),
    ("post", "/api/machine/goto", {"X": 150}),
    ("post", "/api/machine/probe", {"direction": [0, 0, -1], "distance": 5, "feed": 300}),
    ("post", "/api/machine/tool", {"tool": 1}),
    ("post", "/api/sim/scenario", test_scenario()),
]


@pytest.mark.parametrize("method, path, body", REFUSED_WHILE_A_PROGRAM_RUNS)
def test_a_running_program_locks_motion_tool_and_scenario(client, held_program, method, path, body):
    before = machine(client)
    error = refused_by_mode(getattr(client, method)(path, json=body), "MDA")
    assert error["mode"] == "MDA"
    after = machine(client)
    assert (after["mcs"], after["tool"]) == (before["mcs"], before["tool"])
    assert ok(client.get("/api/nc"))["state"] == "running"


def test_a_running_program_locks_nc_start_of_a_jog_measurement(client, held_program):
    before = machine(client)["mcs"]
    session = ok(client.post("/api/measure", json={"task": "edge.set", "params": {"axis": "X", "direction": "+"}}))
    refused_by_mode(client.post(f"/api/measure/{session['id']}/start"), "MDA")
    assert machine(client)["mcs"] == before
    assert ok(client.get(f"/api/measure/{session['id']}"))["points"][0]["stored"] is False


def test_after_the_program_jog_works_again(client, held_program):
    held_program.set()
    client.app.state.services.nc.wait(10)
    assert ok(client.post("/api/machine/jog", json={"axis": "X", "distance": 5}))["mcs"]["X"] == pytest.approx(105.0)


def test_a_running_jog_measurement_locks_nc_run(client):
    real_time(client)
    ok(client.post("/api/machine/goto", json={"X": 290, "Y": 180, "Z": -100}))    # tip 20 mm above the hole
    session = ok(client.post("/api/measure", json={"task": "hole.1", "params": {}}))
    out: dict = {}
    thread = threading.Thread(target=lambda: out.update(r=client.post(f"/api/measure/{session['id']}/start")),
                              daemon=True)
    thread.start()
    wait_until(lambda: machine(client)["busy"], "the measurement moves")
    before_programs = ok(client.get("/api/programs"))
    error = refused_by_mode(client.post("/api/nc/run", json={"mda": "G91 G0 X10"}), "hole.1")
    assert error["mode"] == "JOG"
    assert ok(client.get("/api/nc"))["state"] == "idle" and ok(client.get("/api/programs")) == before_programs
    ok(client.post("/api/nc/reset"))                            # the one Reset ends the measurement too
    thread.join(10)
    assert not thread.is_alive() and out["r"].status_code == 409
    assert machine(client)["busy"] is False
    assert ok(client.get(f"/api/measure/{session['id']}"))["points"][0]["stored"] is False

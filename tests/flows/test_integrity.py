"""Trustworthy writes (design.md §9.1): no silently wrong offset under concurrent edits, faults or bad input.

Each case of issue [integrity] is repeated through the JSON API on a noise-free scenario and
checked against the scenario's pose (truthkit, own numpy), or, where the product must refuse,
against the stored state after the refusal (nothing written: offsets, log and audit unchanged).
"""

from __future__ import annotations

import threading
import time

import numpy as np
import pytest
from truthkit import Operator, frame_of, scenario
from waiting import wait_until

ROT_Z = 4.0
DEPTH = -10.0
CORNER_STARTS = [(20.0, -8.0, DEPTH), (70.0, -8.0, DEPTH), (-8.0, 20.0, DEPTH)]   # outside, position 1
CORNER = (0.0, 0.0, DEPTH)
TOL = 1e-6


@pytest.fixture
def op(client):
    operator = Operator(client, scenario(rot=(0.0, 0.0, ROT_Z)))
    operator.load()
    return operator


def corner_session(op: Operator, target: str = "G54") -> str:
    return op.create("corner.right", {"kind": "outside", "position": 1, "setpoint": {"X": 0.0, "Y": 0.0}},
                     target)["id"]


def measure_point(op: Operator, sid: str, n: int) -> None:
    op.ball_to(op.part.mcs(*CORNER_STARTS[n - 1]))
    answer = op.start(sid, point=n)
    assert answer["point"]["stored"], answer


def assert_corner_in(op: Operator, name: str = "G54") -> None:
    """The corner reads (0, 0) in ``name`` and its front edge is parallel to X: the true pose."""
    after = op.frame(name)
    corner = op.part.mcs(*CORNER)
    assert np.allclose(after.to_child(corner)[:2], [0.0, 0.0], atol=TOL), after.to_child(corner)
    edge = after.dir_to_child(op.part.dir_mcs([1.0, 0.0, 0.0]))
    assert abs(edge[1]) < TOL


def stored_state(op: Operator) -> dict:
    """Offsets, audit and the log of measurements (failed attempts are logged too: status "alarm ...")."""
    log = [e for e in op.ok(op.c.get("/api/log")) if not str(e["status"]).startswith("alarm")]
    return {"offsets": op.ok(op.c.get("/api/offsets")), "log": log, "audit": op.ok(op.c.get("/api/audit"))}


# --- the context of each point ---------------------------------------------------------------------

def test_offset_edited_between_the_points_and_calculate(op):
    op.put_offset("G54", trans=(0.0, 0.0, -7.0))
    op.activate("G500")
    sid = corner_session(op)
    for n in (1, 2, 3):
        measure_point(op, sid, n)
    op.ok(op.c.put("/api/offsets/G54", json={"trans": {"X": 210.0}}))
    op.calculate(sid)
    assert_corner_in(op)
    assert op.frame("G54").T[2] == pytest.approx(-7.0, abs=1e-12)      # Z: not determined, kept


def test_another_wo_activated_between_the_points(op):
    op.put_offset("G55", trans=(30.0, 40.0, 5.0))
    op.activate("G500")
    sid = corner_session(op)
    measure_point(op, sid, 1)
    op.activate("G55")
    measure_point(op, sid, 2)
    measure_point(op, sid, 3)
    op.calculate(sid)
    assert_corner_in(op)


def test_a_rotated_wo_between_the_points_is_refused_and_nothing_is_written(op):
    op.put_offset("G55", rot=(0.0, 0.0, 3.0), trans=(30.0, 40.0, 5.0))
    op.activate("G500")
    sid = corner_session(op)
    measure_point(op, sid, 1)
    op.activate("G55")
    measure_point(op, sid, 2)
    measure_point(op, sid, 3)
    before = stored_state(op)
    body = op.ok(op.c.post(f"/api/measure/{sid}/calculate"), 409)
    assert body["error"]["code"] == "context_changed" and "P2" in body["error"]["message"]
    assert stored_state(op) == before


def test_probe_record_edited_between_the_points_is_refused(op):
    op.activate("G500")
    sid = corner_session(op)
    measure_point(op, sid, 1)
    record = op.ok(op.c.get("/api/probes/1"))
    record["trigger"] = {"X-": 2.001, "X+": -2.001, "Y-": 2.001, "Y+": -2.001, "Z-": 2.0}
    op.ok(op.c.put("/api/probes/1", json=record))
    measure_point(op, sid, 2)
    measure_point(op, sid, 3)
    before = stored_state(op)
    body = op.ok(op.c.post(f"/api/measure/{sid}/calculate"), 409)
    assert body["error"]["code"] == "context_changed"
    assert stored_state(op) == before


def test_a_put_during_a_running_measurement_is_kept(op):
    """Set edge X runs at real time; G54 Y written meanwhile stays, X is the measured one.
    (The block is not turned here, so the left face is X = const in every WCS.)"""
    slow = scenario(rot=(0.0, 0.0, 0.0))
    slow["machine"]["time_scale"] = 1.0
    op.load(slow)
    op.ok(op.c.put("/api/settings", json={"measuring_feed": 3000.0, "position_feed": 5000.0}))
    op.put_offset("G54", trans=(0.0, 0.0, 0.0))
    op.activate("G54")
    op.ball_to(op.part.mcs(-12.0, 30.0, DEPTH))
    sid = op.create("edge.set", {"axis": "X", "direction": "+", "setpoint": 0.0}, "G54")["id"]
    op.ok(op.c.post(f"/api/measure/{sid}/start", json={"wait": False}), 202)
    running = op.ok(op.c.get(f"/api/measure/{sid}"))
    assert running["running"] is True and running["progress"]["point"] == 1
    op.ok(op.c.put("/api/offsets/G54", json={"trans": {"Y": 123.0}}))
    wait_until(lambda: not op.ok(op.c.get(f"/api/measure/{sid}"))["running"], "the measurement ends")
    session = op.ok(op.c.get(f"/api/measure/{sid}"))
    assert session["alarm"] is None and session["answer"]["correction"]["target"] == "G54"
    frame = frame_of(op.offset("G54"))
    assert frame.T[1] == pytest.approx(123.0, abs=1e-12)
    face = op.part.mcs(0.0, 30.0, DEPTH)                  # the left face at the touch height
    assert frame.to_child(face)[0] == pytest.approx(0.0, abs=TOL)


# --- limits -------------------------------------------------------------------------------------------

def test_huge_setpoint_is_refused_before_anything_moves(op):
    op.activate("G500")
    before = stored_state(op)
    body = op.ok(op.c.post("/api/measure", json={"task": "corner.right", "target": "G54", "params": {
        "kind": "outside", "position": 1, "setpoint": {"X": 1e300, "Y": 0.0}}}), 400)
    assert body["error"]["field"] == "setpoint.X"
    assert stored_state(op) == before


def test_a_correction_beyond_the_offset_limits_writes_nothing(op):
    op.activate("G500")
    op.ball_to(op.part.mcs(-12.0, 30.0, DEPTH))
    sid = op.create("edge.set", {"axis": "X", "direction": "+", "setpoint": -99_999.0}, "G54")["id"]
    before = stored_state(op)
    body = op.ok(op.c.post(f"/api/measure/{sid}/start", json={}), 422)
    assert body["error"]["code"] == "correction_out_of_range" and body["error"]["field"] == "trans.X"
    assert stored_state(op) == before


@pytest.mark.parametrize("change,field", [
    ({"trigger": {"X+": 1e308}}, "trigger"),
    ({"skew": [1e308, 0.0]}, "skew"),
    ({"trigger": {"X+": True}}, "trigger.X+"),
    ({"ball_diameter": 1e9}, "ball_diameter"),
])
def test_implausible_probe_data_is_refused(op, change, field):
    before = op.ok(op.c.get("/api/probes/1"))
    body = op.ok(op.c.put("/api/probes/1", json={**before, **change}), 422)
    assert body["error"]["field"].startswith(field), body
    assert op.ok(op.c.get("/api/probes/1")) == before


# --- strict numbers and sizes ---------------------------------------------------------------------------

@pytest.mark.parametrize("method,path,body", [
    ("post", "/api/machine/goto", {"Y": False}),
    ("post", "/api/machine/jog", {"axis": "X", "distance": True}),
    ("put", "/api/machine/override", {"feed": False}),
    ("post", "/api/machine/tool", {"tool": 9223372036854775808}),
    ("post", "/api/machine/tool", {"tool": True}),
    ("post", "/api/machine/probe", {"direction": [1, 0, False], "distance": 5, "feed": 100}),
])
def test_booleans_and_huge_integers_are_not_numbers(op, method, path, body):
    machine = op.ok(op.c.get("/api/machine"))
    response = getattr(op.c, method)(path, json=body)
    assert response.status_code == 422, response.text
    after = op.ok(op.c.get("/api/machine"))
    assert (after["mcs"], after["tool"], after["feed_override"]) == \
        (machine["mcs"], machine["tool"], machine["feed_override"])


def test_bodies_over_one_mebibyte_are_refused(op):
    before = op.offset("G54")
    payload = b'{"trans": {"X": 1.0}, "pad": "' + b"x" * (1024 * 1024) + b'"}'
    response = op.c.put("/api/offsets/G54", content=payload, headers={"content-type": "application/json"})
    assert response.status_code == 413
    assert response.json()["error"]["code"] == "body_too_large"
    assert op.offset("G54") == before


# --- Calculate runs once -------------------------------------------------------------------------------

def test_parallel_calculate_commits_once(op):
    op.activate("G500")
    for _ in range(10):
        sid = corner_session(op)
        for n in (1, 2, 3):
            measure_point(op, sid, n)
        logs = len(op.ok(op.c.get("/api/log")))
        audits = len(op.ok(op.c.get("/api/audit", params={"limit": 1000})))
        barrier = threading.Barrier(4)
        statuses: list[int] = []

        def calculate(session_id=sid, go=barrier, out=statuses):
            go.wait()
            out.append(op.c.post(f"/api/measure/{session_id}/calculate").status_code)

        threads = [threading.Thread(target=calculate) for _ in range(4)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        assert sorted(statuses) == [200, 409, 409, 409], statuses
        assert len(op.ok(op.c.get("/api/log"))) == logs + 1
        assert len(op.ok(op.c.get("/api/audit", params={"limit": 1000}))) == audits + 1
        assert_corner_in(op)


# --- hold-to-run ----------------------------------------------------------------------------------

def test_a_continuous_jog_stops_without_renewal(op):
    slow = scenario(rot=(0.0, 0.0, 0.0))
    slow["machine"]["time_scale"] = 1.0
    op.load(slow)
    start = op.ok(op.c.get("/api/machine"))["mcs"]["X"]
    op.ok(op.c.post("/api/machine/jog/continuous", json={"axis": "X", "direction": 1}))
    began = time.monotonic()
    for _ in range(6):                                   # renewed for ~1.2 s: keeps moving
        time.sleep(0.2)
        op.ok(op.c.post("/api/machine/jog/continuous", json={"axis": "X", "direction": 1}))
    assert op.ok(op.c.get("/api/machine"))["busy"] is True
    renewed = time.monotonic()
    while op.ok(op.c.get("/api/machine"))["busy"]:
        assert time.monotonic() - renewed < 1.0, "the axis kept moving without a renewal"
        time.sleep(0.02)
    assert time.monotonic() - renewed >= 0.4             # it ran out the 0.5 s of the last renewal
    moved = op.ok(op.c.get("/api/machine"))["mcs"]["X"] - start
    assert moved > 0.0 and time.monotonic() - began > 1.2
    time.sleep(0.3)
    assert op.ok(op.c.get("/api/machine"))["mcs"]["X"] - start == pytest.approx(moved, abs=1e-9)


# --- storage faults --------------------------------------------------------------------------------

def _storage_refuses_writes(app) -> None:
    """Every new connection of the app's database refuses writes (the driver's "readonly
    database" error, as a read-only file or a full disk give it)."""
    from sqlalchemy import event

    db = app.state.services.db

    def read_only(connection, _record):
        cursor = connection.cursor()
        cursor.execute("PRAGMA query_only=ON")
        cursor.close()

    event.listen(db.engine, "connect", read_only)
    db.engine.dispose()


def test_storage_that_cannot_be_written_is_503_and_the_machine_does_not_change(op, app):
    before = op.offset("G54")
    machine = op.ok(op.c.get("/api/machine"))
    _storage_refuses_writes(app)
    body = op.ok(op.c.put("/api/offsets/G54", json={"trans": {"X": 5.0}}), 503)
    assert body["error"]["code"] == "storage_unavailable" and "database" in body["error"]["message"]
    assert op.offset("G54") == before
    body = op.ok(op.c.post("/api/machine/tool", json={"tool": 1}), 503)
    assert body["error"]["code"] == "storage_unavailable"
    assert op.ok(op.c.get("/api/machine"))["tool"] == machine["tool"]     # the spindle did not change


def test_a_full_disk_is_503_with_the_drivers_words(op, app):
    from sqlalchemy import event

    db = app.state.services.db

    def full(connection, _record):
        cursor = connection.cursor()
        pages = cursor.execute("PRAGMA page_count").fetchone()[0]
        cursor.execute(f"PRAGMA max_page_count={pages}")
        cursor.close()

    before = op.offset("G54")
    event.listen(db.engine, "connect", full)
    db.engine.dispose()
    last = None                 # the file is full at once or after a few writes (page slack)
    for i in range(200):
        response = op.c.put("/api/offsets/G54", json={"trans": {"X": float(i)}, "rot": {"Z": 0.5}})
        if response.status_code != 200:
            break
        last = i
    assert response.status_code == 503 and "full" in response.json()["error"]["message"]
    expected = before["trans"]["X"] if last is None else float(last)
    assert op.offset("G54")["trans"]["X"] == expected        # the refused write changed nothing


@pytest.mark.parametrize("make", ["under_a_file", "not_a_database"])
def test_a_database_that_cannot_be_opened_stops_start_up_with_one_line(tmp_path, make):
    import subprocess
    import sys

    if make == "under_a_file":
        (tmp_path / "plain").write_text("x")
        path = tmp_path / "plain" / "hmi.db"
    else:
        path = tmp_path / "hmi.db"
        path.write_bytes(b"this is not an SQLite file" * 100)
    run = subprocess.run([sys.executable, "-m", "app", "--db", str(path), "--port", "1"], capture_output=True,
                         text=True, timeout=60)
    assert run.returncode == 1
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and str(path) in lines[0] and lines[0].startswith("python -m app: cannot open the database")


# --- scenario load and tool change --------------------------------------------------------------------

def test_a_rejected_scenario_changes_nothing(op):
    op.ok(op.c.put("/api/machine/override", json={"feed": 50.0}))
    op.ok(op.c.post("/api/machine/jog", json={"axis": "X", "distance": 3.0}))
    machine = op.ok(op.c.get("/api/machine"))
    scene = op.ok(op.c.get("/api/machine/scene"))
    bad = scenario(rot=(0.0, 0.0, 0.0))
    bad["seed"] = -1
    bad["workpiece"]["pose"]["trans"] = [1.0, 2.0, 3.0]
    body = op.ok(op.c.post("/api/sim/scenario", json=bad), 422)
    assert body["error"]["code"] in ("invalid_scenario", "validation")
    assert op.ok(op.c.get("/api/machine")) == machine
    assert op.ok(op.c.get("/api/machine/scene")) == scene


def test_a_scenario_load_while_moving_is_refused(op):
    slow = scenario(rot=(0.0, 0.0, 0.0))
    slow["machine"]["time_scale"] = 1.0
    op.load(slow)
    op.ok(op.c.post("/api/machine/jog/continuous", json={"axis": "X", "direction": 1}))
    body = op.ok(op.c.post("/api/sim/scenario", json=slow), 409)
    assert body["error"]["code"] == "busy"
    op.ok(op.c.post("/api/machine/stop"))


@pytest.mark.parametrize("change", ["tool", "scenario"])
def test_a_tool_change_or_scenario_load_discards_the_stored_points(op, change):
    op.activate("G500")
    sid = corner_session(op)
    measure_point(op, sid, 1)
    if change == "tool":
        op.ok(op.c.post("/api/machine/tool", json={"tool": 1}))
    else:
        op.ok(op.c.post("/api/sim/scenario", json=op.scen))
    session = op.ok(op.c.get(f"/api/measure/{sid}"))
    assert not any(p["stored"] for p in session["points"])
    assert "discarded" in session["notice"]


# --- the log pages and exports everything ----------------------------------------------------------

def test_the_log_pages_and_the_exports_hold_every_entry(op, app):
    import csv
    import io

    with app.state.services.db.unit() as unit:
        for i in range(1234):
            unit.add_log({"task": "edge.set", "target": "G54", "status": "ok", "result": {"position": float(i)}})
    page = op.ok(op.c.get("/api/log", params={"limit": 10, "offset": 1230}))
    assert [e["result"]["position"] for e in page] == [3.0, 2.0, 1.0, 0.0]
    newest = op.ok(op.c.get("/api/log", params={"limit": 1}))[0]
    assert newest["result"]["position"] == 1233.0
    rows = list(csv.reader(io.StringIO(op.c.get("/log/export.csv").text)))
    assert len(rows) == 1 + 1234
    exported = op.c.get("/log/export.json").json()
    assert len(exported) == 1234 and exported[-1]["result"]["position"] == 0.0
    screen = op.c.get("/log").text
    assert "1234 entries" in screen and "page 1 of 13" in screen
    assert "page 13 of 13" in op.c.get("/log", params={"page": 13}).text


# --- a frame the NC cannot hold (LinuxCNC: no rotation about X or Y) ---------------------------------

@pytest.fixture
def flat_nc(app, op):
    """The simulated NC refuses, as LinuxCNC does, any G54 rotated about X or Y."""
    from app.machine.protocol import Alarm
    from engine import alarms

    machine = app.state.services.machine.machine

    def holds(name, frame):
        rot = frame.get("rot", {})
        if abs(rot.get("X", 0.0)) > 0 or abs(rot.get("Y", 0.0)) > 0:
            return Alarm.of(alarms.ZO_NUMBER, f"{name} holds no rotation about X or Y")
        return None

    machine.holds = holds
    yield op
    del machine.holds


def test_an_offset_the_nc_cannot_hold_is_refused_before_it_is_stored(flat_nc):
    op = flat_nc
    before = stored_state(op)
    body = op.ok(op.c.put("/api/offsets/G54", json={"rot": {"X": 1.5}}), 409)
    assert body["error"]["code"] == "alarm" and body["error"]["message"].startswith("61321")
    assert stored_state(op) == before                       # database and NC unchanged
    op.ok(op.c.put("/api/offsets/G54", json={"rot": {"Z": 1.5}}))   # about Z it holds


def test_a_tilted_plane_measured_into_an_offset_the_nc_cannot_hold_writes_nothing(flat_nc, client):
    op = flat_nc
    op.load(scenario(rot=(1.0, -0.5, 4.0)))
    before = stored_state(op)
    sid = op.create("plane.align", {}, "G54")["id"]
    for x, y in [(30.0, 25.0), (170.0, 30.0), (100.0, 100.0)]:
        op.ball_to(op.part.mcs(x, y, 8.0))
        assert op.start(sid)["point"]["stored"]
    body = op.calculate(sid, status=409)
    assert body["error"]["message"].startswith("61321")
    after = stored_state(op)
    assert after["offsets"] == before["offsets"] and after["audit"] == before["audit"]
    assert any(a["code"] == 61321 for a in op.c.get("/api/machine").json()["alarms"])   # as the NC shows it

"""Robustness of the measuring API (design.md §4): bad input, abort, Reset, busy, alarms, schema.

Every refusal is a 4xx ``{"error": {"code", "message", "field"?}}`` and changes nothing (offsets,
log); never a 500.
"""

from __future__ import annotations

import sys
import threading
from pathlib import Path

import numpy as np
import pytest
from waiting import wait_until

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "flows"))
from truthkit import HOLE_D, HOLES, SPIGOT_H, SPIGOTS, Operator, scenario  # noqa: E402


@pytest.fixture
def op(client):
    operator = Operator(client, scenario())
    operator.load()
    return operator


def snapshot(op: Operator) -> tuple:
    """Offsets and the log of measurements (a failed attempt is logged too, status "alarm ...")."""
    log = [e for e in op.ok(op.c.get("/api/log")) if not str(e["status"]).startswith("alarm")]
    return op.ok(op.c.get("/api/offsets")), log


def error_of(response, status: int, code: str | None = None, field: str | None = None) -> dict:
    assert response.status_code == status, response.text
    err = response.json()["error"]
    assert err["message"]
    if code:
        assert err["code"] == code, err
    if field:
        assert err.get("field") == field, err
    return err


BAD_CREATE = [
    ({"task": "hole.9", "params": {}}, "task"),
    ({"task": 7, "params": {}}, "task"),
    ({"task": "hole.1", "params": {"diameter": -20}}, "diameter"),
    ({"task": "hole.1", "params": {"diameter": "twenty"}}, "diameter"),
    ({"task": "spigot.1", "params": {"infeed": 5}}, "diameter"),
    ({"task": "spigot.2", "params": {"diameter": 10, "infeed": 0}}, "infeed"),
    ({"task": "spigot.rect", "params": {"length": 10, "width": 10, "infeed": -2}}, "infeed"),
    ({"task": "spigot.rect", "params": {"length": 10, "infeed": 2}}, "width"),
    ({"task": "pocket.rect", "params": {"length": 0}}, "length"),
    ({"task": "probe.radius", "params": {}}, "diameter"),
    ({"task": "edge.set", "params": {"axis": "W"}}, "axis"),
    ({"task": "edge.set", "params": {"direction": "up"}}, "direction"),
    ({"task": "edge.distance", "params": {"direction_p2": 1}}, "direction_p2"),
    ({"task": "edge.align", "params": {"axis": "Y", "reference_axis": "Y"}}, "reference_axis"),
    ({"task": "edge.set", "params": {"axis": "X", "setpoint": "zero"}}, "setpoint.X"),
    ({"task": "edge.set", "params": {"axis": "X", "setpoint": {"Y": 1}}}, "setpoint.Y"),
    ({"task": "hole.1", "params": {"setpoint": {"X": "a", "Y": 0}}}, "setpoint.X"),
    ({"task": "corner.right", "params": {"setpoint": 5}}, "setpoint"),
    ({"task": "corner.right", "params": {"position": 5}}, "position"),
    ({"task": "corner.any", "params": {"position": "left"}}, "position"),
    ({"task": "corner.right", "params": {"kind": "concave"}}, "kind"),
    ({"task": "hole.2", "params": {"diameter": 10, "angle_correction": "Q"}}, "angle_correction"),
    ({"task": "hole.2", "params": {"diameter": 10, "angle_correction": "C"}}, "angle_correction"),  # no C
    ({"task": "hole.3", "params": {"diameter": 10, "setpoint_angle": 360}}, "setpoint_angle"),
    ({"task": "hole.2", "params": {"diameter": 10, "set_p1": "yes"}}, "set_p1"),
    ({"task": "hole.1", "params": {"diameter": 10}, "target": "G99"}, "target"),
    ({"task": "hole.1", "params": {"diameter": 10, "target": "G54x"}}, "target"),
    ({"task": "hole.1", "params": {"diameter": 10}, "target": 54}, "target"),
    ({"task": "hole.1", "params": [1, 2]}, "params"),
    ({"task": "hole.1", "params": {}, "extra": True}, "extra"),
    ({"task": "tool.length", "params": {"offset_v": -1}}, "offset_v"),
]


def test_bad_create_is_4xx_naming_the_field_and_changes_nothing(op):
    good = op.create("hole.1", {"diameter": HOLE_D})
    before = snapshot(op)
    for body, field in BAD_CREATE:
        response = op.c.post("/api/measure", json=body)
        assert 400 <= response.status_code < 500, (body, response.text)
        err = response.json()["error"]
        assert err["code"] and err["message"] and err.get("field") == field, (body, err)
    assert snapshot(op) == before
    assert op.ok(op.c.get("/api/measure/current"))["id"] == good["id"]     # the open screen stays


def test_rotary_angle_correction_accepted_when_the_axis_exists(client):
    op = Operator(client, scenario(rotary=True))
    op.load()
    session = op.create("hole.2", {"diameter": 10, "angle_correction": "c"})
    assert session["params"]["angle_correction"] == "C"


def test_unknown_session_and_point(op):
    for method, url in (("post", "/api/measure/nope/start"), ("post", "/api/measure/nope/calculate"),
                        ("post", "/api/measure/nope/points/1/invalidate"), ("get", "/api/measure/nope"),
                        ("delete", "/api/measure/nope")):
        error_of(getattr(op.c, method)(url), 404, "no_session")
    sid = op.create("hole.2", {"diameter": HOLE_D})["id"]
    error_of(op.c.post(f"/api/measure/{sid}/start", json={"point": 3}), 404, "no_point", "point")
    error_of(op.c.post(f"/api/measure/{sid}/start", json={"point": 13}), 422, field="point")   # beyond P12
    error_of(op.c.post(f"/api/measure/{sid}/start", json={"point": "two"}), 422, field="point")
    error_of(op.c.post(f"/api/measure/{sid}/points/3/invalidate"), 404, "no_point", "point")
    error_of(op.c.post(f"/api/measure/{sid}/calculate"), 409, "points_missing")
    single = op.create("hole.1", {"diameter": HOLE_D})["id"]
    error_of(op.c.post(f"/api/measure/{single}/calculate"), 409, "single_point")


def hole_start(op, c, dz=-8.0):
    return op.part.mcs(c[0] + 0.3, c[1] - 0.2, dz)


def test_invalidate_and_remeasure(op):
    op.activate("G54")
    sid = op.create("hole.2", {"diameter": HOLE_D, "set_p1": True})["id"]
    op.ball_to(hole_start(op, HOLES[0]))
    assert op.start(sid)["session"]["plc_dbb43"] == 0x10
    op.ball_to(hole_start(op, HOLES[1]))
    session = op.start(sid)["session"]
    assert session["can_calculate"] and session["plc_dbb43"] == 0x30
    before = snapshot(op)
    session = op.ok(op.c.post(f"/api/measure/{sid}/points/1/invalidate"))
    assert not session["can_calculate"] and session["next_point"] == 1 and session["plc_dbb43"] == 0x20
    error_of(op.c.post(f"/api/measure/{sid}/calculate"), 409, "points_missing")
    assert snapshot(op) == before
    op.ball_to(hole_start(op, HOLES[0]))
    answer = op.start(sid)
    assert answer["point"]["n"] == 1 and answer["session"]["can_calculate"]
    result = op.calculate(sid)
    p1, p2 = (op.part.mcs(*c, -8.0) for c in HOLES[:2])
    g54 = op.frame("G54")
    assert np.allclose(g54.to_child(p1)[:2], 0.0, atol=1e-6)
    d = g54.to_child(p2) - g54.to_child(p1)
    assert abs(d[1]) < 1e-6
    assert result["log_id"] and op.ok(op.c.get("/api/measure/current"))["plc_dbb43"] == 0   # §3.1 step 6


def test_61301_nothing_touched(op):
    op.ball_to(op.part.mcs(-60.0, 60.0, -10.0))           # 60 mm in front of the left face, in air
    op.ok(op.c.put("/api/settings", json={"measuring_path": 20.0}))
    before = snapshot(op)
    sid = op.create("edge.set", {"axis": "X", "direction": "+"}, "G54")["id"]
    err = error_of(op.c.post(f"/api/measure/{sid}/start"), 409, "alarm")
    assert "61301" in err["message"]
    session = op.ok(op.c.get(f"/api/measure/{sid}"))
    assert not session["points"][0]["stored"] and session["alarm"]["code"] == 61301
    machine = op.ok(op.c.get("/api/machine"))
    assert [a["code"] for a in machine["alarms"]] == [61301]
    assert snapshot(op) == before
    failed = op.ok(op.c.get("/api/log"))[0]                             # the failed attempt, logged
    assert failed["status"] == "alarm 61301" and failed["target"] == "G54" and failed["correction"] is None
    assert failed["result"]["alarm"]["point"] == 1
    error_of(op.c.post(f"/api/measure/{sid}/start"), 409, "alarm")      # pending until Reset
    op.ok(op.c.post("/api/machine/reset"))
    assert op.ok(op.c.get("/api/machine"))["alarms"] == []
    # the alarm stops the cycle where the stroke ended: 2 x measuring path along +X
    assert np.allclose(op.ball_mcs(), op.part.mcs(-60.0, 60.0, -10.0) + [40.0, 0.0, 0.0], atol=1e-9)


def test_61302_collision_in_intermediate_positioning(client):
    op = Operator(client, scenario(kind="spigots"))
    op.load()
    before = snapshot(op)
    c = SPIGOTS[0]
    op.ball_to(op.part.mcs(c[0], c[1], SPIGOT_H + 5.0))
    # the approximate diameter is far too small: "down DZ" lands on the spigot. The start guard
    # refuses it before anything moves (issue 24 §1) ...
    sid = op.create("spigot.1", {"diameter": 4.0, "infeed": 13.0}, "G54")["id"]
    err = error_of(op.c.post(f"/api/measure/{sid}/start"), 409, "guard")
    assert "DZ" in err["segment"]["label"] and not op.ok(op.c.get("/api/machine"))["alarms"]
    assert snapshot(op) == before
    # ... and without the guard the machine's own monitoring stops the move: 61302
    sid = op.create("spigot.1", {"diameter": 4.0, "infeed": 13.0, "guard": False}, "G54")["id"]
    err = error_of(op.c.post(f"/api/measure/{sid}/start"), 409, "alarm")
    assert "61302" in err["message"]
    assert 61302 in [a["code"] for a in op.ok(op.c.get("/api/machine"))["alarms"]]
    assert not op.ok(op.c.get(f"/api/measure/{sid}"))["points"][0]["stored"]
    assert snapshot(op) == before


# --- timed moves: Reset, abort, busy ------------------------------------------------------------

def timed(op: Operator) -> str:
    """time_scale 1, probe in the air above the block; hole.1 without diameter probes 100 mm at
    300 mm/min (20 s) unless stopped."""
    scen = scenario()
    scen["machine"]["time_scale"] = 1.0
    op.load(scen)
    return op.create("hole.1", {}, "G54")["id"]


def run_start(op: Operator, sid: str) -> tuple[threading.Thread, dict]:
    out: dict = {}

    def target():
        out["response"] = op.c.post(f"/api/measure/{sid}/start")

    thread = threading.Thread(target=target, daemon=True)
    thread.start()
    wait_until(lambda: op.ok(op.c.get("/api/machine"))["busy"], "the measurement starts")
    return thread, out


def test_reset_during_nc_start_stores_nothing(op):
    sid = timed(op)
    before = snapshot(op)
    thread, out = run_start(op, sid)
    # busy: a second NC Start, a new screen and an invalidate are refused while it runs
    error_of(op.c.post(f"/api/measure/{sid}/start"), 409, "busy")
    error_of(op.c.post("/api/measure", json={"task": "hole.1", "params": {}}), 409, "busy")
    error_of(op.c.post(f"/api/measure/{sid}/points/1/invalidate"), 409, "busy")
    assert op.ok(op.c.get(f"/api/measure/{sid}"))["busy"] is True
    op.ok(op.c.post("/api/machine/reset"))
    thread.join(timeout=5.0)                   # how soon it ends is a figure of bench/, not a bar here
    assert not thread.is_alive()
    error_of(out["response"], 409, "alarm")
    session = op.ok(op.c.get(f"/api/measure/{sid}"))
    assert not session["points"][0]["stored"] and session["busy"] is False
    assert snapshot(op) == before
    assert op.ok(op.c.get("/api/machine"))["busy"] is False


def test_delete_during_a_timed_move_aborts(op):
    sid = timed(op)
    before = snapshot(op)
    thread, out = run_start(op, sid)
    assert op.ok(op.c.delete(f"/api/measure/{sid}")) == {"deleted": sid}
    thread.join(timeout=5.0)
    assert not thread.is_alive()
    assert 400 <= out["response"].status_code < 500, out["response"].text
    assert op.ok(op.c.get("/api/measure/current")) is None
    assert op.ok(op.c.get("/api/machine"))["busy"] is False
    assert snapshot(op) == before


def test_delete_while_idle(op):
    sid = op.create("corner.right", {})["id"]
    assert op.ok(op.c.delete(f"/api/measure/{sid}")) == {"deleted": sid}
    assert op.ok(op.c.get("/api/measure/current")) is None
    error_of(op.c.post(f"/api/measure/{sid}/start"), 404, "no_session")


def test_openapi_has_the_measure_calls_with_examples(client):
    schema = client.get("/openapi.json").json()
    paths = schema["paths"]
    for path, method in (("/api/measure", "post"), ("/api/measure/current", "get"),
                         ("/api/measure/{session_id}/start", "post"),
                         ("/api/measure/{session_id}/points/{n}/invalidate", "post"),
                         ("/api/measure/{session_id}/calculate", "post"),
                         ("/api/measure/{session_id}", "delete")):
        assert method in paths[path], path
    create = schema["components"]["schemas"]["CreateBody"]
    examples = create.get("examples") or []
    assert examples and all("task" in e for e in examples)
    assert {e["task"] for e in examples} >= {"hole.1", "corner.right", "edge.set"}


def test_nc_start_with_a_cutter_in_the_spindle_is_refused_with_61309(client):
    """Spec §10 [I]: probe not the active tool -> 61309, no motion, nothing stored."""
    assert client.post("/api/machine/tool", json={"tool": 1}).status_code == 200
    before = client.get("/api/machine").json()["mcs"]
    session = client.post("/api/measure", json={"task": "edge.set",
                                                "params": {"axis": "X", "direction": "+"}}).json()
    answer = client.post(f"/api/measure/{session['id']}/start")
    assert answer.status_code == 409 and answer.json()["error"]["message"].startswith("61309")
    assert client.get("/api/machine").json()["mcs"] == before
    assert client.get(f"/api/measure/{session['id']}").json()["points"][0]["stored"] is False

"""The start guard's reach check through the API (issue 24 §1, measuring-math §1.3): a measuring
feed so high that the braking behind the switch would push the probe beyond its permissible
deflection is refused before NC Start moves anything (409 ``guard``, alarm 65302, the probing
segment with its braking figure), the axes where they were, no alarm, nothing stored. The truth
is the formula worked by hand and the simulator: the same start with the guard off breaks the
probe (61302), and a feed whose braking fits measures the face where it is.

Scenario (tests/flows/truthkit.py): latency 0 s, deceleration 1 m/s², Kv 1 (m/min)/mm (the
scenario defaults), permissible deflection 5 mm; the block's top face is part z = 0."""

from __future__ import annotations

import re

import pytest
import test_start_guard as guarded
from truthkit import Operator

R = guarded.R
FACE = (100.0, 15.0)          # a plain spot of the top face (clear of every feature)
MAX_DEFLECTION = 5.0


def braking_by_hand(feed_mm_min: float, t: float = 0.0, a: float = 1.0, kv: float = 1.0) -> float:
    """measuring-math §1.3: s_b = 1000·v·t + 1000·v²/(2a) + v[m/min]/Kv, v in m/s."""
    v = feed_mm_min / 60000.0
    return 1000.0 * v * t + 1000.0 * v * v / (2.0 * a) + (feed_mm_min / 1000.0) / kv


@pytest.fixture
def op(client):
    return guarded.operator_in_g54(client)


def stored(op: Operator) -> dict:
    return {"log": op.ok(op.c.get("/api/log")), "G54": op.offset("G54"), "probe": op.ok(op.c.get("/api/probes/1"))}


def test_a_feed_whose_braking_exceeds_the_deflection_is_refused_before_motion(op):
    feed = 6000.0                                     # 0.1 m/s: 5 mm + 6 mm = 11 mm of braking > 5 mm
    assert braking_by_hand(feed) == pytest.approx(11.0, abs=1e-12)
    op.ok(op.c.put("/api/settings", json={"measuring_feed": feed}))
    op.ball_to_part(*FACE, R + 10.0)
    before, data = op.ok(op.c.get("/api/machine")), stored(op)
    session = op.create("edge.set", {"axis": "Z", "direction": "-", "setpoint": 0.0}, "G54")
    answer = op.c.post(f"/api/measure/{session['id']}/start")
    assert answer.status_code == 409, answer.text
    error = answer.json()["error"]
    assert error["code"] == "guard" and error["alarm"]["code"] == 65302
    segment = error["segment"]
    assert segment["kind"] == "probe" and segment["verdict"] == "overtravel" and segment["label"].startswith("P1")
    assert segment["feed"] == feed
    assert segment["braking"] == pytest.approx(braking_by_hand(feed), abs=1e-9)
    assert segment["deflection"] == pytest.approx(braking_by_hand(feed), abs=1e-9)
    assert segment["max_deflection"] == MAX_DEFLECTION
    assert segment["at"]["Z"] == pytest.approx(R, abs=1e-6)          # it would touch the top face
    assert "11.000 mm" in error["message"] and "6000 mm/min" in error["message"]
    after = op.ok(op.c.get("/api/machine"))
    assert after["mcs"] == before["mcs"] and not after["alarms"] and not after["busy"]
    assert stored(op) == data
    # the plan says the same before NC Start
    plan = op.ok(op.c.get(f"/api/measure/{session['id']}/plan"))
    assert plan["verdict"] == "refused" and plan["segments"][plan["refused_step"] - 1]["verdict"] == "overtravel"


def test_a_feed_whose_braking_fits_measures(op):
    feed = 3000.0                                     # 0.05 m/s: 1.25 mm + 3 mm = 4.25 mm < 5 mm
    assert braking_by_hand(feed) == pytest.approx(4.25, abs=1e-12)
    op.ok(op.c.put("/api/settings", json={"measuring_feed": feed}))
    op.ball_to_part(*FACE, R + 10.0)
    session = op.create("edge.set", {"axis": "Z", "direction": "-", "setpoint": 0.0}, "measure_only")
    plan = op.ok(op.c.get(f"/api/measure/{session['id']}/plan"))
    probe = [s for s in plan["segments"] if s["kind"] == "probe"][0]
    assert plan["verdict"] == "clear" and probe["braking"] == pytest.approx(4.25, abs=1e-9)
    done = op.start(session["id"])
    state = op.ok(op.c.get("/api/machine"))
    assert not state["alarms"]
    assert done["result"]["position"]["Z"] == pytest.approx(0.0, abs=1e-6)     # the top face, G54 on the true pose


def test_the_simulator_agrees_the_probe_breaks_with_the_guard_off(op):
    op.ok(op.c.put("/api/settings", json={"measuring_feed": 6000.0}))
    op.ball_to_part(*FACE, R + 10.0)
    session = op.create("edge.set", {"axis": "Z", "direction": "-", "setpoint": 0.0, "guard": False}, "measure_only")
    answer = op.c.post(f"/api/measure/{session['id']}/start")
    assert answer.status_code == 409 and "61302" in answer.json()["error"]["message"], answer.text


# --- tool measuring: not modelled, and said so ------------------------------------------------------

@pytest.fixture
def tool_api(tmp_path):
    import json

    from fastapi.testclient import TestClient
    from test_tool_measuring_truth import SCENARIO, Api

    from app.config import Settings
    from app.main import create_app

    path = tmp_path / "scenario.json"
    path.write_text(json.dumps(SCENARIO))
    with TestClient(create_app(Settings(db_path=tmp_path / "hmi.db", scenario_path=path, time_scale=0))) as c:
        yield Api(c)


def test_tool_measuring_says_it_is_not_checked_for_collisions(tool_api):
    from test_tool_measuring_truth import CUTTER_T

    tool_api.calibrate()
    answer = tool_api.length(CUTTER_T)
    assert any(w.startswith("Start guard: tool measuring is not checked for collisions") for w in answer["warnings"])
    session = tool_api.c.post("/api/measure", json={"task": "tool.length", "params": {}}).json()
    plan = tool_api.c.get(f"/api/measure/{session['id']}/plan").json()
    assert plan["verdict"] == "unknown" and plan["segments"]
    assert all(s["verdict"] == "unknown" for s in plan["segments"])
    # the milling machine's tool probe is not broken by overtravel: its reach is not checked
    probes = [s for s in plan["segments"] if s["kind"] == "probe"]
    assert probes and all(s["braking"] is None for s in probes)


# --- the measuring screen's 2D preview marks the refused segment ------------------------------------

HTMX = {"HX-Request": "true"}


def test_the_measuring_screens_preview_marks_the_refused_segment(op):
    """The deep spigot of the issue (Ø20, 12 high, infeed 30 from 10 above its top): the live
    picture marks P1's down move in red with the ball where it would touch; a fitting infeed
    marks nothing. The picture only reads: the axes stay where they are."""
    op.ball_to_part(guarded.SPIGOT_C[0], guarded.SPIGOT_C[1], guarded.SPIGOT_H + R + 10.0)
    before = op.ok(op.c.get("/api/machine"))["mcs"]
    form = {"diameter": "20", "infeed": "30", "target": "measure_only"}
    text = op.c.post("/measure/task/spigot.1/svg", data=form, headers=HTMX).text
    assert 'class="guard-refused"' in text and 'class="guard-hit"' in text, text
    marked = re.search(r'id="task-svg-side" class="task-svg" data-guard-refused="([^"]+)"', text)
    assert marked is not None and marked.group(1).startswith("P1") and "DZ" in marked.group(1)
    # the side view: the ball would touch the block's top face (part z = 0) with its centre R above it
    hit = re.search(r'<svg id="task-svg-side".*?<circle class="guard-hit" cx="([-\d.]+)" cy="([-\d.]+)"', text, re.S)
    assert hit is not None and -float(hit.group(2)) == pytest.approx(R, abs=1e-3)
    fits = op.c.post("/measure/task/spigot.1/svg", data={**form, "infeed": str(guarded.SPIGOT_H / 2 + R + 10.0)},
                     headers=HTMX).text
    assert "guard-refused" not in fits and "task-svg-side" in fits
    assert op.ok(op.c.get("/api/machine"))["mcs"] == before

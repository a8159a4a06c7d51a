"""The start guard (issue 24 §1, design.md §10.1) against the simulator's truth.

The deep spigot of the issue (Ø20 spigot 12 mm high, infeed 30) is refused before anything moves:
409 ``guard`` with the alarm and the segment, the axes where they were, no alarm in the machine,
the probe intact, nothing logged or written. The property test starts every task from random
positions around its feature and compares the guard's verdict (``GET /api/measure/{id}/plan``)
with what the simulator does when the same point runs with the guard switched off: the guard must
refuse exactly the starts on which the simulator collides (the simulator is the truth; the
guard's geometry is its own, engine.guard).
"""

from __future__ import annotations

import numpy as np
import pytest
from truthkit import BALL_D, Operator, scenario

SPIGOT_C, SPIGOT_D, SPIGOT_H = (60.0, 40.0), 20.0, 12.0
HOLE_C, HOLE_D, HOLE_DEPTH = (150.0, 40.0), 20.0, 25.0
POCKET_C, POCKET_SIZE, POCKET_DEPTH = (150.0, 90.0), (36.0, 24.0), 15.0
BOSS_C, BOSS_SIZE, BOSS_H = (60.0, 90.0), (30.0, 20.0), 10.0
R = BALL_D / 2.0
COUNTS: dict[str, dict[str, int]] = {}


def guard_scenario() -> dict:
    data = scenario(rot=(0.0, 0.0, 3.0))
    data["workpiece"]["features"] = [
        data["workpiece"]["features"][0],
        {"type": "spigot", "center": list(SPIGOT_C), "diameter": SPIGOT_D, "height": SPIGOT_H},
        {"type": "hole", "center": list(HOLE_C), "diameter": HOLE_D, "depth": HOLE_DEPTH},
        {"type": "pocket", "center": list(POCKET_C), "size": list(POCKET_SIZE), "depth": POCKET_DEPTH},
        {"type": "boss", "center": list(BOSS_C), "size": list(BOSS_SIZE), "height": BOSS_H},
    ]
    return data


def operator_in_g54(client) -> Operator:
    """An operator on the guard scenario with G54 on the part's corner, active."""
    operator = Operator(client, guard_scenario())
    operator.load()
    pose = operator.scen["workpiece"]["pose"]
    operator.put_offset("G54", rot=pose["rot"], trans=pose["trans"])       # G54 on the part's corner
    operator.activate("G54")
    return operator


@pytest.fixture
def op(client):
    return operator_in_g54(client)


def machine(op: Operator) -> dict:
    return op.ok(op.c.get("/api/machine"))


def test_the_deep_spigot_is_refused_before_anything_moves(op):
    op.ball_to_part(SPIGOT_C[0] + 0.5, SPIGOT_C[1] - 0.3, SPIGOT_H + R + 10.0)   # 10 mm above the top
    before = machine(op)
    log_before = op.ok(op.c.get("/api/log"))
    session = op.create("spigot.1", {"diameter": SPIGOT_D, "infeed": 30}, "measure_only")
    answer = op.c.post(f"/api/measure/{session['id']}/start")
    assert answer.status_code == 409, answer.text
    error = answer.json()["error"]
    assert error["code"] == "guard"
    assert error["alarm"]["code"] == 65300
    assert "infeed 30 mm" in error["message"]
    segment = error["segment"]
    assert segment["point"] == 1 and "DZ" in segment["label"] and segment["verdict"] == "collision"
    assert segment["body"] == "workpiece"
    after = machine(op)
    assert after["mcs"] == before["mcs"] and not after["alarms"] and not after["busy"]
    assert op.ok(op.c.get("/api/log")) == log_before
    # the probe is intact: the same spigot measured with an infeed that fits gives the truth
    session = op.create("spigot.1", {"diameter": SPIGOT_D, "infeed": SPIGOT_H / 2 + R + 10.0}, "measure_only")
    done = op.start(session["id"])
    assert done["result"]["center"]["X"] == pytest.approx(SPIGOT_C[0], abs=1e-6)
    assert done["result"]["center"]["Y"] == pytest.approx(SPIGOT_C[1], abs=1e-6)


def test_the_plan_shows_the_offending_segment(op):
    op.ball_to_part(SPIGOT_C[0], SPIGOT_C[1], SPIGOT_H + R + 10.0)
    session = op.create("spigot.1", {"diameter": SPIGOT_D, "infeed": 30}, "measure_only")
    plan = op.ok(op.c.get(f"/api/measure/{session['id']}/plan"))
    assert plan["verdict"] == "refused" and plan["guard"] is True
    refused = [s for s in plan["segments"] if s["verdict"] == "collision"]
    assert len(refused) == 1 and refused[0]["step"] == plan["refused_step"] == len(plan["segments"])
    # the down move ends 30 below the start: the ball would reach below the block's top face
    assert refused[0]["to"]["Z"] == pytest.approx(SPIGOT_H + R + 10.0 - 30.0, abs=1e-6)
    assert refused[0]["at"]["Z"] == pytest.approx(R, abs=1e-6)          # touching the top face (z = 0)
    assert all(s["verdict"] == "clear" for s in plan["segments"][:-1])


def test_switching_the_guard_off_is_audited_and_then_the_machine_collides(op):
    op.ball_to_part(SPIGOT_C[0], SPIGOT_C[1], SPIGOT_H + R + 10.0)
    session = op.create("spigot.1", {"diameter": SPIGOT_D, "infeed": 30, "guard": False}, "measure_only")
    audit = op.ok(op.c.get("/api/audit"))
    rows = audit if isinstance(audit, list) else audit.get("entries", audit.get("items", []))
    assert any(r.get("kind") == "guard" for r in rows), audit
    answer = op.c.post(f"/api/measure/{session['id']}/start")
    assert answer.status_code == 409 and answer.json()["error"]["code"] == "alarm"
    assert "61302" in answer.json()["error"]["message"]


def test_guard_must_be_a_boolean(op):
    answer = op.c.post("/api/measure", json={"task": "spigot.1", "params": {"diameter": 20, "infeed": 5,
                                                                            "guard": "no"}})
    assert answer.status_code == 400 and answer.json()["error"]["field"] == "guard"


# --- property: the guard refuses exactly what the simulator collides on ---------------------------

def _spigot(rng):
    start = (SPIGOT_C[0] + rng.uniform(-3, 3), SPIGOT_C[1] + rng.uniform(-3, 3), SPIGOT_H + R + rng.uniform(1, 12))
    return "spigot.1", {"diameter": SPIGOT_D, "infeed": float(rng.uniform(3, 30))}, start


def _boss(rng):
    start = (BOSS_C[0] + rng.uniform(-3, 3), BOSS_C[1] + rng.uniform(-3, 3), BOSS_H + R + rng.uniform(1, 8))
    return "spigot.rect", {"length": BOSS_SIZE[0], "width": BOSS_SIZE[1],
                           "infeed": float(rng.uniform(3, 25))}, start


def _hole(rng):
    start = (HOLE_C[0] + rng.uniform(-4, 4), HOLE_C[1] + rng.uniform(-4, 4), -rng.uniform(3, 20))
    diameter = float(rng.choice([HOLE_D, HOLE_D - 4.0, rng.uniform(100, 140)]))   # wrong: the approach
    return "hole.1", {"diameter": diameter}, start


def _pocket(rng):
    start = (POCKET_C[0] + rng.uniform(-6, 6), POCKET_C[1] + rng.uniform(-4, 4), -rng.uniform(3, 12))
    # a pocket's approach starts E_MESS_D_M (50) before the wall the parameters describe
    return "pocket.rect", {"length": float(rng.uniform(20, 160)), "width": float(rng.uniform(15, 130))}, start


def _edge(rng):
    start = (rng.uniform(5, 195), rng.uniform(5, 115), SPIGOT_H + R + rng.uniform(1, 12))
    return "edge.set", {"axis": "Z", "direction": "-", "setpoint": 0.0}, start


def _ring(rng):
    """probe.radius in the ring gauge (MCS centre of its top face [600, 100, -160], bore Ø25)."""
    start = ("MCS", 600.0 + rng.uniform(-3, 3), 100.0 + rng.uniform(-3, 3), -160.0 - rng.uniform(-6, 10))
    return "probe.radius", {"diameter": float(rng.choice([25.0, rng.uniform(60, 130)]))}, start


FEATURES = {"probe.radius": _ring, "spigot.1": _spigot, "spigot.rect": _boss, "hole.1": _hole, "pocket.rect": _pocket,
            "edge.set": _edge}


def _simulator_collided(op: Operator, move_labels: set[str]) -> bool:
    entry = op.ok(op.c.get("/api/log"))
    entries = entry if isinstance(entry, list) else entry.get("entries", [])
    alarm = (entries[0].get("result") or {}).get("alarm") or {} if entries else {}
    return alarm.get("code") == 61302 and alarm.get("step") in move_labels


@pytest.mark.parametrize("feature", sorted(FEATURES))
def test_guard_refuses_exactly_what_the_simulator_collides_on(op, feature):
    rng = np.random.default_rng(sum(map(ord, feature)))
    counts = COUNTS.setdefault(feature, {"refused": 0, "agreed": 0, "disagreed": 0, "trials": 0})
    for _ in range(12):
        task, params, start = FEATURES[feature](rng)
        op.load()
        op.activate("G54")
        op.ball_to(start[1:] if start[0] == "MCS" else op.part.mcs(*start))
        session = op.create(task, {**params, "guard": False}, "measure_only")
        plan = op.ok(op.c.get(f"/api/measure/{session['id']}/plan"))
        refused = plan["verdict"] == "refused"
        move_labels = {s["label"] for s in plan["segments"] if s["kind"] == "move"}
        before = machine(op)["mcs"]
        answer = op.c.post(f"/api/measure/{session['id']}/start")
        collided = answer.status_code == 409 and _simulator_collided(op, move_labels)
        counts["trials"] += 1
        counts["refused"] += int(refused)
        counts["agreed" if refused == collided else "disagreed"] += 1
        assert refused == collided, (task, params, start, plan, answer.json())
        if not collided:
            assert answer.status_code == 200 or answer.json()["error"]["code"] == "alarm", answer.text
        assert before is not None
    print(f"start guard {feature}: {counts}")

"""Safe approaches in every plan (issue 24 §2): every milling task that positions around a feature
runs from a start just above (or just inside) the feature and from its far side. Each run ends in
one of two ways, both judged against the scenario's truth (noise-free, G54 on the true pose): the
measured feature where it truly is, or a refusal before anything moves (the start guard's 409,
axes where they were). Never a collision, never a broken probe."""

from __future__ import annotations

import pytest
import test_start_guard as guarded

BOSS_C, BOSS_H, BOSS_SIZE = guarded.BOSS_C, guarded.BOSS_H, guarded.BOSS_SIZE
HOLE_C, HOLE_D = guarded.HOLE_C, guarded.HOLE_D
POCKET_C, POCKET_SIZE = guarded.POCKET_C, guarded.POCKET_SIZE
SPIGOT_C, SPIGOT_D, SPIGOT_H, R = guarded.SPIGOT_C, guarded.SPIGOT_D, guarded.SPIGOT_H, guarded.R

ABOVE = R + 1.0            # ball centre 1 mm above a top face
BELOW = -(R + 1.0)         # ball centre just inside a hole or pocket, 1 mm below the top edge

# task, params, what it measures (truth in part coordinates), starts (part coordinates of the ball
# centre) with the outcome they must have: just above or inside the feature, off towards its far
# side as far as the task's own positioning allows (both measured), and so far off that the task's
# approach around the start would come down on the feature itself (refused before any motion)
CASES = {
    "spigot.1": ({"diameter": SPIGOT_D, "infeed": 5.0}, {"center": SPIGOT_C, "diameter": SPIGOT_D},
                 [((*SPIGOT_C, SPIGOT_H + ABOVE), "measured"),
                  ((SPIGOT_C[0] + 2.5, SPIGOT_C[1] + 2.0, SPIGOT_H + ABOVE), "measured"),
                  ((SPIGOT_C[0] + 7.0, SPIGOT_C[1] + 6.0, SPIGOT_H + ABOVE), "refused")]),
    "spigot.rect": ({"length": BOSS_SIZE[0], "width": BOSS_SIZE[1], "infeed": 5.0}, {"center": BOSS_C},
                    [((*BOSS_C, BOSS_H + ABOVE), "measured"),
                     ((BOSS_C[0] + 2.5, BOSS_C[1] - 2.0, BOSS_H + ABOVE), "measured"),
                     ((BOSS_C[0] + 13.0, BOSS_C[1] - 8.0, BOSS_H + ABOVE), "refused")]),
    "hole.1": ({"diameter": HOLE_D}, {"center": HOLE_C, "diameter": HOLE_D},
               [((*HOLE_C, BELOW), "measured"), ((HOLE_C[0] + 5.0, HOLE_C[1] - 4.0, BELOW), "measured")]),
    "pocket.rect": ({"length": POCKET_SIZE[0], "width": POCKET_SIZE[1]}, {"center": POCKET_C},
                    [((*POCKET_C, BELOW), "measured"), ((POCKET_C[0] - 14.0, POCKET_C[1] + 8.0, BELOW), "measured")]),
}
RUNS = [(task, i) for task in sorted(CASES) for i in range(len(CASES[task][2]))]
NAMES = ("above", "off-centre", "far-off")


@pytest.fixture
def op(client):
    return guarded.operator_in_g54(client)


@pytest.mark.parametrize(("task", "start"), RUNS, ids=[f"{t}-{NAMES[i]}" for t, i in RUNS])
def test_every_task_from_above_and_from_the_far_side(op, task, start):
    params, truth, starts = CASES[task]
    where, outcome = starts[start]
    op.ball_to_part(*where)
    before = op.ok(op.c.get("/api/machine"))["mcs"]
    session = op.create(task, params, "measure_only")
    answer = op.c.post(f"/api/measure/{session['id']}/start")
    state = op.ok(op.c.get("/api/machine"))
    assert all(a["code"] != 61302 for a in state["alarms"]), state["alarms"]      # no collision
    if outcome == "refused":
        assert answer.status_code == 409 and answer.json()["error"]["code"] == "guard", answer.text
        assert state["mcs"] == before                                              # nothing moved
        return
    assert answer.status_code == 200, answer.text
    result = answer.json()["result"]
    assert [result["center"]["X"], result["center"]["Y"]] == pytest.approx(list(truth["center"]), abs=1e-6)
    if "diameter" in truth:
        assert result["diameter"] == pytest.approx(truth["diameter"], abs=1e-6)

"""Rotary-table alignment (spec §2.5.2, §2.7.2, §6.2 rotary case, §11 Q8) against the truth.

The part stands turned on a rotary table C. Align edge / 2 holes with angle correction "C"
write the measured − setpoint angle into G54's C offset; NC Start on the set-up support turns C
so that the edge lies at the setpoint angle. Checked against the simulator's truth: the part's
true pose after the turn (scene.workpiece_pose) and a re-measurement.
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
from test_chain_truth import CHAIN_SCENARIO, Operator, make_client, post, rpy, run_points

TURN = 6.5                         # deg: the part's true turn on the table at C = 0
TABLE_CENTRE = (340.0, 210.0)
ROTARY_SCENARIO = copy.deepcopy(CHAIN_SCENARIO)
ROTARY_SCENARIO["rotary_axes"] = {"C": {"limits": [-360, 360]}}
ROTARY_SCENARIO["machine"]["rotary_table"] = {"axis": "C", "center": list(TABLE_CENTRE)}
ROTARY_SCENARIO["workpiece"] = {
    "pose": {"trans": [250.0, 150.0, -120.0], "rot": [0.0, 0.0, TURN]},
    "features": [{"type": "block", "size": [200, 120, 60]},
                 {"type": "hole", "center": [40, 60], "diameter": 20, "depth": 25},
                 {"type": "hole", "center": [160, 60], "diameter": 20, "depth": 25}]}


class TableOperator(Operator):
    """Looks at the part where the table has turned it (truth: pose turned about the table axis)."""

    def turned(self, c_deg: float) -> None:
        pose = ROTARY_SCENARIO["workpiece"]["pose"]
        turn = rpy((0.0, 0.0, -c_deg))
        centre = np.array([*TABLE_CENTRE, 0.0])
        self.R = turn @ rpy(pose["rot"])
        self.t = turn @ (np.array(pose["trans"], float) - centre) + centre


def true_edge_angle(op: Operator) -> float:
    """Angle of the part's front edge (part x axis) to MCS X, deg."""
    x = op.R[:, 0]
    return math.degrees(math.atan2(x[1], x[0]))


@pytest.mark.parametrize("task", ["edge.align", "hole.2"])
def test_rotary_table_alignment(tmp_path, task):
    with make_client(tmp_path, ROTARY_SCENARIO) as client:
        op = TableOperator(client, ROTARY_SCENARIO)
        post(client, "/api/machine/activate", {"offset": "G54"})
        if task == "edge.align":
            params = {"axis": "Y", "direction": "+", "reference_axis": "X", "angle_correction": "C",
                      "setpoint_angle": 0.0}
            starts = [(30, -8, -6), (170, -8, -6)]
        else:
            params = {"diameter": 20, "angle_correction": "C", "setpoint_angle": 0.0, "set_p1": False}
            starts = [(40, 60, -10), (160, 60, -10)]
        answer = run_points(client, op, task, params, starts)
        assert answer["result"]["angle"] == pytest.approx(TURN, abs=1e-6)
        support = answer["setup_support"]
        assert [r["code"] for r in support["reasons"]] == ["rotary"]
        assert support["reasons"][0]["move"] == pytest.approx(TURN, abs=1e-6)
        g54 = client.get("/api/offsets/G54").json()
        assert g54["trans"]["C"] == pytest.approx(TURN, abs=1e-6)        # offset += measured − setpoint

        screen = client.get(f"/api/measure/{answer['_session']}/setup-support").json()
        assert screen["top_line"] == "Rotary axis must be positioned!"
        assert any(t["name"] == "position_rotary" for t in screen["toggles"])

        op.goto_mcs(Z=5.0)                                                # clear before turning the table
        done = post(client, f"/api/measure/{answer['_session']}/setup-support", {})
        assert done["axis_motion"] is True
        status = client.get("/api/machine").json()
        assert status["mcs"]["C"] == pytest.approx(TURN, abs=1e-9)
        assert status["wcs"]["C"] == pytest.approx(0.0, abs=1e-9)         # C = 0 in the new WO
        op.turned(status["mcs"]["C"])
        assert true_edge_angle(op) == pytest.approx(0.0, abs=1e-9)        # truth: the edge lies along X

        # re-measure (measure only): the turned part's edge reads the setpoint angle
        again = run_points(client, op, "edge.align",
                           {"axis": "Y", "direction": "+", "reference_axis": "X", "angle_correction": "rotation",
                            "setpoint_angle": 0.0}, [(30, -8, -6), (170, -8, -6)], target="measure_only")
        assert again["result"]["angle"] == pytest.approx(0.0, abs=1e-6)


def test_rotary_turn_into_probe_is_a_collision(tmp_path):
    with make_client(tmp_path, ROTARY_SCENARIO) as client:
        op = TableOperator(client, ROTARY_SCENARIO)
        op.ball_to((203.0, 60, -6))                  # right of the block, 1 mm clear of its face
        r = client.post("/api/machine/goto", json={"C": -30.0, "coords": "MCS"})
        assert r.status_code == 409 and "61302" in r.text


def test_rotary_table_axis_must_exist():
    from app.machine.scenario import load_scenario

    bad = copy.deepcopy(ROTARY_SCENARIO)
    bad["machine"]["rotary_table"]["axis"] = "A"
    with pytest.raises(ValueError, match="rotary_table"):
        load_scenario(bad)


def test_table_turn_moves_the_true_part_rigidly():
    """scene.workpiece_pose: a +c table turn is Rz(−c) about the table axis (DIN 66217)."""
    from app.machine.scenario import load_scenario
    from app.machine.scene import workpiece_pose

    sc = load_scenario(ROTARY_SCENARIO)
    rot, trans = workpiece_pose(sc, 30.0)
    centre = np.array([*TABLE_CENTRE, -120.0])
    r0, t0 = rpy((0, 0, TURN)), np.array([250.0, 150.0, -120.0])
    expected_t = rpy((0, 0, -30.0)) @ (t0 - centre) + centre
    assert np.allclose(rot, rpy((0, 0, TURN - 30.0)), atol=1e-12)
    assert np.allclose(trans, expected_t, atol=1e-9)
    assert np.allclose(workpiece_pose(sc, 0.0)[0], r0)

"""The trainer's set-up error (app/machine/sim_trainer.py) against the scenario's hidden pose.

Truth: the scenario's pose (part -> MCS) and scipy rotations; a frame written with a known
error must come back with exactly that error."""

from __future__ import annotations

import numpy as np
import pytest
from sim_helpers import rotation, scenario

from app.machine.sim import SimulatedMachine

POSE_T = np.array([200.0, 150.0, -150.0])
POSE_R = (0.4, -0.3, 17.0)
BLOCK = (200.0, 120.0, 60.0)


def machine(rot=POSE_R, **overrides) -> SimulatedMachine:
    sc = scenario(workpiece={"pose": {"trans": POSE_T.tolist(), "rot": list(rot)},
                             "features": [{"type": "block", "size": list(BLOCK)},
                                          {"type": "hole", "center": [40, 30], "diameter": 20, "depth": 25}]},
                  **overrides)
    return SimulatedMachine(sc)


def frame(trans, rot) -> dict:
    return {"trans": dict(zip("XYZ", map(float, trans), strict=True)),
            "rot": dict(zip("XYZ", map(float, rot), strict=True))}


def part_point(x: float, y: float, z: float = 0.0) -> np.ndarray:
    return rotation(POSE_R) @ np.array([x, y, z]) + POSE_T


def test_known_error_of_a_corner_set_up_comes_back_as_written():
    m = machine()
    dt, dr = np.array([0.012, -0.034, 0.021]), np.array([0.0, 0.0, 0.015])
    m.write_offset("G54", frame(POSE_T + dt, np.array(POSE_R) + dr))
    answer = m.setup_error("G54")
    assert answer["reference"].startswith("corner 1 ")
    assert [answer["error"]["trans"][a] for a in "XYZ"] == pytest.approx(dt, abs=1e-9)
    assert [answer["error"]["rot"][a] for a in "XYZ"] == pytest.approx(dr, abs=1e-9)
    assert [answer["ideal"]["trans"][a] for a in "XYZ"] == pytest.approx(POSE_T, abs=1e-9)


def test_a_perfect_set_up_on_the_back_right_corner_has_no_error():
    m = machine()
    corner3 = part_point(BLOCK[0], BLOCK[1])
    m.write_offset("G55", frame(corner3, POSE_R))
    answer = m.setup_error("G55")
    assert "corner 3" in answer["reference"]
    assert max(abs(v) for v in answer["error"]["trans"].values()) < 1e-9
    assert max(abs(v) for v in answer["error"]["rot"].values()) < 1e-9
    assert max(abs(v) for v in answer["reference_in_wcs"].values()) < 1e-9


def test_the_zero_on_the_hole_aligned_to_the_other_edge():
    """WCS on the hole's centre, X along the part's y edge (a quarter turn): only the error remains."""
    m = machine(rot=(0.0, 0.0, POSE_R[2]))
    centre = rotation((0.0, 0.0, POSE_R[2])) @ np.array([40.0, 30.0, 0.0]) + POSE_T
    m.write_offset("G56", frame(centre + [0.005, 0.0, 0.0], (0.0, 0.0, POSE_R[2] + 90.0 - 0.02)))
    answer = m.setup_error("G56")
    assert answer["reference"].startswith("hole Ø20")
    assert answer["error"]["trans"]["X"] == pytest.approx(0.005, abs=1e-9)
    assert answer["error"]["rot"]["Z"] == pytest.approx(-0.02, abs=1e-9)


def test_the_error_is_in_the_offsets_parent_system_under_a_basic_frame():
    """BASIC_0 outside G54 (design.md §3 chain): the right G54 is BASIC_0⁻¹ ∘ part."""
    m = machine()
    basic_t = np.array([10.0, -5.0, 2.0])
    m.write_offset("BASIC_0", frame(basic_t, (0.0, 0.0, 0.0)))
    dt = np.array([0.0, 0.02, 0.0])
    m.write_offset("G54", frame(POSE_T - basic_t + dt, POSE_R))
    answer = m.setup_error("G54")
    assert [answer["error"]["trans"][a] for a in "XYZ"] == pytest.approx(dt, abs=1e-9)
    # the corner lies at −error in the operator's WCS (the WCS zero is dt beyond it)
    assert [answer["reference_in_wcs"][a] for a in "XYZ"] == pytest.approx(-rotation(POSE_R).T @ dt, abs=1e-9)


def test_the_rotary_table_turns_the_truth():
    """A turned table places the part by −angle about the table centre (scene.workpiece_pose)."""
    m = machine(rot=(0.0, 0.0, POSE_R[2]), rotary_axes={"C": {"limits": [-360, 360]}},
                machine={"rotary_table": {"axis": "C", "center": [300, 200]}})
    m.goto({"C": 30.0})
    turn = rotation((0.0, 0.0, -30.0))
    centre = np.array([300.0, 200.0, 0.0])
    corner1 = turn @ (POSE_T - centre) + centre
    m.write_offset("G54", frame(corner1, (0.0, 0.0, POSE_R[2] - 30.0)))
    answer = m.setup_error("G54")
    assert max(abs(v) for v in answer["error"]["trans"].values()) < 1e-9
    assert max(abs(v) for v in answer["error"]["rot"].values()) < 1e-9


def test_unknown_offset_is_refused():
    with pytest.raises(ValueError, match="G59"):
        machine().setup_error("G59")

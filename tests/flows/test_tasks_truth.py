"""Noise-free end-to-end truth of every workpiece measuring task, through the JSON API only.

The probe is positioned like an operator (up, across, down) at start positions computed from
the scenario's pose; result keys (design.md §4) and the written zero offset are compared with
the truth computed here from the pose (truthkit), to 1e-6 mm / 1e-6 deg.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from truthkit import (
    BLOCK,
    BOSS_C,
    BOSS_H,
    BOSS_SIZE,
    HOLE_D,
    HOLES,
    POCKET_C,
    POCKET_SIZE,
    SPIGOT_D,
    SPIGOT_H,
    SPIGOTS,
    TOL_DEG,
    TOL_MM,
    Operator,
    Pose,
    angle_deg,
    angle_diff,
    scenario,
)

ROT_Z = 4.0
DEPTH = -10.0          # part z of edge/corner touches on the block's sides
POCKET_DEPTH = -8.0    # part z inside holes and the pocket
WORST: dict[str, float] = {}   # worst deviation per task (printed after the module)


def note(task: str, *deviations: float) -> None:
    WORST[task] = max(WORST.get(task, 0.0), *(abs(float(d)) for d in deviations))


@pytest.fixture(scope="module", autouse=True)
def _print_worst_deviations():
    """After this module's tests: the worst deviation per task (the report's figures; pytest -s)."""
    yield
    for name, dev in sorted(WORST.items()):
        print(f"{name:24s} {dev:.3g} mm")


def close(actual, expected, tol=TOL_MM, task: str | None = None):
    a, e = np.asarray(actual, float), np.asarray(expected, float)
    dev = float(np.max(np.abs(a - e))) if a.size else 0.0
    if task:
        note(task, dev)
    assert dev <= tol, f"{task}: {actual} != {expected} (dev {dev:.3g})"


def close_angle(actual, expected, period=360.0, task: str | None = None):
    dev = angle_diff(float(actual), float(expected), period)
    if task:
        note(task, dev)
    assert dev <= TOL_DEG, f"{task}: angle {actual} != {expected} (dev {dev:.3g})"


def xy(d: dict) -> list[float]:
    return [d["X"], d["Y"]]


@pytest.fixture
def op(client):
    operator = Operator(client, scenario(rot=(0.0, 0.0, ROT_Z)))
    operator.load()
    return operator


@pytest.fixture
def op_spigots(client):
    operator = Operator(client, scenario(rot=(0.0, 0.0, ROT_Z), kind="spigots"))
    operator.load()
    return operator


def part_g54(op: Operator, error=(1.3, -0.8, 3.5)):
    """G54 = the part's pose plus a translation error, activated: a G54 that holds a rotation."""
    pose = op.scen["workpiece"]["pose"]
    op.put_offset("G54", rot=pose["rot"], trans=np.add(pose["trans"], error))
    op.activate("G54")


def check_translation_only(op, before: Pose, after: Pose, task: str):
    close(after.R, before.R, TOL_DEG * math.pi / 180, task)


# --- holes and circular spigots ------------------------------------------------------------------

def hole_start(op, c, dx=0.6, dy=-0.4):
    return op.part.mcs(c[0] + dx, c[1] + dy, POCKET_DEPTH)


def spigot_start(op, c, dx=0.5, dy=0.3):
    return op.part.mcs(c[0] + dx, c[1] + dy, SPIGOT_H + 5.0)


SPIGOT_INFEED = 13.0     # ball centre 7 above the block top, 8 below the spigot's top


def test_hole1_measured_under_g500_into_g54_needs_setup_support(op):
    setpoint = {"X": 10.0, "Y": -5.0}
    ans = op.measure("hole.1", {"diameter": HOLE_D, "setpoint": setpoint}, [hole_start(op, HOLES[0])], "G54")
    centre = op.part.mcs(*HOLES[0], POCKET_DEPTH)
    close(xy(ans["result"]["center"]), centre[:2], task="hole.1")          # G500: WCS = MCS
    close(ans["result"]["diameter"], HOLE_D, task="hole.1")
    g54 = op.frame("G54")
    close(g54.to_child(centre)[:2], xy(setpoint), task="hole.1")
    close(g54.T[2], 0.0, task="hole.1")
    close(g54.R, np.eye(3), task="hole.1")
    assert ans["activated"] is False
    assert [r["code"] for r in ans["setup_support"]["reasons"]] == ["inactive_wo"]
    assert op.ok(op.c.get("/api/machine"))["active_offset"] == "G500"
    assert ans["correction"]["after"] == op.offset("G54")


def test_hole1_in_a_rotated_active_g54(op):
    part_g54(op)
    before = op.frame("G54")
    setpoint = {"X": 3.0, "Y": 2.0}
    ans = op.measure("hole.1", {"diameter": HOLE_D, "setpoint": setpoint}, [hole_start(op, HOLES[2])])
    centre = op.part.mcs(*HOLES[2], POCKET_DEPTH)
    close(xy(ans["result"]["center"]), before.to_child(centre)[:2], task="hole.1")
    close(ans["result"]["diameter"], HOLE_D, task="hole.1")
    assert ans["activated"] is True and ans["setup_support"] is None
    after = op.frame("G54")
    check_translation_only(op, before, after, "hole.1")
    close(after.to_child(centre)[:2], xy(setpoint), task="hole.1")
    close(after.to_child(centre)[2], before.to_child(centre)[2], task="hole.1")   # Z kept
    # activated: the WCS display follows the new G54
    wcs = op.ok(op.c.get("/api/machine"))["wcs"]
    close([wcs["X"], wcs["Y"], wcs["Z"]], after.to_child(op.ball_mcs()), task="hole.1")


@pytest.mark.parametrize("setpoint_angle", [0.0, 30.0])
def test_hole2_rotation_and_set_p1(op, setpoint_angle):
    op.activate("G54")
    setpoint = {"X": 5.0, "Y": 7.0}
    params = {"diameter": HOLE_D, "angle_correction": "rotation", "setpoint_angle": setpoint_angle,
              "set_p1": True, "setpoint": setpoint}
    ans = op.measure("hole.2", params, [hole_start(op, HOLES[0]), hole_start(op, HOLES[1], -0.5, 0.7)])
    p1, p2 = (op.part.mcs(*c, POCKET_DEPTH) for c in HOLES[:2])
    close_angle(ans["result"]["angle"], ROT_Z, task="hole.2")
    close(xy(ans["result"]["p1"]), p1[:2], task="hole.2")
    g54 = op.frame("G54")
    close(g54.to_child(p1)[:2], xy(setpoint), task="hole.2")
    close_angle(angle_deg(g54.to_child(p2) - g54.to_child(p1)), setpoint_angle, task="hole.2")
    close(g54.R[:, 2], [0, 0, 1], task="hole.2")
    assert ans["activated"] is True


def test_hole3_rotation_into_inactive_g55(op):
    setpoint, sa = {"X": -20.0, "Y": 15.0}, 12.0
    params = {"diameter": HOLE_D, "angle_correction": "rotation", "setpoint_angle": sa, "setpoint": setpoint}
    ans = op.measure("hole.3", params, [hole_start(op, c) for c in HOLES[:3]], "G55")
    p0 = op.part.mcs(100.0, 60.0, POCKET_DEPTH)          # circumcentre of a right triangle
    p1 = op.part.mcs(*HOLES[0], POCKET_DEPTH)
    close(xy(ans["result"]["center"]), p0[:2], task="hole.3")
    close_angle(ans["result"]["angle"], angle_deg(p1 - p0), task="hole.3")
    g55 = op.frame("G55")
    close(g55.to_child(p0)[:2], xy(setpoint), task="hole.3")
    close_angle(angle_deg(g55.to_child(p1) - g55.to_child(p0)), sa, task="hole.3")
    assert ans["setup_support"]["reasons"][0]["code"] == "inactive_wo"
    assert op.offset("G54") == op.offset("G56")            # nothing else written


def test_hole3_without_angle_correction_keeps_rotation(op):
    part_g54(op)
    before = op.frame("G54")
    ans = op.measure("hole.3", {"diameter": HOLE_D, "setpoint": {"X": 1.0, "Y": 2.0}},
                     [hole_start(op, c) for c in HOLES[1:]])
    p0 = op.part.mcs(100.0, 60.0, POCKET_DEPTH)          # circumcentre of P2..P4 of the pattern
    after = op.frame("G54")
    check_translation_only(op, before, after, "hole.3")
    close(after.to_child(p0)[:2], [1.0, 2.0], task="hole.3")
    close(xy(ans["result"]["center"]), before.to_child(p0)[:2], task="hole.3")


def test_hole4_rotation(op):
    op.activate("G54")
    sa = -3.0
    ans = op.measure("hole.4", {"diameter": HOLE_D, "angle_correction": "rotation", "setpoint_angle": sa,
                                "setpoint": {"X": 0.0, "Y": 0.0}}, [hole_start(op, c) for c in HOLES])
    p0 = op.part.mcs(100.0, 60.0, POCKET_DEPTH)
    p1, p2 = (op.part.mcs(*c, POCKET_DEPTH) for c in HOLES[:2])
    close(xy(ans["result"]["center"]), p0[:2], task="hole.4")
    close_angle(ans["result"]["angle"], ROT_Z, task="hole.4")
    g54 = op.frame("G54")
    close(g54.to_child(p0)[:2], [0.0, 0.0], task="hole.4")
    close_angle(angle_deg(g54.to_child(p2) - g54.to_child(p1)), sa, task="hole.4")


def test_spigot1_and_measure_only(op_spigots):
    op = op_spigots
    before = op.offset("G54")
    ans = op.measure("spigot.1", {"diameter": SPIGOT_D, "infeed": SPIGOT_INFEED},
                     [spigot_start(op, SPIGOTS[1])], "measure_only")
    centre = op.part.mcs(*SPIGOTS[1], 0.0)
    close(xy(ans["result"]["center"]), centre[:2], task="spigot.1")
    close(ans["result"]["diameter"], SPIGOT_D, task="spigot.1")
    assert op.offset("G54") == before and ans["activated"] is False


def test_spigot1_into_active_g54(op_spigots):
    op = op_spigots
    op.activate("G54")
    ans = op.measure("spigot.1", {"diameter": SPIGOT_D, "infeed": SPIGOT_INFEED, "setpoint": {"X": 2, "Y": 3}},
                     [spigot_start(op, SPIGOTS[0])])
    centre = op.part.mcs(*SPIGOTS[0], 0.0)
    close(op.frame("G54").to_child(centre)[:2], [2.0, 3.0], task="spigot.1")
    assert ans["activated"] is True


def test_spigot2_rotation(op_spigots):
    op = op_spigots
    op.activate("G54")
    ans = op.measure("spigot.2", {"diameter": SPIGOT_D, "infeed": SPIGOT_INFEED, "set_p1": True,
                                  "setpoint": {"X": 0, "Y": 0}},
                     [spigot_start(op, SPIGOTS[3]), spigot_start(op, SPIGOTS[2])])
    p1, p2 = (op.part.mcs(*c, 0.0) for c in (SPIGOTS[3], SPIGOTS[2]))
    close_angle(ans["result"]["angle"], ROT_Z, task="spigot.2")
    g54 = op.frame("G54")
    close(g54.to_child(p1)[:2], [0.0, 0.0], task="spigot.2")
    close_angle(angle_deg(g54.to_child(p2) - g54.to_child(p1)), 0.0, task="spigot.2")


def test_spigot3_into_basic_ref_under_a_rotated_g54(op_spigots):
    op = op_spigots
    part_g54(op)
    sa = 5.0
    ans = op.measure("spigot.3", {"diameter": SPIGOT_D, "infeed": SPIGOT_INFEED, "angle_correction": "rotation",
                                  "setpoint_angle": sa, "setpoint": {"X": 4, "Y": -6}},
                     [spigot_start(op, c) for c in SPIGOTS[:3]], "BASIC_REF")
    p0, p1 = op.part.mcs(100.0, 60.0, 0.0), op.part.mcs(*SPIGOTS[0], 0.0)
    ref = op.frame("BASIC_REF")            # setpoints hold in the WCS of BASIC_REF alone (G500)
    close(ref.to_child(p0)[:2], [4.0, -6.0], task="spigot.3")
    close_angle(angle_deg(ref.to_child(p1) - ref.to_child(p0)), sa, task="spigot.3")
    assert ans["activated"] is True
    # the active chain now holds BASIC_REF ∘ G54: the display follows
    wcs = op.ok(op.c.get("/api/machine"))["wcs"]
    close([wcs["X"], wcs["Y"], wcs["Z"]], op.wcs_pose("G54").to_child(op.ball_mcs()), task="spigot.3")


def test_spigot4_rotation(op_spigots):
    op = op_spigots
    op.activate("G54")
    ans = op.measure("spigot.4", {"diameter": SPIGOT_D, "infeed": SPIGOT_INFEED, "angle_correction": "rotation",
                                  "setpoint": {"X": 0, "Y": 0}}, [spigot_start(op, c) for c in SPIGOTS])
    p0 = op.part.mcs(100.0, 60.0, 0.0)
    p1, p2 = (op.part.mcs(*c, 0.0) for c in SPIGOTS[:2])
    close(xy(ans["result"]["center"]), p0[:2], task="spigot.4")
    g54 = op.frame("G54")
    close(g54.to_child(p0)[:2], [0.0, 0.0], task="spigot.4")
    close_angle(angle_deg(g54.to_child(p2) - g54.to_child(p1)), 0.0, task="spigot.4")


def test_hole2_rotary_axis_correction(client):
    op = Operator(client, scenario(rot=(0.0, 0.0, ROT_Z), rotary=True))
    op.load()
    op.put_offset("G54", trans=(1.0, 2.0, 3.0), extra={"C": 10.0})
    op.activate("G54")
    sa = 1.5
    ans = op.measure("hole.2", {"diameter": HOLE_D, "angle_correction": "C", "setpoint_angle": sa},
                     [hole_start(op, HOLES[0]), hole_start(op, HOLES[1])])
    after = op.offset("G54")
    close(after["trans"]["C"], 10.0 + ROT_Z - sa, task="hole.2")          # spec §11 Q8: + (measured − set)
    close([after["trans"][a] for a in "XYZ"], [1.0, 2.0, 3.0], task="hole.2")
    close([after["rot"][a] for a in "XYZ"], [0.0, 0.0, 0.0], task="hole.2")
    codes = [r["code"] for r in ans["setup_support"]["reasons"]]
    assert codes == ["rotary"] and ans["correction"]["rotary_axis"] == "C"
    close(ans["correction"]["rotary_move"], ROT_Z - sa, task="hole.2")


# --- in the aligned WCS: set edge, distance, pocket, rectangular spigot -----------------------------

EDGE_CASES = [   # axis, direction, start (part), the part coordinate of the face
    ("X", "+", (-8.0, 60.0, DEPTH), ("x", 0.0)),
    ("X", "-", (208.0, 60.0, DEPTH), ("x", BLOCK[0])),
    ("Y", "+", (100.0, -8.0, DEPTH), ("y", 0.0)),
    ("Y", "-", (100.0, 128.0, DEPTH), ("y", BLOCK[1])),
    ("Z", "-", (60.0, 20.0, 8.0), ("z", 0.0)),
]


@pytest.mark.parametrize("axis,direction,start,face", EDGE_CASES)
def test_edge_set_in_aligned_g54(op, axis, direction, start, face):
    part_g54(op)
    before = op.frame("G54")
    s = 12.5
    ans = op.measure("edge.set", {"axis": axis, "direction": direction, "setpoint": s},
                     [op.part.mcs(*start)])
    j = "XYZ".index(axis)
    on_face = list(start)
    on_face["xyz".index(face[0])] = face[1]
    p = op.part.mcs(*on_face)
    close(ans["result"]["position"][axis], before.to_child(p)[j], task="edge.set")
    after = op.frame("G54")
    check_translation_only(op, before, after, "edge.set")
    close(after.to_child(p)[j], s, task="edge.set")
    others = [k for k in range(3) if k != j]
    close(after.to_child(p)[others], before.to_child(p)[others], task="edge.set")
    assert ans["activated"] is True


def test_edge_set_z_under_g500_into_g54(op):
    ans = op.measure("edge.set", {"axis": "Z", "direction": "-", "setpoint": {"Z": -2.0}},
                     [op.part.mcs(60.0, 20.0, 8.0)], "G54")
    top = op.part.mcs(60.0, 20.0, 0.0)
    close(ans["result"]["position"]["Z"], top[2], task="edge.set")
    close(op.frame("G54").T, [0.0, 0.0, top[2] + 2.0], task="edge.set")


@pytest.mark.parametrize("case", ["web", "groove"])
def test_edge_distance(op, case):
    part_g54(op)
    before = op.frame("G54")
    if case == "web":
        params = {"axis": "X", "direction": "+", "direction_p2": "-", "setpoint": 4.0}
        starts = [(-8.0, 60.0, DEPTH), (208.0, 60.0, DEPTH)]
        distance, centre = BLOCK[0], op.part.mcs(100.0, 60.0, DEPTH)
    else:
        params = {"axis": "Y", "direction": "-", "direction_p2": "+", "setpoint": -1.0}
        starts = [(100.0, 58.0, POCKET_DEPTH), (100.0, 62.0, POCKET_DEPTH)]
        distance, centre = POCKET_SIZE[1], op.part.mcs(100.0, POCKET_C[1], POCKET_DEPTH)
    ans = op.measure("edge.distance", params, [op.part.mcs(*s) for s in starts])
    j = "XYZ".index(params["axis"])
    close(ans["result"]["distance"], distance, task="edge.distance")
    close(ans["result"]["center"][params["axis"]], before.to_child(centre)[j], task="edge.distance")
    after = op.frame("G54")
    check_translation_only(op, before, after, "edge.distance")
    close(after.to_child(centre)[j], params["setpoint"], task="edge.distance")


def test_pocket_rect(op):
    part_g54(op)
    before = op.frame("G54")
    ans = op.measure("pocket.rect", {"length": POCKET_SIZE[0], "width": POCKET_SIZE[1], "setpoint": {"X": 7, "Y": 8}},
                     [op.part.mcs(POCKET_C[0] + 1.1, POCKET_C[1] - 0.7, POCKET_DEPTH)])
    centre = op.part.mcs(*POCKET_C, POCKET_DEPTH)
    close(xy(ans["result"]["center"]), before.to_child(centre)[:2], task="pocket.rect")
    close([ans["result"]["length"], ans["result"]["width"]], POCKET_SIZE, task="pocket.rect")
    after = op.frame("G54")
    check_translation_only(op, before, after, "pocket.rect")
    close(after.to_child(centre)[:2], [7.0, 8.0], task="pocket.rect")


def test_spigot_rect(op_spigots):
    op = op_spigots
    part_g54(op)
    before = op.frame("G54")
    ans = op.measure("spigot.rect", {"length": BOSS_SIZE[0], "width": BOSS_SIZE[1], "infeed": 10.0,
                                     "setpoint": {"X": -3, "Y": 0}},
                     [op.part.mcs(BOSS_C[0] - 0.8, BOSS_C[1] + 0.5, BOSS_H + 5.0)])
    centre = op.part.mcs(*BOSS_C, 5.0)
    close(xy(ans["result"]["center"]), before.to_child(centre)[:2], task="spigot.rect")
    close([ans["result"]["length"], ans["result"]["width"]], BOSS_SIZE, task="spigot.rect")
    after = op.frame("G54")
    check_translation_only(op, before, after, "spigot.rect")
    close(after.to_child(centre)[:2], [-3.0, 0.0], task="spigot.rect")


# --- corners ------------------------------------------------------------------------------------

def corner_geometry(kind: str, position: int, n_points: int):
    """Start points (part) of P1..Pn and the corner (part) for ``kind``/``position``."""
    if kind == "outside":
        x0, x1, y0, y1, z, gap = 0.0, BLOCK[0], 0.0, BLOCK[1], DEPTH, -8.0
    else:
        (cx, cy), (lx, ly) = POCKET_C, POCKET_SIZE
        x0, x1, y0, y1, z, gap = cx - lx / 2, cx + lx / 2, cy - ly / 2, cy + ly / 2, POCKET_DEPTH, 6.0
    cxp = x0 if position in (1, 4) else x1          # corner's x, y
    cyp = y0 if position in (1, 2) else y1
    sx = 1.0 if position in (1, 4) else -1.0        # from the corner into the part
    sy = 1.0 if position in (1, 2) else -1.0
    along = (8.0, 22.0) if kind == "inside" else (20.0, 70.0)
    starts = [(cxp + sx * a, cyp + sy * gap, z) for a in along]               # P1, P2: edge ∥ X
    side = (8.0, 18.0) if kind == "inside" else (20.0, 60.0)
    starts += [(cxp + sx * gap, cyp + sy * a, z) for a in side[: n_points - 2]]   # P3 (P4): edge ∥ Y
    return starts, (cxp, cyp, z)


CORNERS = [(task, kind, pos) for task in ("corner.right", "corner.any")
           for kind in ("outside", "inside") for pos in (1, 2, 3, 4)]


@pytest.mark.parametrize("task,kind,position", CORNERS)
def test_corner(op, task, kind, position):
    setpoint = {"X": 0.0, "Y": 0.0} if position % 2 else {"X": -15.0, "Y": 6.5}
    op.put_offset("G54", trans=(0.0, 0.0, -7.0))
    op.activate("G54")
    before = op.frame("G54")
    starts, corner = corner_geometry(kind, position, 3 if task == "corner.right" else 4)
    ans = op.measure(task, {"kind": kind, "position": position, "setpoint": setpoint},
                     [op.part.mcs(*s) for s in starts])
    corner_mcs = op.part.mcs(*corner)
    close(xy(ans["result"]["corner"]), before.to_child(corner_mcs)[:2], task=task)
    close_angle(ans["result"]["angle"], ROT_Z, 180.0, task=task)
    after = op.frame("G54")
    close(after.to_child(corner_mcs)[:2], xy(setpoint), task=task)
    edge = after.dir_to_child(op.part.dir_mcs([1.0, 0.0, 0.0]))
    close(edge[1], 0.0, task=task)                                    # P1P2 ∥ X
    close(after.T[2], -7.0, task=task)                                # Z untouched
    assert ans["activated"] is True


# --- align edge, orient plane -----------------------------------------------------------------------

@pytest.mark.parametrize("axis,setpoint_angle", [("Y", 0.0), ("Y", 10.0), ("X", 0.0), ("X", -2.0)])
def test_edge_align(op, axis, setpoint_angle):
    op.put_offset("G54", trans=(5.0, 6.0, 7.0))
    op.activate("G54")
    if axis == "Y":          # front face, probing +Y, reference X
        starts, edge_dir = [(40.0, -8.0, DEPTH), (160.0, -8.0, DEPTH)], [1.0, 0.0, 0.0]
        ref = "X"
    else:                    # left face, probing +X, reference Y
        starts, edge_dir = [(-8.0, 20.0, DEPTH), (-8.0, 100.0, DEPTH)], [0.0, 1.0, 0.0]
        ref = "Y"
    params = {"axis": axis, "direction": "+", "reference_axis": ref, "angle_correction": "rotation",
              "setpoint_angle": setpoint_angle}
    ans = op.measure("edge.align", params, [op.part.mcs(*s) for s in starts])
    close_angle(ans["result"]["angle"], ROT_Z, 180.0, task="edge.align")
    after = op.frame("G54")
    d = after.dir_to_child(op.part.dir_mcs(edge_dir))
    measured = angle_deg(d) if axis == "Y" else angle_deg(d) - 90.0   # against the reference axis
    close_angle(measured, setpoint_angle, 180.0, task="edge.align")
    close(after.T, [5.0, 6.0, 7.0], task="edge.align")                # rotation about the WCS origin


@pytest.mark.parametrize("target", ["G54", "G56"])
def test_plane_align_tilted(client, target):
    tilt = (0.6, -0.4, ROT_Z)
    op = Operator(client, scenario(rot=tilt))
    op.load()
    op.put_offset("G54", trans=(2.0, 3.0, 4.0), rot=(0.0, 0.0, 1.0))
    op.activate("G54")
    before = op.frame("G54")
    starts = [op.part.mcs(x, y, 6.0) for x, y in ((60.0, 20.0), (150.0, 60.0), (60.0, 100.0))]
    ans = op.measure("plane.align", {}, starts, target)
    n = op.part.dir_mcs([0.0, 0.0, 1.0])
    n_wcs = before.dir_to_child(n)
    close(ans["result"]["alpha"], math.degrees(math.asin(-n_wcs[1])), TOL_DEG, task="plane.align")
    close(ans["result"]["beta"], math.degrees(math.atan2(n_wcs[0], n_wcs[2])), TOL_DEG, task="plane.align")
    after = op.frame(target)
    old = op.frame("G54") if target == "G54" else Pose()
    close(after.dir_to_child(n), [0.0, 0.0, 1.0], TOL_DEG * math.pi / 180, task="plane.align")
    close(after.T, old.T if target == "G56" else before.T, task="plane.align")   # translation kept
    codes = [r["code"] for r in ans["setup_support"]["reasons"]]
    assert "realign" in codes
    assert ("inactive_wo" in codes) == (target == "G56")

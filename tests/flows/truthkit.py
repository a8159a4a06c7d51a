"""Truth kit for the end-to-end measuring checks: scenarios, operator moves, independent truth.

Everything here is computed from the scenario pose with its own numpy (design.md §3: RPY
R = Rz(c)·Ry(b)·Rx(a), p_mcs = R·p_part + trans); nothing comes from ``engine``. The product is
driven only through the JSON API of design.md §4.
"""

from __future__ import annotations

import copy
import math

import numpy as np

PROBE_LENGTH = 100.0
BALL_D = 4.0
TOP_Z = -120.0                    # MCS z of the block's top face (part z = 0) at the pose origin
BLOCK = (200.0, 120.0, 60.0)
HOLE_D = 12.0
HOLES = ((30.0, 25.0), (170.0, 25.0), (170.0, 95.0), (30.0, 95.0))   # P1..P4 counter-clockwise
POCKET_C, POCKET_SIZE = (100.0, 60.0), (50.0, 30.0)
SPIGOT_D, SPIGOT_H = 16.0, 15.0
SPIGOTS = HOLES
BOSS_C, BOSS_SIZE, BOSS_H = (100.0, 60.0), (40.0, 24.0), 10.0
TOL_MM = 1e-6
TOL_DEG = 1e-6


# --- rotations (own implementation of design.md §3) -------------------------------------------

def rpy(rot_deg) -> np.ndarray:
    a, b, c = np.radians(np.asarray(rot_deg, dtype=float))
    rx = np.array([[1, 0, 0], [0, math.cos(a), -math.sin(a)], [0, math.sin(a), math.cos(a)]])
    ry = np.array([[math.cos(b), 0, math.sin(b)], [0, 1, 0], [-math.sin(b), 0, math.cos(b)]])
    rz = np.array([[math.cos(c), -math.sin(c), 0], [math.sin(c), math.cos(c), 0], [0, 0, 1]])
    return rz @ ry @ rx


class Pose:
    """A rigid map child -> parent: p_parent = R·p_child + T."""

    def __init__(self, rot=(0.0, 0.0, 0.0), trans=(0.0, 0.0, 0.0), matrix=None):
        self.R = rpy(rot) if matrix is None else np.asarray(matrix, float)
        self.T = np.asarray(trans, dtype=float)

    def to_parent(self, p) -> np.ndarray:
        return self.R @ np.asarray(p, float) + self.T

    def to_child(self, p) -> np.ndarray:
        return self.R.T @ (np.asarray(p, float) - self.T)

    def dir_to_child(self, d) -> np.ndarray:
        return self.R.T @ np.asarray(d, float)

    def dir_to_parent(self, d) -> np.ndarray:
        return self.R @ np.asarray(d, float)


def frame_of(api_frame: dict) -> Pose:
    """Pose of a stored frame ``{"trans", "fine", "rot"}`` (translation = coarse + fine)."""
    trans = api_frame.get("trans", {})
    fine = api_frame.get("fine") or {}
    t = [float(trans.get(a, 0.0)) + float(fine.get(a, 0.0)) for a in "XYZ"]
    rot = [float(api_frame.get("rot", {}).get(a, 0.0)) for a in "XYZ"]
    return Pose(rot, t)


def angle_deg(vec) -> float:
    return math.degrees(math.atan2(vec[1], vec[0]))


def angle_diff(a: float, b: float, period: float = 360.0) -> float:
    """Smallest |a - b| modulo ``period`` (an edge has no direction: period 180)."""
    d = (a - b) % period
    return min(d, period - d)


# --- scenarios -----------------------------------------------------------------------------------

def scenario(rot=(0.0, 0.0, 4.0), trans=(250.0, 150.0, TOP_Z), kind: str = "holes", *,
             latency: float = 0.0, pretravel: dict | None = None, eccentricity=(0.0, 0.0),
             rotary: bool = False) -> dict:
    """Noise-free scenario with a turned block. kind "holes": 4 holes + a pocket; "spigots":
    4 round spigots + a rectangular boss."""
    if kind == "holes":
        features = [{"type": "hole", "center": list(c), "diameter": HOLE_D, "depth": 25.0} for c in HOLES]
        features.append({"type": "pocket", "center": list(POCKET_C), "size": list(POCKET_SIZE), "depth": 15.0})
    else:
        features = [{"type": "spigot", "center": list(c), "diameter": SPIGOT_D, "height": SPIGOT_H}
                    for c in SPIGOTS]
        features.append({"type": "boss", "center": list(BOSS_C), "size": list(BOSS_SIZE), "height": BOSS_H})
    probe = {"t": 9, "ball_diameter": BALL_D, "length": PROBE_LENGTH, "max_deflection": 5.0,
             "eccentricity": list(eccentricity), "noise_sigma": 0.0}
    if pretravel:
        probe["pretravel"] = pretravel
    data = {
        "seed": 3,
        "machine": {"limits": {"X": [-10, 800], "Y": [-10, 500], "Z": [-400, 10]}, "rapid": 10000,
                    "latency_s": latency, "time_scale": 0},
        "probe": probe,
        "workpiece": {"pose": {"trans": list(trans), "rot": list(rot)},
                      "features": [{"type": "block", "size": list(BLOCK)}, *features]},
        "ring_gauge": {"center": [600, 100, -160], "diameter": 25.0, "height": 20},
        "tools": [{"t": 1, "type": 120, "length": 85.0, "radius": 5.0}],
        "start": {"X": 100.0, "Y": 100.0, "Z": 0.0},
    }
    if rotary:
        data["rotary_axes"] = {"C": {"limits": [-360, 360]}}
    return copy.deepcopy(data)


class Part:
    """The scenario's truth: part coordinates -> MCS."""

    def __init__(self, scen: dict):
        pose = scen["workpiece"]["pose"]
        self.pose = Pose(pose["rot"], pose["trans"])

    def mcs(self, x, y, z) -> np.ndarray:
        return self.pose.to_parent([x, y, z])

    def dir_mcs(self, d) -> np.ndarray:
        return self.pose.dir_to_parent(d)


# --- the operator --------------------------------------------------------------------------------

class Operator:
    """Drives the API like an operator: up, across, down; NC Start; Calculate."""

    def __init__(self, client, scen: dict):
        self.c = client
        self.scen = scen
        self.part = Part(scen)
        self.safe_z = TOP_Z + 27.0       # ball centre z above everything (spigots stand 15 high)

    # -- helpers
    def ok(self, response, status: int = 200):
        assert response.status_code == status, response.text
        return response.json()

    def load(self, scen: dict | None = None) -> None:
        if scen is not None:
            self.scen, self.part = scen, Part(scen)
        self.ok(self.c.post("/api/sim/scenario", json={**self.scen, "reset_data": True}))

    def ball_mcs(self) -> np.ndarray:
        mcs = self.ok(self.c.get("/api/machine"))["mcs"]
        return np.array([mcs["X"], mcs["Y"], mcs["Z"] - PROBE_LENGTH])

    def _goto_ball(self, p) -> None:
        self.ok(self.c.post("/api/machine/goto", json={"X": float(p[0]), "Y": float(p[1]),
                                                        "Z": float(p[2]) + PROBE_LENGTH, "coords": "MCS"}))

    def ball_to(self, p_mcs) -> None:
        """Up to the safe height, across, down to ``p_mcs`` (ball centre, MCS)."""
        p = np.asarray(p_mcs, float)
        here = self.ball_mcs()
        if np.allclose(here, p, atol=1e-9):
            return
        self._goto_ball([here[0], here[1], max(self.safe_z, here[2])])
        self._goto_ball([p[0], p[1], max(self.safe_z, here[2])])
        self._goto_ball(p)

    def ball_to_part(self, x, y, z) -> None:
        self.ball_to(self.part.mcs(x, y, z))

    def put_offset(self, name: str, rot=(0.0, 0.0, 0.0), trans=(0.0, 0.0, 0.0), extra: dict | None = None):
        body = {"trans": {a: float(v) for a, v in zip("XYZ", trans, strict=True)},
                "fine": {"X": 0.0, "Y": 0.0, "Z": 0.0},
                "rot": {a: float(v) for a, v in zip("XYZ", rot, strict=True)}}
        if extra:
            body["trans"].update(extra)
        return self.ok(self.c.put(f"/api/offsets/{name}", json=body))

    def offset(self, name: str) -> dict:
        return self.ok(self.c.get(f"/api/offsets/{name}"))

    def frame(self, name: str) -> Pose:
        return frame_of(self.offset(name))

    def activate(self, name: str) -> dict:
        return self.ok(self.c.post("/api/machine/activate", json={"offset": name}))

    def wcs_pose(self, settable: str | None = None) -> Pose:
        """WCS -> MCS of the chain BASIC_REF ∘ BASIC_0 ∘ BASIC_1 ∘ settable (own composition)."""
        chain = [self.frame(n) for n in ("BASIC_REF", "BASIC_0", "BASIC_1")]
        if settable is None:
            settable = self.ok(self.c.get("/api/machine"))["active_offset"]
        if settable != "G500":
            chain.append(self.frame(settable))
        R, T = np.eye(3), np.zeros(3)
        for f in chain:
            R, T = R @ f.R, R @ f.T + T
        return Pose(matrix=R, trans=T)

    # -- measuring
    def create(self, task: str, params: dict, target: str | None = None, status: int = 200) -> dict:
        body = {"task": task, "params": params}
        if target is not None:
            body["target"] = target
        return self.ok(self.c.post("/api/measure", json=body), status)

    def start(self, sid: str, status: int = 200, **body) -> dict:
        return self.ok(self.c.post(f"/api/measure/{sid}/start", json=body or None), status)

    def calculate(self, sid: str, status: int = 200) -> dict:
        return self.ok(self.c.post(f"/api/measure/{sid}/calculate"), status)

    def measure(self, task: str, params: dict, starts, target: str | None = None) -> dict:
        """Create the session, position at each start (ball centre, MCS) and NC Start; Calculate."""
        session = self.create(task, params, target)
        answer = None
        for p in starts:
            self.ball_to(p)
            answer = self.start(session["id"])
            assert answer["point"]["stored"], answer
        if len(starts) > 1:
            assert answer["session"]["can_calculate"], answer
            answer = self.calculate(session["id"])
        self.ball_to([*self.ball_mcs()[:2], self.safe_z])
        return answer

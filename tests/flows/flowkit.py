"""Helpers for end-to-end flows driven only through the JSON API, checked against scenario truth.

Positions are computed from the scenario (the operator sees the part and jogs the probe near
it); every measured number comes from the product. Motion goes up, across, then down: a rapid
through the part is a collision.
"""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path

import numpy as np
from fastapi.testclient import TestClient
from truthkit import rpy

SAFE_Z = -100.0      # G500 WCS Z of the ball centre above everything (spindle near MCS Z 0)

# design.md §4 example probe; the block turned about Z only (a corner + Z edge set-up measures
# translation and the rotation about the tool axis; a tilt would need plane.align).
CAL_SCENARIO = {
    "seed": 7,
    "machine": {"limits": {"X": [-10, 800], "Y": [-10, 500], "Z": [-400, 10]},
                "rapid": 10000, "jog_feed": 1000, "latency_s": 0.004, "decel": 1.0, "kv": 1.0,
                "time_scale": 0},
    "probe": {"t": 9, "ball_diameter": 4.0, "length": 100.0, "eccentricity": [0.010, -0.006],
              "nominal": {"length": 100.2, "ball_diameter": 4.0},
              "pretravel": {"X+": 0.004, "X-": 0.005, "Y+": 0.003, "Y-": 0.006, "Z-": 0.002},
              "noise_sigma": 0.0003, "max_deflection": 2.0},
    "workpiece": {"pose": {"trans": [250.0, 150.0, -120.0], "rot": [0.0, 0.0, 12.5]},
                  "features": [{"type": "block", "size": [200, 120, 60]}]},
    "ring_gauge": {"center": [600, 100, -150], "diameter": 25.0, "height": 20},
    "tool_probe": {"center": [700, 400, -200], "disc_diameter": 20.0},
    "tools": [{"t": 1, "length": 85.0, "radius": 5.0}],
    "start": {"X": 400.0, "Y": 300.0, "Z": 0.0},
}


def cal_scenario(**changes) -> dict:
    data = copy.deepcopy(CAL_SCENARIO)
    for dotted, value in changes.items():
        node = data
        *path, last = dotted.split("__")
        for key in path:
            node = node[key]
        node[last] = value
    return data


def make_client(tmp_path: Path, scenario: dict) -> TestClient:
    from app.config import Settings
    from app.main import create_app

    tmp_path.mkdir(parents=True, exist_ok=True)
    path = tmp_path / "scenario.json"
    path.write_text(json.dumps(scenario))
    return TestClient(create_app(Settings(db_path=tmp_path / "hmi.db", scenario_path=path, time_scale=0)))


def ok(response, status: int = 200) -> dict:
    assert response.status_code == status, response.text
    return response.json()


class Flow:
    """Operator actions through the JSON API."""

    def __init__(self, client: TestClient, scenario: dict):
        self.c = client
        self.sc = scenario

    # --- machine ----------------------------------------------------------------------------
    def activate(self, name: str) -> None:
        ok(self.c.post("/api/machine/activate", json={"offset": name}))

    def wcs(self) -> np.ndarray:
        w = ok(self.c.get("/api/machine"))["wcs"]
        return np.array([w["X"], w["Y"], w["Z"]], float)

    def goto(self, x=None, y=None, z=None) -> None:
        target = {k: float(v) for k, v in (("X", x), ("Y", y), ("Z", z)) if v is not None}
        ok(self.c.post("/api/machine/goto", json={**target, "coords": "WCS"}))

    def travel(self, x: float, y: float, z: float, safe_z: float = SAFE_Z) -> None:
        """Up to ``safe_z``, across, down (G500: WCS = BCS of the nominal ball centre)."""
        self.goto(z=max(safe_z, self.wcs()[2]))
        self.goto(x=x, y=y)
        self.goto(z=z)

    def override(self, percent: float) -> None:
        ok(self.c.put("/api/machine/override", json={"feed": percent}))

    # --- measuring --------------------------------------------------------------------------
    def create(self, task: str, params: dict, target: str | None = None, status: int = 200) -> dict:
        body = {"task": task, "params": params}
        if target:
            body["target"] = target
        return ok(self.c.post("/api/measure", json=body), status)

    def start(self, session_id: str, point: int | None = None, status: int = 200) -> dict:
        body = {} if point is None else {"point": point}
        return ok(self.c.post(f"/api/measure/{session_id}/start", json=body), status)

    def calculate(self, session_id: str) -> dict:
        return ok(self.c.post(f"/api/measure/{session_id}/calculate"))

    # --- truth ------------------------------------------------------------------------------
    def part_to_mcs(self, p) -> np.ndarray:
        pose = self.sc["workpiece"]["pose"]
        return rpy(pose["rot"]) @ np.asarray(p, float) + np.asarray(pose["trans"], float)

    def travel_part(self, p, safe_z: float = SAFE_Z) -> None:
        """Ball centre to part point ``p`` (G500 active), up-across-down."""
        m = self.part_to_mcs(p)
        self.travel(m[0], m[1], m[2], safe_z)

    # --- flows ------------------------------------------------------------------------------
    def calibrate_radius(self, diameter: float | None = None, miss=(0.3, -0.2), depth: float = 8.0) -> dict:
        """Ring gauge: ball near the centre (``miss`` mm off), ``depth`` below the top face."""
        ring = self.sc["ring_gauge"]
        cx, cy, top = ring["center"]
        self.activate("G500")
        self.travel(cx + miss[0], cy + miss[1], top - depth)
        session = self.create("probe.radius", {"diameter": diameter or ring["diameter"]})
        answer = self.start(session["id"])
        self.goto(z=SAFE_Z)
        return answer

    def calibrate_length(self, above: float = 4.0) -> dict:
        """On the ring gauge's top face, its height known in the MCS (= G500 WCS, no basic frame)."""
        ring = self.sc["ring_gauge"]
        cx, cy, top = ring["center"]
        r_mid = (ring["diameter"] / 2.0 + (ring.get("outer_diameter") or ring["diameter"] + 30) / 2.0) / 2.0
        self.activate("G500")
        self.travel(cx + r_mid, cy, top + above)
        session = self.create("probe.length", {"setpoint": top})
        answer = self.start(session["id"])
        self.goto(z=SAFE_Z)
        return answer

    def corner_and_z_setup(self, target: str = "G54", depth: float = 6.0) -> dict:
        """Outside corner, position 1 (front-left) + set edge Z− into ``target``; G500 positioning."""
        self.activate("G500")
        points = {1: (30.0, -12.0, -depth), 2: (150.0, -12.0, -depth), 3: (-12.0, 40.0, -depth)}
        session = self.create("corner.right", {"kind": "outside", "position": 1,
                                               "setpoint": {"X": 0.0, "Y": 0.0}}, target)
        for n in (1, 2):
            self.travel_part(points[n])
            self.start(session["id"], n)
        self.goto(z=SAFE_Z)
        self.travel_part(points[3])
        self.start(session["id"], 3)
        corner = self.calculate(session["id"])
        self.travel_part((40.0, 40.0, 5.0))          # above the top face
        session = self.create("edge.set", {"axis": "Z", "direction": "-", "setpoint": 0.0}, target)
        edge = self.start(session["id"])
        self.goto(z=SAFE_Z)
        self.activate(target)
        return {"corner": corner, "edge": edge}

    def offset_error(self, name: str = "G54") -> tuple[float, float, np.ndarray]:
        """(translation error mm, rotation error rad, per-axis translation error) against the pose."""
        frame = ok(self.c.get(f"/api/offsets/{name}"))
        trans = np.array([frame["trans"].get(a, 0.0) + (frame.get("fine") or {}).get(a, 0.0)
                          for a in "XYZ"], float)
        rot = np.array([frame["rot"].get(a, 0.0) for a in "XYZ"], float)
        pose = self.sc["workpiece"]["pose"]
        dt = trans - np.asarray(pose["trans"], float)
        r_err = rpy(rot).T @ rpy(pose["rot"])
        angle = math.acos(max(-1.0, min(1.0, (float(np.trace(r_err)) - 1.0) / 2.0)))
        return float(np.linalg.norm(dt)), angle, dt



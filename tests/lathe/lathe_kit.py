"""Helpers for the lathe tests: the scenario of turning.md §10.2 and an API driver.

Positions are set the way an operator pre-positions by hand: from the scenario's geometry (the
operator sees the part and the probes); every measured number comes from the product. Moves go
one axis at a time, clear of the part, the chuck, the grooves and the tool probe (a move
through them is a collision, 61302).
"""

from __future__ import annotations

import copy
import json
from pathlib import Path

from fastapi.testclient import TestClient

# turning.md §10.2's example truth (1-B, 2-A/2-B, 4-A, 5-C), at time_scale 0
LATHE_SCENARIO = {
    "seed": 3,
    "machine": {"kind": "lathe", "diameter_programming": True, "spos": True,
                "limits": {"X": [-50, 600], "Z": [-50, 800]}, "time_scale": 0},
    "spindle": {"angle": 0.0},
    "tools": [{"t": 7, "type": 500, "sl": 3, "l1": 10.0, "l2": 40.0, "radius": 5.0,
               "nominal": {"l1": 10.0, "l2": 40.0, "radius": 5.0}},
              {"t": 3, "type": 500, "sl": 3, "l1": 100.70, "l2": 60.30, "radius": 2.0,
               "nominal": {"l1": 100.65, "l2": 60.32, "radius": 2.0}},
              {"t": 1, "type": 500, "sl": 3, "l1": 60.0, "l2": 30.0, "radius": 0.8}],
    "probe": {"t": 8, "type": 580, "sl": 7, "l1": 40.119, "l2": 100.456, "ball_diameter": 5.99,
              "pretravel": {"X+": 0.0, "X-": 0.0, "Z-": 0.0}, "noise_sigma": 0.0,
              "nominal": {"l1": 40.123, "l2": 100.456, "ball_diameter": 6.0}},
    "tool_probe": {"faces": {"Z-": 220.35, "Z+": 199.65, "X-": 400.25, "X+": 379.80},
                   "pretravel": 0.0, "max_deflection": 1.0},
    "grooves": [{"sl7": {"x_minus": 50.054, "x_plus": 60.123, "bottom_z": 15.021, "top_z": 25.021, "wall": 5.0},
                 "sl8": {"z_minus": 10.0, "z_plus": 20.0, "top_x": 120.0, "bottom_x": 110.0, "wall": 5.0}}],
    "workpiece": {"chuck_face_z": 0.0, "eccentricity": [0.030, 0.0], "face_runout_deg": 0.0,
                  "profile": [{"type": "cylinder", "z": [0, 60], "diameter": 45.006},
                              {"type": "bore", "z": [20, 60], "diameter": 35.004}]},
}
TRUE_FACES = LATHE_SCENARIO["tool_probe"]["faces"]
SAFE = {"X": 600.0, "Z": 800.0}           # turret retracted (MCS of F)


def lathe_scenario(**changes) -> dict:
    """A copy with ``a__b__c=value`` changes (list items by index)."""
    data = copy.deepcopy(LATHE_SCENARIO)
    for dotted, value in changes.items():
        node = data
        *path, last = dotted.split("__")
        for key in path:
            node = node[int(key)] if isinstance(node, list) else node[key]
        if isinstance(node, list):
            node[int(last)] = value
        else:
            node[last] = value
    return data


def make_client(tmp_path: Path, scenario: dict | None = None) -> TestClient:
    from app.config import Settings
    from app.main import create_app

    tmp_path.mkdir(parents=True, exist_ok=True)
    path = tmp_path / "lathe.json"
    path.write_text(json.dumps(scenario or LATHE_SCENARIO))
    return TestClient(create_app(Settings(db_path=tmp_path / "hmi.db", scenario_path=path, time_scale=0)))


class Lathe:
    """The JSON API of a lathe HMI, as an operator's hands: tool change, moves, tasks."""

    def __init__(self, client: TestClient, scenario: dict | None = None):
        self.c = client
        self.scenario = scenario or LATHE_SCENARIO

    def ok(self, response, code: int = 200) -> dict:
        assert response.status_code == code, response.text
        return response.json()

    def status(self) -> dict:
        return self.ok(self.c.get("/api/machine"))

    def tool(self, t: int) -> dict:
        return self.ok(self.c.post("/api/machine/tool", json={"tool": t}))

    def goto(self, coords: str = "MCS", **axes) -> dict:
        """One move per call; give one axis to stay clear of things."""
        return self.ok(self.c.post("/api/machine/goto", json={**axes, "coords": coords}))

    def retract(self) -> None:
        """Away from everything: first Z (out of a groove, off a face), then X, then Z."""
        self.goto(Z=SAFE["Z"])
        self.goto(X=SAFE["X"])

    def lengths(self, t: int) -> tuple[float, float]:
        row = self.ok(self.c.get(f"/api/tools/{t}"))
        wear = row["wear"]
        return row["l1"] + wear.get("l1", 0.0), row["l2"] + wear.get("l2", 0.0)

    def tip_to(self, t: int, x: float, z: float) -> None:
        """The tool's NC tip (from the stored lengths) to MCS (x, z): Z first, then X (retracted first)."""
        l1, l2 = self.lengths(t)
        self.retract()
        self.goto(Z=z + l2)
        self.goto(X=x + l1)

    def task(self, name: str, params: dict, target=None, code: int = 200) -> dict:
        body = {"task": name, "params": params}
        if target is not None:
            body["target"] = target
        session = self.ok(self.c.post("/api/measure", json=body))
        answer = self.c.post(f"/api/measure/{session['id']}/start", json={})
        return self.ok(answer, code)

    def spos(self, angle: float) -> dict:
        return self.ok(self.c.post("/api/lathe/spos", json={"angle": angle}))

    # --- the standard set-ups ------------------------------------------------------------------
    def calibrate_tool_probe(self, fa: float = 1.0, tsa: float = 1.0) -> dict:
        """The four faces with the calibration tool T7 (1-B's order −X, −Z, +X, +Z)."""
        self.tool(7)
        params = {"measuring_path": fa, "tolerance": {"safe_area": tsa}}
        out = {}
        self.tip_to(7, 420.0, 240.0)
        out["X-"] = self.task("lathe.toolprobe.calibrate", {"axis": "X", **params})
        self.tip_to(7, 420.0, 240.0)
        out["Z-"] = self.task("lathe.toolprobe.calibrate", {"axis": "Z", **params})
        self.tip_to(7, 420.0, 240.0)
        self.goto(X=350.0 + 10.0)                          # down beside the probe (right of it)
        out["X+"] = self.task("lathe.toolprobe.calibrate", {"axis": "X", **params})
        self.goto(Z=170.0 + 40.0)                          # below the probe to its left
        self.goto(X=420.0 + 10.0)
        out["Z+"] = self.task("lathe.toolprobe.calibrate", {"axis": "Z", **params})
        self.goto(X=420.0 + 10.0)                          # up, above the probe, before retracting right
        self.retract()
        return out

    def ball_to(self, x: float, z: float, coords: str = "MCS") -> None:
        """The probe's NC ball centre to (x radius, z): retract, Z, then X (MCS), or in the WCS
        (x a diameter with DIAMON)."""
        self.retract()
        if coords == "MCS":
            l1, l2 = self.lengths(self.scenario["probe"]["t"])
            self.goto(Z=z + l2)
            self.goto(X=x + l1)
        else:
            self.goto(coords="WCS", Z=z)
            self.goto(coords="WCS", X=x)

    def calibrate_probe_in_groove(self, fa: float = 2.0) -> dict:
        """The probe T8 in groove 1: X both directions with skew and ball diameter, then −Z (4-A)."""
        self.tool(self.scenario["probe"]["t"])
        params = {"groove": {"number": 1}, "measuring_path": fa, "tolerance": {"safe_area": 4.0}}
        self.ball_to(80.0, 40.0)
        x = self.task("lathe.probe.groove", {**params, "axis": "X", "direction": "both", "skew": True,
                                             "ball_diameter": True})
        self.ball_to(80.0, 40.0)
        z = self.task("lathe.probe.groove", {**params, "axis": "Z", "direction": "-"})
        self.retract()
        return {"X": x, "Z": z}

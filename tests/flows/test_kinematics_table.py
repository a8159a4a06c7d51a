"""Rotary table kinematics and the kinematic-data API (issue 33, design.md §10.6).

The table's true axis line is off the nominal vertical through ``center`` by tens of µm / µrad;
``kinematics.measure`` on a sphere standing on the table must find it (truth = the scenario's line,
compared by this file's own geometry). PUT /api/kinematics: bad input names the field and changes
nothing; a write is audited and an undo restores the nominal."""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_chain_truth import make_client, post

TRUE_C = {"point": [300.03, 199.98, 0.0], "direction": [20e-6, -30e-6, 1.0]}
SPHERE = (380.0, 200.0, -150.0)            # MCS at table 0 (a sphere alone on the table)


def table_scenario() -> dict:
    return {
        "seed": 5,
        "machine": {"limits": {"X": [-10, 800], "Y": [-10, 500], "Z": [-400, 10]}, "latency_s": 0.0,
                    "time_scale": 0, "rotary_table": {"axis": "C", "center": [300, 200], "true": {"C": TRUE_C}}},
        "rotary_axes": {"C": {"limits": [-360, 360]}},
        "probe": {"t": 9, "ball_diameter": 4.0, "length": 100.0, "noise_sigma": 0.0003},
        "workpiece": {"pose": {"trans": list(SPHERE), "rot": [0, 0, 0]},
                      "features": [{"type": "sphere", "center": [0, 0, 0], "diameter": 25.0}]},
        "start": {"X": 380.0, "Y": 200.0, "Z": 0.0},
    }


def test_table_axis_within_2um_10urad_of_the_truth(tmp_path):
    with make_client(tmp_path, table_scenario()) as client:
        assert client.get("/api/kinematics").json()["C"]["unit"] == "table"
        session = post(client, "/api/measure", {"task": "kinematics.measure", "params": {
            "sphere": {"center": list(SPHERE), "diameter": 25.0}, "axis": "C",
            "positions": [0, 60, 120, 180, 240, 300], "mode": "optimise"}})
        for _ in session["points"]:
            post(client, f"/api/measure/{session['id']}/start")
        result = post(client, f"/api/measure/{session['id']}/calculate")["result"]
        line = result["axes"]["C"]
        p, d = np.array(line["point"]), np.array(line["direction"])
        tp, td = np.array(TRUE_C["point"]), np.array(TRUE_C["direction"]) / np.linalg.norm(TRUE_C["direction"])
        off = tp - p
        distance = float(np.linalg.norm(off - (off @ d) * d))
        angle = math.atan2(float(np.linalg.norm(np.cross(d, td))), float(d @ td))
        print(f"table C: line {distance * 1000:.3f} um, direction {angle * 1e6:.2f} urad")
        assert distance < 0.002 and angle < 10e-6
        assert result["deviation"]["C"]["offset"] == pytest.approx(math.hypot(0.03, 0.02), abs=0.002)
        stored = client.get("/api/kinematics").json()["C"]
        assert np.allclose(stored["point"], line["point"]) and np.allclose(stored["direction"], line["direction"])
        assert client.get("/api/machine").json()["mcs"]["C"] == 0.0


def test_put_kinematics_validates_audits_and_undoes(tmp_path):
    with make_client(tmp_path, table_scenario()) as client:
        before = client.get("/api/kinematics").json()
        for body, field in (({"A": {"point": [0, 0, 0]}}, "A"),
                            ({"C": {"direction": [0, 0, 0]}}, "C.direction"),
                            ({"C": {"point": [0, "x", 0]}}, "C.point"),
                            ({"C": {"point": [0, 0]}}, "C.point")):
            r = client.put("/api/kinematics", json=body)
            assert r.status_code == 422 and r.json()["error"]["field"] == field, r.text
        assert client.get("/api/kinematics").json() == before
        r = client.put("/api/kinematics", json={"C": {"point": [300.01, 200.0, 0.0], "direction": [0, 0, 2.0]}})
        assert r.status_code == 200 and r.json()["C"]["direction"] == [0.0, 0.0, 1.0]
        audit = client.get("/api/audit", params={"kind": "kinematics"}).json()
        assert audit[0]["before"]["C"]["point"] == [300.0, 200.0, 0.0]
        undone = client.post(f"/api/audit/{audit[0]['id']}/undo", json={})
        assert undone.status_code == 200, undone.text
        assert client.get("/api/kinematics").json()["C"]["point"] == [300.0, 200.0, 0.0]

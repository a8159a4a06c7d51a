"""Trainer mode through the API: the hidden scene and the simulator's set-up error.

Truth: the test scenario's pose (part corner 1 at MCS (250, 150, −120), not rotated) and its probe
(eccentricity and a nominal length that differ from the truth)."""

from __future__ import annotations

import pytest
from hmi_testdata import BLOCK_TOP_Z, test_scenario

CORNER1 = {"X": 250.0, "Y": 150.0, "Z": BLOCK_TOP_Z}
ECC = (0.012, -0.007)
NOMINAL_L, TRUE_L = 100.3, 100.0


def trainer_scenario() -> dict:
    s = test_scenario()
    s["probe"] = {**s["probe"], "eccentricity": list(ECC), "nominal": {"length": NOMINAL_L, "ball_diameter": 4.0}}
    return s


@pytest.fixture
def trainer(client):
    assert client.post("/api/sim/scenario", json={**trainer_scenario(), "reset_data": True}).status_code == 200
    assert client.put("/api/settings", json={"trainer_hide_part": True}).status_code == 200
    return client


def test_a_known_error_written_into_g54_is_the_reported_error(trainer):
    delta = {"X": 0.013, "Y": -0.021, "Z": 0.004}
    frame = {"trans": {a: CORNER1[a] + delta[a] for a in "XYZ"}, "rot": {"X": 0.0, "Y": 0.0, "Z": 0.01}}
    assert trainer.put("/api/offsets/G54", json=frame).status_code == 200
    assert trainer.post("/api/machine/activate", json={"offset": "G54"}).status_code == 200
    answer = trainer.get("/api/sim/setup-error").json()          # default: the active WO
    assert answer["offset"] == "G54"
    assert answer["reference"].startswith("corner 1")
    assert answer["error"]["trans"] == pytest.approx(delta, abs=1e-9)
    assert answer["error"]["rot"] == pytest.approx({"X": 0.0, "Y": 0.0, "Z": 0.01}, abs=1e-9)


def test_setup_error_needs_a_zero_offset(trainer):
    response = trainer.get("/api/sim/setup-error")                # G500 is active
    assert response.status_code == 422
    assert response.json()["error"]["field"] == "offset"
    response = trainer.get("/api/sim/setup-error", params={"offset": "G99"})
    assert response.status_code == 422 and "G99" in response.json()["error"]["message"]


def test_hidden_scene_has_no_part_and_the_probe_where_the_nc_puts_it(trainer):
    scene = trainer.get("/api/machine/scene").json()
    assert scene["hidden"] is True
    assert scene["block"] is None and scene["rects"] == [] and scene["spheres"] == []
    assert {c["kind"] for c in scene["circles"]} == {"ring_bore", "ring_outer", "tool_probe"}
    mcs = trainer.get("/api/machine").json()["mcs"]
    nc_tip = [mcs["X"], mcs["Y"], mcs["Z"] - NOMINAL_L]
    true_tip = [mcs["X"] + ECC[0], mcs["Y"] + ECC[1], mcs["Z"] - TRUE_L]
    assert scene["probe"]["tip"] == pytest.approx(nc_tip, abs=1e-9)
    assert scene["probe"]["tip"] != pytest.approx(true_tip, abs=1e-3)


def test_without_trainer_mode_the_scene_is_the_truth(client):
    assert client.post("/api/sim/scenario", json={**trainer_scenario(), "reset_data": True}).status_code == 200
    scene = client.get("/api/machine/scene").json()
    assert scene["hidden"] is False and scene["block"] is not None
    mcs = client.get("/api/machine").json()["mcs"]
    assert scene["probe"]["tip"] == pytest.approx([mcs["X"] + ECC[0], mcs["Y"] + ECC[1], mcs["Z"] - TRUE_L],
                                                  abs=1e-9)

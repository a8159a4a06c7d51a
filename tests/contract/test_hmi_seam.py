"""The HMI side of the seam: it calls only the ``Machine`` Protocol, asks before the optional
interfaces, names its controller, and writes what it stores to the NC (design.md §9.6)."""

from __future__ import annotations

import pytest
from fastapi.testclient import TestClient

from app.config import Settings
from app.machine import registry
from app.machine.protocol import Machine, SimulatorControl, SwivelHead
from app.main import create_app


def _error(response, status: int, code: str) -> dict:
    assert response.status_code == status, response.text
    error = response.json()["error"]
    assert error["code"] == code and error["message"]
    return error


@pytest.fixture
def bare_app(tmp_path, scenario_file, monkeypatch):
    """The app on a controller that offers the Protocol and nothing else."""
    monkeypatch.setitem(registry.MACHINES, "bare", "bare_controller:BareController")
    return create_app(Settings(db_path=tmp_path / "hmi.db", scenario_path=scenario_file, machine="bare"))


@pytest.fixture
def bare(bare_app):
    with TestClient(bare_app) as test_client:
        yield test_client


def _nc_frame(frame: dict, axes) -> dict:
    return {part: {a: v for a, v in frame[part].items() if a in axes} for part in ("trans", "fine", "rot")}


def _nc_tool(tool: dict) -> dict:
    return {k: tool[k] for k in ("type", "length", "radius", "wear")}


# --- the controller ---------------------------------------------------------------------------
def test_the_simulator_is_the_default_controller(app, client):
    assert client.get("/api/machine").json()["controller"] == "sim"
    sim = app.state.services.machine.machine
    assert isinstance(sim, Machine) and isinstance(sim, SwivelHead) and isinstance(sim, SimulatorControl)


def test_the_hmi_runs_on_a_controller_with_the_protocol_only(bare_app, bare):
    controller = bare_app.state.services.machine.machine
    assert isinstance(controller, Machine)
    assert not isinstance(controller, SwivelHead) and not isinstance(controller, SimulatorControl)
    state = bare.get("/api/machine").json()
    assert state["controller"] == "bare" and state["swivel"] is False and state["tool"] == 9
    moved = bare.post("/api/machine/jog", json={"axis": "X", "distance": 5.0})
    assert moved.status_code == 200 and moved.json()["mcs"]["X"] == pytest.approx(state["mcs"]["X"] + 5.0)
    assert bare.put("/api/offsets/G54", json={"trans": {"X": 1.0}}).status_code == 200
    assert bare.post("/api/machine/activate", json={"offset": "G54"}).json()["active_offset"] == "G54"
    assert bare.put("/api/tools/1", json={"length": 85.5}).status_code == 200
    assert bare.post("/api/machine/tool", json={"tool": 1}).json()["tool_length"] == pytest.approx(85.5)
    assert bare.post("/api/machine/reset").status_code == 200


def test_simulator_only_calls_answer_409_not_simulated(bare):
    from hmi_testdata import test_scenario

    before = bare.get("/api/machine").json()
    _error(bare.post("/api/sim/scenario", json=test_scenario()), 409, "not_simulated")
    _error(bare.get("/api/machine/scene"), 409, "not_simulated")
    _error(bare.get("/machine-view"), 409, "not_simulated")
    assert bare.get("/api/machine").json() == before


# --- the NC holds what the HMI stored ---------------------------------------------------------
def test_every_stored_offset_and_tool_is_on_the_nc_from_the_start(app, client):
    sim = app.state.services.machine.machine
    axes = sim.axes
    stored = client.get("/api/offsets").json()
    assert sim.nc_offsets == {name: _nc_frame(frame, axes) for name, frame in stored.items()}
    assert sim.nc_tools == {tool["t"]: _nc_tool(tool) for tool in client.get("/api/tools").json()}


def test_writes_reach_the_nc_after_the_database(app, client):
    sim = app.state.services.machine.machine
    after = client.put("/api/offsets/G55", json={"trans": {"X": 12.5}, "rot": {"Z": 3.0}}).json()
    assert sim.nc_offsets["G55"] == _nc_frame(after, sim.axes)
    tool = client.put("/api/tools/1", json={"length": 86.0, "wear": {"radius": 0.02}}).json()
    assert sim.nc_tools[1] == _nc_tool(tool)
    new = client.put("/api/tools/7", json={"type": 200, "length": 70.0, "radius": 3.0}).json()
    assert sim.nc_tools[7] == _nc_tool(new)
    refused = client.put("/api/offsets/G55", json={"trans": {"X": "far"}})
    assert refused.status_code == 422
    assert sim.nc_offsets["G55"] == _nc_frame(after, sim.axes)     # nothing stored, nothing sent


def test_a_scenario_load_writes_the_stored_data_to_the_fresh_nc(app, client):
    from hmi_testdata import test_scenario

    client.put("/api/offsets/G54", json={"trans": {"Y": -4.0}})
    assert client.post("/api/sim/scenario", json=test_scenario()).status_code == 200
    sim = app.state.services.machine.machine
    assert sim.nc_offsets["G54"]["trans"]["Y"] == -4.0
    assert set(sim.nc_tools) == {tool["t"] for tool in client.get("/api/tools").json()}


def test_a_measurement_writes_its_correction_to_the_nc(app, client):
    """edge.set on the test block's left face (X = 250) writes G54; the NC holds the new frame."""
    for target in ({"Z": 0.0}, {"X": 240.0, "Y": 200.0}, {"Z": -30.0}):      # ball 10 mm before the face
        assert client.post("/api/machine/goto", json={**target, "coords": "MCS"}).status_code == 200
    session = client.post("/api/measure", json={"task": "edge.set", "target": "G54",
                                                "params": {"axis": "X", "direction": "+", "setpoint": {"X": 0.0}}})
    assert session.status_code == 200, session.text
    answer = client.post(f"/api/measure/{session.json()['id']}/start")
    assert answer.status_code == 200, answer.text
    stored = client.get("/api/offsets/G54").json()
    assert stored["trans"]["X"] == pytest.approx(250.0, abs=1e-6)
    assert app.state.services.machine.machine.nc_offsets["G54"] == _nc_frame(stored, ("X", "Y", "Z"))

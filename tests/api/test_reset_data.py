"""reset_data (POST /api/sim/scenario) clears the stored machine data the same way on the mill and
on the lathe (app/services/data_reset.py): the operator's extra tool, the written zero offset, the
probe and tool-probe records and the tool in the spindle go; the scenario's nominal data come back."""

from __future__ import annotations

import sys
from pathlib import Path

from hmi_testdata import TEST_SCENARIO

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "lathe"))
from lathe_kit import LATHE_SCENARIO, make_client  # noqa: E402

EXTRA_TOOL = 77
G54 = {"trans": {"X": 12.5, "Y": -3.25, "Z": 40.0}, "fine": {}, "rot": {}}


def _dirty(client, tool: dict, spindle: int) -> None:
    """The operator's data: an extra tool, G54 written, probe record 3 and tool-probe record 2, the
    scenario's tool ``spindle`` in the spindle."""
    assert client.put(f"/api/tools/{EXTRA_TOOL}", json=tool).status_code == 200
    assert client.put("/api/offsets/G54", json=G54).status_code == 200
    assert client.put("/api/probes/3", json={"number": 3, "ball_diameter": 3.0}).status_code == 200
    assert client.put("/api/tool-probes/2", json={"number": 2, "disc_diameter": 12.0}).status_code == 200
    assert client.post("/api/machine/tool", json={"tool": spindle}).status_code == 200, client.post(
        "/api/machine/tool", json={"tool": spindle}).text
    assert client.get("/api/machine").json()["tool"] == spindle


def _assert_clean(client, scenario_tools: set[int], spindle_at_start) -> None:
    tools = {row["t"] for row in client.get("/api/tools").json()}
    assert EXTRA_TOOL not in tools and scenario_tools <= tools
    g54 = client.get("/api/offsets/G54").json()
    assert all(not v for part in ("trans", "fine", "rot") for v in (g54.get(part) or {}).values())
    assert client.get("/api/probes/3").json().get("ball_diameter") in (None, 4.0)   # empty: the record's default
    assert not client.get("/api/tool-probes/2").json().get("disc_diameter")
    assert client.get("/api/machine").json()["tool"] == spindle_at_start     # the scenario's, not the operator's


def _other_tool(client, tools: list[int]) -> int:
    start = client.get("/api/machine").json()["tool"]
    return next(t for t in tools if t != start)


def test_reset_data_clears_the_mill(client):
    at_start = client.get("/api/machine").json()["tool"]
    tools = [TEST_SCENARIO["probe"]["t"], *(t["t"] for t in TEST_SCENARIO.get("tools", []))]
    _dirty(client, {"type": 120, "length": 80.0, "radius": 4.0}, _other_tool(client, tools))
    assert client.post("/api/sim/scenario", json={**TEST_SCENARIO, "reset_data": True}).status_code == 200
    _assert_clean(client, {TEST_SCENARIO["probe"]["t"]}, at_start)


def test_reset_data_clears_the_lathe(tmp_path):
    with make_client(tmp_path) as client:
        at_start = client.get("/api/machine").json()["tool"]
        tools = [LATHE_SCENARIO["probe"]["t"], *(t["t"] for t in LATHE_SCENARIO["tools"])]
        _dirty(client, {"type": 500, "sl": 3, "length": 0.0, "l1": 30.0, "l2": 50.0, "radius": 0.4},
               _other_tool(client, tools))
        assert client.post("/api/sim/scenario", json={**LATHE_SCENARIO, "reset_data": True}).status_code == 200
        _assert_clean(client, set(tools), at_start)

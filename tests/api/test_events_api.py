"""GET /api/events: server-sent events with the machine state and session changes (design.md §9.9).

Read as a client reads them: the stream's lines parsed into events, over TestClient (time_scale 0)
and over a real uvicorn server with httpx while the machine moves at real speed.
"""

from __future__ import annotations

import json
import threading
import time

import httpx
import pytest
from hmi_testdata import PROBE_LENGTH, TEST_SCENARIO, test_scenario


def read_events(lines, count: int, until_s: float | None = None) -> list[tuple[str, dict, float]]:
    """``(event, data, received_at)`` of the first ``count`` events of an SSE line stream."""
    events, name, data = [], None, []
    deadline = None if until_s is None else time.monotonic() + until_s
    for line in lines:
        if line.startswith("event:"):
            name = line[6:].strip()
        elif line.startswith("data:"):
            data.append(line[5:].strip())
        elif line == "" and data:
            events.append((name or "message", json.loads("\n".join(data)), time.monotonic()))
            name, data = None, []
            if len(events) >= count or (deadline is not None and time.monotonic() > deadline):
                break
    return events


def test_the_stream_starts_with_the_machine_state_and_the_session(client):
    with client.stream("GET", "/api/events", params={"limit": 2}) as response:
        assert response.status_code == 200
        assert response.headers["content-type"].startswith("text/event-stream")
        events = read_events(response.iter_lines(), 2)
    kinds = {name: data for name, data, _ in events}
    machine = kinds["machine"]
    start = TEST_SCENARIO["start"]
    assert machine["mcs"] == start                          # the scenario's start position
    # G500, no frames: the WCS is the probe tip, the axes less the probe length along Z
    assert machine["wcs"] == {"X": start["X"], "Y": start["Y"], "Z": start["Z"] - PROBE_LENGTH}
    assert machine["busy"] is False and machine["alarms"] == []
    assert kinds["session"] == {"id": None, "seq": kinds["session"]["seq"]}
    assert sorted(d["seq"] for _, d, _ in events) == [1, 2]


def test_a_new_session_and_an_alarm_with_its_remedy_are_streamed(client):
    client.post("/api/machine/goto", json={"X": 0.0, "Y": 0.0, "Z": -100.0, "coords": "MCS"})   # in air
    session = client.post("/api/measure", json={"task": "edge.set", "params": {"axis": "X", "direction": "+"},
                                                "target": "measure_only"}).json()
    assert client.post(f"/api/measure/{session['id']}/start").status_code == 409          # nothing touched
    with client.stream("GET", "/api/events", params={"limit": 2}) as response:
        events = dict((name, data) for name, data, _ in read_events(response.iter_lines(), 2))
    assert events["session"]["id"] == session["id"] and events["session"]["alarm"]["code"] == 61301
    alarm = events["machine"]["alarms"][-1]
    # the manual's remedy for 61301 (seed 001 §11: check the measuring input, the path, the probe)
    assert alarm["code"] == 61301 and "measuring input" in alarm["remedy"]
    assert "measuring path" in alarm["remedy"]


def test_a_bad_limit_is_refused_naming_the_field(client):
    response = client.get("/api/events", params={"limit": 0})
    assert response.status_code == 422
    assert response.json()["error"]["field"] == "limit"


@pytest.fixture
def real_time_api(api):
    scenario = test_scenario()
    scenario["machine"]["time_scale"] = 1.0
    assert api.post("/api/sim/scenario", json={**scenario, "reset_data": True}).status_code == 200
    yield api
    api.post("/api/machine/stop")


def test_more_than_ten_states_a_second_while_moving(live_server, real_time_api):
    """A held continuous jog (renewed every 0.15 s) at the scenario's jog feed of 1000 mm/min."""
    holding = threading.Event()
    holding.set()

    def hold():
        with httpx.Client(base_url=live_server, timeout=5) as http:
            while holding.is_set():
                http.post("/api/machine/jog/continuous", json={"axis": "Y", "direction": 1})
                time.sleep(0.15)

    renewer = threading.Thread(target=hold, daemon=True)
    with httpx.Client(base_url=live_server, timeout=5) as http, http.stream("GET", "/api/events") as response:
        renewer.start()
        try:
            events = read_events(response.iter_lines(), 200, until_s=1.5)
        finally:
            holding.clear()
            renewer.join(timeout=2)
    moving = [(data, at) for name, data, at in events if name == "machine" and data["busy"]]
    assert len(moving) >= 10
    span = moving[-1][1] - moving[0][1]
    assert len(moving) - 1 >= 10 * span, f"{len(moving)} states in {span:.2f} s"
    ys = [data["mcs"]["Y"] for data, _ in moving]
    assert all(b >= a for a, b in zip(ys, ys[1:], strict=False))       # +Y only
    speed = (ys[-1] - ys[0]) / span * 60.0                               # mm/min between the first and last
    assert speed == pytest.approx(TEST_SCENARIO["machine"]["jog_feed"], rel=0.35)

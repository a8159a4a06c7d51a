"""The jogging routes of the control panel (issue 17 item 7): the virtual handwheel moves one
increment per detent, the jog feed / RAPID / rapid override of the tab reach the machine, bad
input is refused on the message line with nothing moved."""

from __future__ import annotations

import pytest
from hmi_testdata import TEST_SCENARIO

HTMX = {"HX-Request": "true"}
START = TEST_SCENARIO["start"]


def tab(axis: str = "X", increment: str = "1000", **jog) -> dict:
    """The headers a browser tab sends (static/hmi.js: axis, increment; static/jogging.js: the rest)."""
    extra = {f"X-Panel-{k.title()}": v for k, v in jog.items()}
    return {**HTMX, "X-Panel-Axis": axis, "X-Panel-Increment": increment, **extra}


def mcs(client) -> dict:
    return client.get("/api/machine").json()["mcs"]


def test_each_detent_moves_the_axis_by_the_increment(client):
    client.post("/ui/handwheel", data={"detents": "7"}, headers=tab("Z", "100"))       # 7 x 0.1 mm
    assert mcs(client)["Z"] == pytest.approx(START["Z"] + 0.7, abs=1e-9)
    client.post("/ui/handwheel", data={"detents": "-3", "axis": "Y"}, headers=tab("Z", "1"))   # 3 x 1 um on Y
    assert mcs(client)["Y"] == pytest.approx(START["Y"] - 0.003, abs=1e-9)


@pytest.mark.parametrize(("detents", "increment", "words"), [
    ("lots", "100", "whole number"), ("0", "100", "detents at a time"), ("1001", "100", "detents at a time"),
    ("5", "cont", "select an increment"),
])
def test_a_bad_handwheel_turn_moves_nothing(client, detents, increment, words):
    text = client.post("/ui/handwheel", data={"detents": detents}, headers=tab("X", increment)).text
    assert 'id="message"' in text and words in text.lower()
    assert mcs(client) == START


def test_the_tab_keeps_its_jog_feed_rapid_and_rapid_override(client):
    mcp = client.post("/ui/panel/jogfeed", data={"feed": "2000"}, headers=tab()).text
    assert 'data-jog-feed="2000"' in mcp and 'data-rapid="off"' in mcp
    mcp = client.post("/ui/panel/jogfeed", data={"rapid": "on", "rov": "50"}, headers=tab(feed="2000")).text
    assert 'data-jog-feed="2000"' in mcp and 'data-rapid="on"' in mcp and 'data-rov="50"' in mcp
    mcp = client.post("/ui/panel/jogfeed", data={"feed": "123456", "rov": "7"}, headers=tab()).text   # not offered
    assert 'data-jog-feed=""' in mcp and 'data-rov="25"' in mcp


def test_the_jog_feed_the_machine_is_given(client, app, monkeypatch):
    """The chosen feed, or the scenario's rapid traverse times the rapid override, else the
    machine's own jog feed (None)."""
    sim = app.state.services.machine.machine
    given: list = []
    monkeypatch.setattr(sim, "jog_continuous", lambda axis, direction, feed=None: given.append(feed))
    client.post("/ui/jog/start", data={"direction": "+"}, headers=tab("X", "cont"))
    client.post("/ui/jog/start", data={"direction": "+"}, headers=tab("X", "cont", feed="500"))
    client.post("/ui/jog/start", data={"direction": "+"}, headers=tab("X", "cont", feed="500", rapid="on", rov="5"))
    client.post("/ui/jog/start", data={"direction": "+", "rapid": "on"}, headers=tab("X", "cont", rov="50"))  # Shift
    rapid = TEST_SCENARIO["machine"]["rapid"]
    assert given == [None, 500.0, pytest.approx(rapid * 0.05), pytest.approx(rapid * 0.5)]


def test_a_late_key_up_stops_only_a_held_jog(client):
    """The jog key's release arrives after NC Start started a measurement (a loaded network): it
    must not stop that motion; with a jog held it stops the jog."""
    machine = client.app.state.services.machine.machine
    stops = []
    original = machine.stop
    machine.stop = lambda: (stops.append(1), original())[1]
    try:
        headers = {"HX-Request": "true"}
        assert client.post("/ui/jog/stop", headers=headers).status_code == 200
        assert stops == []                                   # nothing held: nothing stopped
        client.post("/ui/jog/start", data={"axis": "X", "direction": "+"}, headers=headers)
        assert client.post("/ui/jog/stop", headers=headers).status_code == 200
        assert stops == [1]
    finally:
        machine.stop = original

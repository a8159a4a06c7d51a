"""Hold-to-run ends on time (issue 24 §6): the order of renewals, releases and a dropped live feed.

A fake machine records what the dead-man (app.services.machine_service.HoldToRun) asks of it;
no clock is involved: each case is about which request may still move the axis.
"""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from app.services.machine_service import HoldToRun


class FakeMachine:
    def __init__(self) -> None:
        self.busy = False
        self.calls: list[tuple] = []

    def status(self):
        return SimpleNamespace(busy=self.busy)

    def jog_continuous(self, axis, direction, feed):
        self.busy = True
        self.calls.append(("jog", axis, direction))

    def stop(self):
        self.busy = False
        self.calls.append(("stop",))


@pytest.fixture
def hold():
    machine = FakeMachine()
    dead_man = HoldToRun(machine)
    yield dead_man, machine
    dead_man.close()


def press(dead_man: HoldToRun, machine: FakeMachine, tab: str, n: int) -> None:
    """What MachineService.jog_continuous does with one request of key press ``n``."""
    if not dead_man.renew("X", 1, tab, n) and not dead_man.stale(tab, n):
        dead_man.start("X", 1, None, tab, n)


def let_go(dead_man: HoldToRun, machine: FakeMachine, tab: str, n: int) -> None:
    if dead_man.release(tab, n):
        machine.stop()


def test_a_renewal_queued_behind_the_release_does_not_restart_the_jog(hold):
    dead_man, machine = hold
    press(dead_man, machine, "tabA", 1)
    let_go(dead_man, machine, "tabA", 1)
    assert not machine.busy
    press(dead_man, machine, "tabA", 1)               # the renewal that was still on its way
    assert not machine.busy and machine.calls == [("jog", "X", 1), ("stop",)]


def test_a_release_that_overtakes_the_start_keeps_the_axis_still(hold):
    dead_man, machine = hold
    let_go(dead_man, machine, "tabA", 1)              # key-up arrived first
    press(dead_man, machine, "tabA", 1)
    assert not machine.busy and machine.calls == []
    press(dead_man, machine, "tabA", 2)               # the next press moves again
    assert machine.busy


def test_the_held_jog_stops_when_its_tab_s_feed_drops(hold):
    dead_man, machine = hold
    press(dead_man, machine, "tabA", 1)
    assert dead_man.tab_gone("tabB") is False and machine.busy      # another tab left: nothing
    assert dead_man.tab_gone("tabA") is True
    machine.stop()
    press(dead_man, machine, "tabA", 1)               # renewals of the dead tab still arriving
    press(dead_man, machine, "tabA", 2)
    assert not machine.busy
    dead_man.tab_back("tabA")                         # the tab reconnected its feed
    press(dead_man, machine, "tabA", 3)
    assert machine.busy


def test_another_tab_s_key_up_does_not_stop_my_jog(hold):
    dead_man, machine = hold
    press(dead_man, machine, "tabA", 1)
    let_go(dead_man, machine, "tabB", 7)
    assert machine.busy
    let_go(dead_man, machine, "tabA", 1)
    assert not machine.busy


def test_requests_without_a_tab_work_as_before(hold):
    dead_man, machine = hold
    press(dead_man, machine, None, None)
    assert machine.busy
    assert dead_man.renew("X", 1) is True
    assert dead_man.release() is True


def test_the_api_jog_stops_when_the_tab_s_live_feed_ends(client):
    from hmi_testdata import test_scenario

    scenario = test_scenario()
    scenario["machine"]["time_scale"] = 1.0          # the jog runs until something stops it
    assert client.post("/api/sim/scenario", json={**scenario, "reset_data": True}).status_code == 200
    body = {"axis": "Y", "direction": 1, "tab": "tab-1", "press": 1, "seq": 0}
    assert client.post("/api/machine/jog/continuous", json=body).json()["busy"] is True
    with client.stream("GET", "/api/events", params={"tab": "tab-1", "limit": 1}) as feed:
        for _ in feed.iter_lines():
            pass                                       # the feed ends after one event: the tab is gone
    state = client.get("/api/machine").json()
    assert state["busy"] is False
    y = state["mcs"]["Y"]
    assert client.post("/api/machine/jog/continuous", json={**body, "seq": 1}).json()["busy"] is False
    assert client.get("/api/machine").json()["mcs"]["Y"] == y          # a late renewal moved nothing


def test_tab_and_press_are_checked(client):
    answer = client.post("/api/machine/jog/continuous", json={"axis": "Y", "direction": 1, "tab": "a b", "press": 1})
    assert answer.status_code == 422 and answer.json()["error"]["field"] == "tab"
    answer = client.post("/api/machine/jog/continuous", json={"axis": "Y", "direction": 1, "tab": "a", "press": 0})
    assert answer.status_code == 422 and answer.json()["error"]["field"] == "press"
    assert client.get("/api/machine").json()["busy"] is False

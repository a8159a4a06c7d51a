"""The probe lamps and the probe test on the JOG screen, clicked as an operator (issue 26 items 1, 2, 6).

The operator's hand is the simulator's ``POST /api/sim/probe``; the screen follows from the live
feed alone (no reload). The NC Start of a measuring screen with a deflected probe shows 65401.
"""

from __future__ import annotations

import pytest
from live import wait_for_requests
from playwright.sync_api import Error as PlaywrightError
from playwright.sync_api import expect

pytestmark = pytest.mark.e2e


def test_lamp_turns_red_while_the_probe_is_deflected(page, api):
    page.goto("/jog")
    lamp = page.locator('#probe-pane [data-probe-lamp="workpiece"]')
    expect(lamp).to_have_attribute("data-state", "ready")
    header = page.locator('#header-status [data-probe-lamp="workpiece"]')
    expect(header).to_have_attribute("data-state", "ready")
    api.post("/api/sim/probe", json={"deflect": True})
    expect(lamp).to_have_attribute("data-state", "deflected")
    expect(lamp).to_have_class("probe-lamp lamp-deflected")
    expect(lamp).to_contain_text("deflected")
    expect(header).to_have_attribute("data-state", "deflected")
    api.post("/api/sim/probe", json={"deflect": False})
    expect(lamp).to_have_attribute("data-state", "ready")


def test_tool_probe_lamp_and_tool_change(page, api):
    page.goto("/jog")
    tool_lamp = page.locator('#probe-pane [data-probe-lamp="tool"]')
    expect(tool_lamp).to_have_attribute("data-state", "ready")
    api.post("/api/sim/probe", json={"probe": "tool", "deflect": True})
    expect(tool_lamp).to_have_attribute("data-state", "deflected")
    api.post("/api/machine/tool", json={"tool": 1})
    expect(page.locator('#probe-pane [data-probe-lamp="workpiece"]')).to_have_attribute("data-state", "absent")


def test_probe_test_softkey_shows_switched_then_passed(page, api):
    page.goto("/jog")
    page.locator("#vsoftkeys .softkey", has_text="Probe test").first.click()
    test = page.locator("#probe-test")
    expect(test).to_have_attribute("data-state", "waiting")
    api.post("/api/sim/probe", json={"deflect": True})
    expect(test).to_have_attribute("data-state", "switched")
    expect(test).to_contain_text("Switched")
    api.post("/api/sim/probe", json={"deflect": False})
    expect(test).to_have_attribute("data-state", "passed")
    assert api.get("/api/probe/test").json()["state"] == "passed"


def test_tool_probe_test_softkey(page, api):
    page.goto("/jog")
    page.locator("#vsoftkeys .softkey", has_text="Tool probe test").click()
    test = page.locator("#probe-test")
    expect(test).to_have_attribute("data-probe", "tool")
    expect(test).to_have_attribute("data-state", "waiting")
    api.post("/api/sim/probe", json={"probe": "tool", "deflect": True})
    expect(test).to_have_attribute("data-state", "switched")


def test_probe_test_softkey_while_the_pane_refreshes(page, api):
    """The softkey pressed while the pane's own refresh (the live feed's first event) is on its
    way, and the refresh answered first (a busy computer; CI): the refresh replaced the pane and
    the softkey's answer landed in the removed pane, so the screen kept the last test. The
    softkey's answer must show."""
    held: dict = {}

    def hold(route):         # the server answers at once; the browser gets the answer when released
        name = "refresh" if route.request.method == "GET" else "start"
        held.setdefault(name, (route, route.fetch()))

    page.route("**/jog/probe-test", hold)
    try:
        page.goto("/jog")
        wait_for_requests(page, held)                           # the pane's refresh is on its way
        page.locator("#vsoftkeys .softkey", has_text="Tool probe test").click()
        wait_for_requests(page, held, 2)
        route, answer = held["refresh"]
        try:
            route.fulfill(response=answer)                      # the refresh answers first
        except PlaywrightError:
            pass                                                # the softkey cancelled it
        expect(page.locator("#probe-pane.htmx-request")).to_have_count(0)
        route, answer = held["start"]
        with page.expect_response("**/jog/probe-test"):
            route.fulfill(response=answer)
    finally:
        page.unroute("**/jog/probe-test")
    test = page.locator("#probe-test")
    expect(test).to_have_attribute("data-probe", "tool")
    expect(test).to_have_attribute("data-state", "waiting")
    assert api.get("/api/probe/test").json()["probe"] == "tool"


def test_probe_test_on_a_deflected_probe_says_why_in_german(page, api):
    api.post("/api/sim/probe", json={"deflect": True})
    page.goto("/jog?lang=de")
    page.locator("#vsoftkeys .softkey", has_text="Tastertest").first.click()
    expect(page.locator("#probe-pane .field-error")).to_contain_text("bereits ausgelenkt")
    expect(page.locator("#probe-test")).not_to_have_attribute("data-state", "waiting")


def test_nc_start_with_a_deflected_probe_shows_65401(page, api):
    api.post("/api/sim/probe", json={"deflect": True})
    page.goto("/measure/workpiece/edge/set")
    page.locator("#nc-start").click()
    expect(page.locator("#alarm-line")).to_contain_text("65401")
    assert api.get("/api/machine").json()["mcs"] == {"X": 100.0, "Y": 100.0, "Z": 0.0}

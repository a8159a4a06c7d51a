"""Hold-to-run and the tab's own control panel in real Chromium (design.md §9.1).

The machine runs at real speed here (time_scale 1, jog feed 1000 mm/min): a continuous jog
stops within 1 s when the browser loses the connection while the key is still held, the screen
says so within 1 s and recovers by itself; two tabs keep their own axis selection.
"""

from __future__ import annotations

import re
import time

import pytest
from hmi_testdata import test_scenario
from live import browser_tab, wait_for_requests
from playwright.sync_api import expect

pytestmark = pytest.mark.e2e


def real_time(api) -> None:
    scenario = test_scenario()
    scenario["machine"]["time_scale"] = 1.0
    assert api.post("/api/sim/scenario", json={**scenario, "reset_data": True}).status_code == 200


def settle(api, timeout_s: float = 3.0) -> dict:
    deadline = time.monotonic() + timeout_s
    state = api.get("/api/machine").json()
    while state["busy"] and time.monotonic() < deadline:
        time.sleep(0.02)
        state = api.get("/api/machine").json()
    return state


def test_a_held_jog_stops_when_the_connection_is_lost(browser, live_server, api):
    real_time(api)
    with browser_tab(browser, live_server) as page:
        page.goto("/jog")
        page.locator('#mcp button[data-axis="Y"]').click()
        expect(page.locator("#mcp")).to_have_attribute("data-axis", "Y")   # the panel is swapped in first
        page.locator('#mcp button[data-increment="cont"]').click()
        expect(page.locator("#mcp")).to_have_attribute("data-increment", "cont")
        page.locator('#mcp button[data-jog="+"]').hover()
        page.mouse.down()
        time.sleep(0.8)
        assert api.get("/api/machine").json()["busy"] is True          # renewed while held
        page.context.set_offline(True)                                 # the key is still held
        lost_at = time.monotonic()
        expect(page.locator("#connection")).to_be_visible(timeout=1000)
        state = settle(api, timeout_s=1.0)
        assert state["busy"] is False, "the axis still moves 1 s after the connection was lost"
        assert time.monotonic() - lost_at < 1.5
        y = state["mcs"]["Y"]
        time.sleep(0.3)
        assert api.get("/api/machine").json()["mcs"]["Y"] == pytest.approx(y, abs=1e-9)   # stands still
        page.context.set_offline(False)
        expect(page.locator("#connection")).to_be_hidden(timeout=2000)
        page.mouse.up()


def test_releasing_the_key_stops_at_once(browser, live_server, api):
    real_time(api)
    with browser_tab(browser, live_server) as page:
        page.goto("/jog")
        page.locator('#mcp button[data-axis="X"]').click()
        page.locator('#mcp button[data-increment="cont"]').click()
        page.locator('#mcp button[data-jog="+"]').hover()
        page.mouse.down()
        time.sleep(0.5)
        page.mouse.up()
        assert settle(api, timeout_s=1.0)["busy"] is False


def test_each_tab_jogs_its_own_axis(browser, live_server, api):
    with browser_tab(browser, live_server) as tab_a, browser_tab(browser, live_server) as tab_b:
        tab_a.goto("/jog")
        tab_b.goto("/jog")
        tab_a.locator('#mcp button[data-axis="X"]').click()
        tab_a.locator('#mcp button[data-increment="1000"]').click()
        tab_b.locator('#mcp button[data-axis="Y"]').click()
        expect(tab_a.locator("#mcp")).to_have_attribute("data-axis", "X")
        expect(tab_a.locator("#mcp")).to_have_attribute("data-increment", "1000")   # lit before jogging
        start = api.get("/api/machine").json()["mcs"]
        # the step's answer comes when the move has ended (POST /ui/jog blocks like the API)
        with tab_a.expect_response(lambda r: r.url.endswith("/ui/jog") and r.request.method == "POST") as jogged:
            tab_a.locator('#mcp button[data-jog="+"]').click()
        assert jogged.value.ok
        expect(tab_a.locator("#message")).not_to_have_class(re.compile(r"\berror\b"))
        mcs = settle(api)["mcs"]
        assert mcs["X"] == pytest.approx(start["X"] + 1.0) and mcs["Y"] == pytest.approx(start["Y"]), \
            (f"jog request headers {jogged.value.request.headers}, "
             f"message {tab_a.locator('#message').inner_text()!r}")
        tab_a.reload()                                   # the tab keeps its selection
        expect(tab_a.locator("#mcp")).to_have_attribute("data-axis", "X")
        expect(tab_b.locator("#mcp")).to_have_attribute("data-axis", "Y")


def test_a_panel_key_pressed_while_the_panel_loads_is_not_lost(browser, live_server, api):
    real_time(api)
    with browser_tab(browser, live_server) as page:
        page.goto("/jog")
        held = []
        page.route("**/ui/panel/axis", lambda route: held.append(route))      # a slow answer
        page.locator('#mcp button[data-axis="Y"]').click()
        wait_for_requests(page, held)
        assert len(held) == 1
        page.locator('#mcp button[data-increment="cont"]').click()            # pressed meanwhile
        held.pop().continue_()
        page.unroute("**/ui/panel/axis")
        expect(page.locator("#mcp")).to_have_attribute("data-axis", "Y")
        expect(page.locator("#mcp")).to_have_attribute("data-increment", "cont")
        expect(page.locator('#mcp button[data-increment="cont"]')).to_have_class(re.compile(r"\bon\b"))


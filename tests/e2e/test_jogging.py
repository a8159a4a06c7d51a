"""Jogging as an operator does it (issue 17 item 7): the jog feed choice, RAPID with the rapid
override, keyboard jog with hold-to-run (key up and leaving the window stop it), and the virtual
handwheel (one detent = one increment). Speeds are checked against the scenario's truth: the
chosen feed, or its rapid traverse times the rapid override, at 100 % feed override.
"""

from __future__ import annotations

import math
import time

import numpy as np
import pytest
from hmi_testdata import TEST_SCENARIO, test_scenario
from live import browser_tab, wait_for_requests
from playwright.sync_api import expect

pytestmark = pytest.mark.e2e
RAPID = TEST_SCENARIO["machine"]["rapid"]          # mm/min


def real_time(api) -> None:
    scenario = test_scenario()
    scenario["machine"]["time_scale"] = 1.0
    assert api.post("/api/sim/scenario", json={**scenario, "reset_data": True}).status_code == 200


def mcs(api) -> dict:
    return api.get("/api/machine").json()["mcs"]


def speed_while(api, axis: str, seconds: float = 0.6) -> float:
    """mm/min of ``axis`` while it moves: the median over sample intervals in which it moved (each
    sample stamped halfway through its request). On a loaded machine a renewal of the hold-to-run
    jog can come late and the axis pause; the median of the moving intervals is the feed."""
    samples = []
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        before = time.monotonic()
        value = mcs(api)[axis]
        samples.append(((before + time.monotonic()) / 2, value))
        time.sleep(0.05)
    speeds = [abs(b - a) / (tb - ta) * 60.0 for (ta, a), (tb, b) in zip(samples, samples[1:], strict=False)
              if abs(b - a) > 1e-6]
    return float(np.median(speeds)) if speeds else 0.0


def settle(api, timeout_s: float = 2.0) -> dict:
    deadline = time.monotonic() + timeout_s
    state = api.get("/api/machine").json()
    while state["busy"] and time.monotonic() < deadline:
        time.sleep(0.02)
        state = api.get("/api/machine").json()
    return state


def hold_jog_key(page, direction: str = "+"):
    page.locator(f'#mcp button[data-jog="{direction}"]').hover()
    page.mouse.down()


def test_the_chosen_jog_feed_moves_the_axis_at_that_speed(browser, live_server, api):
    real_time(api)
    with browser_tab(browser, live_server) as page:
        page.goto("/jog")
        page.locator('#mcp button[data-axis="Y"]').click()
        expect(page.locator("#mcp")).to_have_attribute("data-axis", "Y")
        page.locator('#mcp button[data-increment="cont"]').click()
        expect(page.locator("#mcp")).to_have_attribute("data-increment", "cont")
        page.locator("#jog-feed").select_option("2000")
        expect(page.locator("#mcp")).to_have_attribute("data-jog-feed", "2000")
        hold_jog_key(page)
        time.sleep(0.3)                                   # past the acceleration
        speed = speed_while(api, "Y")
        page.mouse.up()
        assert speed == pytest.approx(2000.0, rel=0.3)
        page.reload()                                     # the tab keeps its choice
        expect(page.locator("#mcp")).to_have_attribute("data-jog-feed", "2000")
        expect(page.locator("#jog-feed")).to_have_value("2000")


def test_rapid_runs_at_rapid_traverse_times_the_rapid_override(browser, live_server, api):
    real_time(api)
    with browser_tab(browser, live_server) as page:
        page.goto("/jog")
        page.locator('#mcp button[data-axis="X"]').click()
        expect(page.locator("#mcp")).to_have_attribute("data-axis", "X")
        page.locator('#mcp button[data-increment="cont"]').click()
        expect(page.locator("#mcp")).to_have_attribute("data-increment", "cont")
        page.locator("#rapid-override").select_option("50")            # not the default (25 %)
        expect(page.locator("#mcp")).to_have_attribute("data-rov", "50")
        page.locator("#rapid").click()
        expect(page.locator("#rapid")).to_have_attribute("aria-pressed", "true")
        hold_jog_key(page)
        time.sleep(0.3)
        speed = speed_while(api, "X")
        page.mouse.up()
        assert speed == pytest.approx(RAPID * 0.5, rel=0.3)
        assert settle(api)["busy"] is False
        page.reload()
        expect(page.locator("#rapid")).to_have_attribute("aria-pressed", "true")
        expect(page.locator("#rapid-override")).to_have_value("50")


def test_a_key_swapped_in_works_at_once(page):
    """A panel answer swaps in new keys; a key pressed right after (here in the same moment the
    answer is in) must act. htmx attaches a key's handlers when it settles; with its default 20 ms
    settle delay such a press did nothing (CI: RAPID pressed right after the rapid override)."""
    page.goto("/jog")
    expect(page.locator("#rapid")).to_have_attribute("aria-pressed", "false")
    page.evaluate("""() => new Promise(resolve => {
        document.addEventListener("htmx:afterRequest", () => {     // the answer is swapped in:
            document.getElementById("rapid").click();             // the new key, at once
            resolve();
        }, {once: true});
        const override = document.getElementById("rapid-override");
        override.value = "50";
        override.dispatchEvent(new Event("change", {bubbles: true}));
    })""")
    expect(page.locator("#mcp")).to_have_attribute("data-rov", "50")
    expect(page.locator("#rapid")).to_have_attribute("aria-pressed", "true")
    page.locator("#rapid").click()                             # leave RAPID off for the next tests
    expect(page.locator("#rapid")).to_have_attribute("aria-pressed", "false")


def test_rapid_pressed_while_the_panel_loads_is_not_lost(browser, live_server):
    """RAPID pressed while the rapid override's answer is on its way (CI: the key looked dead). The
    override's answer replaces the panel; RAPID's answer then belongs to a panel no longer shown."""
    with browser_tab(browser, live_server) as page:
        page.goto("/jog")
        held = []
        page.route("**/ui/panel/jogfeed", lambda route: held.append(route))
        page.locator("#rapid-override").select_option("50")
        page.locator("#rapid").click()                              # pressed meanwhile
        wait_for_requests(page, held, 2)
        assert len(held) == 2
        held[0].continue_()                                         # the override's answer first
        expect(page.locator("#mcp")).to_have_attribute("data-rov", "50")
        held[1].continue_()                                         # then RAPID's
        page.unroute("**/ui/panel/jogfeed")
        expect(page.locator("#rapid")).to_have_attribute("aria-pressed", "true")
        expect(page.locator("#rapid-override")).to_have_value("50")
        page.locator("#rapid").click()                              # RAPID off again for the next tests
        expect(page.locator("#rapid")).to_have_attribute("aria-pressed", "false")


def test_keyboard_jog_runs_while_the_key_is_held(browser, live_server, api):
    real_time(api)
    with browser_tab(browser, live_server) as page:
        page.goto("/jog")
        start = mcs(api)
        page.keyboard.down("ArrowRight")                  # X+
        time.sleep(0.5)
        assert api.get("/api/machine").json()["busy"] is True
        page.keyboard.up("ArrowRight")
        released = time.monotonic()
        state = settle(api, timeout_s=1.0)
        assert state["busy"] is False and time.monotonic() - released < 0.5
        assert state["mcs"]["X"] > start["X"] + 1.0 and state["mcs"]["Y"] == pytest.approx(start["Y"])

        page.keyboard.down("PageDown")                    # Z-
        time.sleep(0.4)
        page.evaluate("window.dispatchEvent(new Event('blur'))")     # the operator leaves the window
        left = time.monotonic()
        state = settle(api, timeout_s=1.0)
        assert state["busy"] is False and time.monotonic() - left < 0.5
        assert state["mcs"]["Z"] < start["Z"] - 1.0
        page.keyboard.up("PageDown")

        page.keyboard.down("Shift")                       # Shift: rapid traverse x rapid override (25 %)
        page.keyboard.down("ArrowUp")
        time.sleep(0.3)
        speed = speed_while(api, "Y")
        page.keyboard.up("ArrowUp")
        page.keyboard.up("Shift")
        assert speed == pytest.approx(RAPID * 0.25, rel=0.3)
        assert settle(api)["busy"] is False


def test_keys_in_a_field_do_not_jog(page, api):
    page.goto("/measure/workpiece/calibrate/radius")
    before = mcs(api)
    field = page.locator('input[name="diameter"]')
    field.click()
    page.keyboard.press("ArrowLeft")
    page.keyboard.press("PageUp")
    time.sleep(0.3)
    assert mcs(api) == before


def test_the_handwheel_moves_one_increment_per_detent(page, api):
    page.goto("/jog")
    page.locator('#mcp button[data-axis="Z"]').click()
    expect(page.locator("#mcp")).to_have_attribute("data-axis", "Z")
    page.locator('#mcp button[data-increment="100"]').click()        # 0.1 mm per detent
    expect(page.locator("#mcp")).to_have_attribute("data-increment", "100")
    start = mcs(api)["Z"]
    wheel = page.locator("#handwheel")
    wheel.hover()
    for _ in range(5):                                                # 5 notches of the mouse wheel
        page.mouse.wheel(0, -100)
    expect(page.locator('#position-values td.value[data-axis="Z"]')).to_have_text(f"{start + 0.5 - 100.0:.3f}")
    assert mcs(api)["Z"] == pytest.approx(start + 0.5, abs=1e-9)
    wheel.focus()
    for _ in range(3):                                                # 3 detents back with the keys
        page.keyboard.press("ArrowDown")
    deadline = time.monotonic() + 2
    while abs(mcs(api)["Z"] - (start + 0.2)) > 1e-9 and time.monotonic() < deadline:
        time.sleep(0.05)
    assert mcs(api)["Z"] == pytest.approx(start + 0.2, abs=1e-9)

    # a quarter turn clockwise by dragging: 25 detents of 0.01 mm (INC 10)
    page.locator('#mcp button[data-increment="10"]').click()
    expect(page.locator("#mcp")).to_have_attribute("data-increment", "10")
    box = page.locator("#handwheel").bounding_box()
    cx, cy, r = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2, box["width"] / 2 - 4
    page.mouse.move(cx, cy - r)
    page.mouse.down()
    for k in range(1, 19):                                            # 12 o'clock to 3 o'clock
        a = math.radians(-90 + 5 * k)
        page.mouse.move(cx + r * math.cos(a), cy + r * math.sin(a))
    page.mouse.up()
    time.sleep(0.5)
    moved = mcs(api)["Z"] - (start + 0.2)
    assert moved == pytest.approx(0.25, abs=0.0101)                   # 25 detents, at most one short


def test_a_bad_handwheel_request_is_refused(api):
    answer = api.post("/ui/handwheel", data={"detents": "lots", "axis": "X"},
                      headers={"Origin": str(api.base_url).rstrip("/")})
    assert answer.status_code in (200, 403)
    if answer.status_code == 200:
        assert "whole number" in answer.text

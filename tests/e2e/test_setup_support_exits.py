"""Every exit of the set-up support screen returns to a complete screen (issue 17, item 4).

NC Start (the control panel's and the screen's own), "<< leave without activating" on the input
screen and the "<<" softkey each lead back to the measuring function's input screen with the
status header, the position display, both softkey bars and the machine control panel, saying what
was done ("G54 activated"); a reload (F5) shows the same complete screen.
"""

from __future__ import annotations

import pytest
import test_setup_support as kit
from playwright.sync_api import expect
from test_setup_support import FLAT, load, run_points

http, server, tab = kit.http, kit.server, kit.tab      # the fixtures of the set-up support tests

pytestmark = pytest.mark.e2e
HOLES = [(40, 30, -8), (160, 30, -8), (160, 90, -8), (40, 90, -8)]
PARAMS = {"diameter": 16, "angle_correction": "rotation", "setpoint_angle": 0.0, "setpoint": {"X": 0, "Y": 0}}
INPUT_SCREEN = "**/measure/workpiece/pocket/hole4"


@pytest.fixture
def measured(http):
    """4 holes measured under G500 into G54: the set-up support offers to activate G54."""
    op = load(http, FLAT)
    http.post("/api/machine/activate", json={"offset": "G500"})
    answer = run_points(http, op, "hole.4", PARAMS, HOLES, target="G54")
    assert answer["setup_support"] is not None
    return answer


def expect_complete(tab) -> None:
    """Header, position display, both softkey bars, the control panel and the input screen."""
    for selector in ("#header-status", "#position-values", "#vsoftkeys", "#hsoftkeys", "#mcp",
                     '#screen[data-task="hole.4"]'):
        expect(tab.locator(selector)).to_have_count(1)
    expect(tab.locator("#position-values td.value").first).to_be_visible()
    expect(tab.locator("#mcp #nc-start")).to_be_visible()


def check_after_reload(tab) -> None:
    tab.reload()
    expect_complete(tab)


def test_nc_start_on_the_panel_returns_to_the_complete_input_screen(tab, http, measured):
    tab.goto(f"/measure/setup-support/{measured['_session']}")
    tab.locator("#nc-start").click()
    tab.wait_for_url(INPUT_SCREEN)
    expect_complete(tab)
    expect(tab.locator("#message")).to_contain_text("G54 activated")
    expect(tab.locator("#screen .task-notice")).to_contain_text("G54 activated")
    expect(tab.locator("#hdr-wo")).to_have_text("G54")
    assert http.get("/api/machine").json()["active_offset"] == "G54"
    check_after_reload(tab)


def test_the_screens_own_nc_start_returns_to_the_complete_input_screen(tab, http, measured):
    tab.goto(f"/measure/setup-support/{measured['_session']}")
    tab.locator("#ss-nc-start").click()
    tab.wait_for_url(INPUT_SCREEN)
    expect_complete(tab)
    expect(tab.locator("#message")).to_contain_text("G54 activated")
    check_after_reload(tab)


def test_the_back_softkey_leaves_without_activating(tab, http, measured):
    tab.goto(f"/measure/setup-support/{measured['_session']}")
    tab.locator('#vsoftkeys .softkey:has-text("<<")').click()
    tab.wait_for_url(INPUT_SCREEN)
    expect_complete(tab)
    expect(tab.locator("#message")).to_contain_text("Left without activating")
    assert http.get("/api/machine").json()["active_offset"] == "G500"
    check_after_reload(tab)


def test_leave_and_nc_start_from_the_input_screen(tab, http, measured):
    # the hand-over on the input screen (the result of Calculate in the browser)
    tab.goto("/measure/workpiece/pocket/hole4")
    expect(tab.locator("#setup-support")).to_be_visible()
    tab.locator("#setup-support button:has-text('leave')").click()
    expect(tab.locator("#message")).to_contain_text("Left without activating")
    expect_complete(tab)
    expect(tab.locator("#setup-support")).to_have_count(0)
    assert http.get("/api/machine").json()["active_offset"] == "G500"
    check_after_reload(tab)


def test_nc_start_on_the_input_screens_hand_over_activates(tab, http, measured):
    tab.goto("/measure/workpiece/pocket/hole4")
    expect(tab.locator("#setup-support")).to_be_visible()
    tab.locator("#nc-start").click()
    expect(tab.locator("#message")).to_contain_text("G54 activated")
    expect_complete(tab)
    expect(tab.locator("#hdr-wo")).to_have_text("G54")
    check_after_reload(tab)

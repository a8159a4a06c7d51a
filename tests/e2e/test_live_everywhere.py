"""Chromium: the open screen follows changes made elsewhere (issue 29 item 1).

A zero offset activated and the units switched through the API show on the open JOG screen without
a click (the live feed, design.md §9.9); the header shows the mode the screen selects (JOG, MDA,
AUTO) as the control's mode keys do; the page title follows htmx navigation; a late answer shows
"busy", not "lost", and neither moves the layout. Truth: the API's own offsets and 1 inch = 25.4 mm.
"""

from __future__ import annotations

import pytest
from playwright.sync_api import expect

pytestmark = pytest.mark.e2e

FOLLOW_MS = 2000            # the bar for a change made elsewhere


@pytest.fixture
def mm_afterwards(api):
    yield
    assert api.put("/api/settings", json={"units": "mm"}).status_code == 200


def test_the_open_jog_screen_follows_an_offset_activation_and_a_units_change(page, api, mm_afterwards):
    g54 = {"trans": {"X": 250.0, "Y": 150.0, "Z": -120.0}, "rot": {"X": 0.0, "Y": 0.0, "Z": 0.0}}
    assert api.put("/api/offsets/G54", json=g54).status_code == 200
    page.goto("/jog")
    title = page.locator("#position .pos-title")
    expect(title).to_contain_text("G500")
    assert api.post("/api/machine/activate", json={"offset": "G54"}).status_code == 200
    expect(title).to_contain_text("G54", timeout=FOLLOW_MS)
    expect(page.locator("#hdr-wo")).to_have_text("G54", timeout=FOLLOW_MS)
    wcs_x = api.get("/api/machine").json()["wcs"]["X"]
    x = page.locator('#position-values td.value[data-axis="X"]')
    expect(x).to_have_text(f"{wcs_x:.3f}", timeout=FOLLOW_MS)          # G54's value, in mm
    unit = page.locator('#position-values tr:has(td[data-axis="X"]) td.unit')
    expect(unit).to_have_text("mm")

    assert api.put("/api/settings", json={"units": "inch"}).status_code == 200
    expect(unit).to_have_text("inch", timeout=FOLLOW_MS)
    expect(x).to_have_text(f"{wcs_x / 25.4:.4f}", timeout=FOLLOW_MS)
    # the screen's own lengths follow too (the tool length pane of the JOG screen)
    expect(page.locator("#screen .panes")).to_contain_text("inch", timeout=FOLLOW_MS)
    expect(title).to_contain_text("G54")


def test_the_header_shows_the_mode_the_screen_selects_and_the_title_follows(page, api):
    assert api.post("/api/nc/reset").status_code == 200
    page.goto("/jog")
    mode = page.locator("#header-status .mode")
    expect(mode).to_have_text("JOG")
    page.locator("#hsoftkeys").get_by_text("MDA / AUTO").click()
    expect(page.locator("#screen")).to_have_attribute("data-screen", "mda")
    expect(mode).to_have_text("MDA")
    expect(page.locator("#nc-channel .nc-mode")).to_have_text("MDA")
    expect(page).to_have_title("MDA · Measure-in-JOG HMI")
    page.locator("#vsoftkeys").get_by_text("Programs").click()
    expect(page.locator("#screen")).to_have_attribute("data-screen", "programs")
    expect(mode).to_have_text("AUTO")
    expect(page).to_have_title("Programs · Measure-in-JOG HMI")
    # a change of the machine state redraws the header: it keeps the screen's mode
    assert api.put("/api/machine/override", json={"feed": 55}).status_code == 200
    expect(page.locator("#header-status .ovr")).to_have_text("F 55 %")
    expect(mode).to_have_text("AUTO")
    page.locator("#hsoftkeys").get_by_text("JOG", exact=True).click()
    expect(page.locator("#screen")).to_have_attribute("data-screen", "jog")
    expect(mode).to_have_text("JOG")
    expect(page).to_have_title("JOG · Measure-in-JOG HMI")
    assert api.put("/api/machine/override", json={"feed": 100}).status_code == 200


def test_a_late_answer_shows_busy_not_lost_and_moves_nothing(page, api):
    page.goto("/jog")
    expect(page.locator('#position-values td.value[data-axis="X"]')).not_to_be_empty()
    before = page.locator("#screen").bounding_box()
    held = []
    page.route("**/ui/panel/increment", lambda route: held.append(route))     # an answer that comes late
    page.locator('#mcp button[data-increment="10"]').click()
    expect(page.locator("#busy")).to_be_visible()
    expect(page.locator("#connection")).to_be_hidden()
    assert page.locator("#screen").bounding_box() == before, "the busy note moved the screen"
    # the live feed still runs: the position follows a move meanwhile
    assert api.post("/api/machine/jog", json={"axis": "X", "distance": 5.0}).status_code == 200
    x = api.get("/api/machine").json()["wcs"]["X"]
    expect(page.locator('#position-values td.value[data-axis="X"]')).to_have_text(f"{x:.3f}")
    expect(page.locator("#connection")).to_be_hidden()
    for route in held:
        route.continue_()
    expect(page.locator("#busy")).to_be_hidden()
    assert page.locator("#screen").bounding_box() == before


def test_a_broken_feed_shows_lost_over_the_header(page, api):
    """The live feed's link breaks (each attempt is reset, as a dead server's would): "lost",
    laid over the header; when the feed comes back the note goes."""
    broken = {"on": False}

    def feed(route):
        if broken["on"]:
            route.abort("connectionreset")      # a dead server: every attempt of the feed fails
        else:
            route.continue_()

    page.route("**/api/events*", feed)
    page.goto("/jog")
    expect(page.locator('#position-values td.value[data-axis="X"]')).not_to_be_empty()
    before = page.locator("#screen").bounding_box()
    broken["on"] = True
    page.goto("/jog")                       # the page's feed now fails at every attempt
    expect(page.locator("#connection")).to_be_visible(timeout=4000)
    expect(page.locator("#busy")).to_be_hidden()
    assert page.locator("#screen").bounding_box() == before, "the lost note moved the screen"
    broken["on"] = False
    expect(page.locator("#connection")).to_be_hidden(timeout=4000)

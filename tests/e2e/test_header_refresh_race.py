"""The header follows the machine although an answer of its own is still on its way.

The header (and the position block, the JOG panes) is drawn again on each "hmi-state" event
(static/live.js). A second event while the first refresh is still under way must win: htmx would
queue it on the old element, the first answer replaces that element, and the queued refresh is
dropped, so the header kept the offset of before (seen as "G500" after "G54 activated"). Now an
answer that comes after a newer state asks again (static/live.js)."""

from __future__ import annotations

import re

import pytest
from playwright.sync_api import Error, expect

pytestmark = pytest.mark.e2e


def test_the_header_shows_the_newest_offset_although_an_older_refresh_answers_late(page, api):
    with page.expect_response("**/ui/header"):
        page.goto("/jog")                               # the live feed's first event draws it again
    expect(page.locator("#header-status")).not_to_have_class(re.compile(r"\bhtmx-request\b"))
    expect(page.locator("#hdr-wo")).to_have_text("G500")
    stale = api.get("/ui/header").text                  # the header as it is now, with G500
    held = []

    def hold_the_first(route):
        if held:
            route.continue_()
        else:
            held.append(route)                          # answered late, below

    page.route("**/ui/header", hold_the_first)
    page.evaluate("htmx.trigger(document.body, 'hmi-state')")
    expect(page.locator("#header-status")).to_have_class(re.compile(r"\bhtmx-request\b"))   # held
    assert api.post("/api/machine/activate", json={"offset": "G54"}).status_code == 200
    # the change's event has come (it writes the position block's offset) and asked the header
    # again while the first refresh is held; then the late answer comes, with the old G500
    expect(page.locator("#position .pos-wo").first).to_have_text("G54")
    assert len(held) == 1
    try:
        held[0].fulfill(status=200, body=stale, content_type="text/html")
    except Error:                                       # the page has gone on without it
        pass
    expect(page.locator("#hdr-wo")).to_have_text("G54")
    expect(page.locator("#header-status")).not_to_have_class(re.compile(r"\bhtmx-request\b"))
    expect(page.locator("#hdr-wo")).to_have_text("G54")


def test_the_live_feed_opens_once_htmx_has_read_the_page(page):
    """A live event before htmx has read the page asks elements that nobody listens on yet, and a
    state that no longer changes never asks again: the header stayed as the page was made (the
    first test above waited in vain for its refresh in CI). static/live.js opens the feed after."""
    page.add_init_script("""
        const Feed = window.EventSource;
        window.EventSource = function (url, options) {
            const header = document.getElementById("header-status");
            window.feedOpenedOnReadPage = !!(header && header["htmx-internal-data"]
                                              && header["htmx-internal-data"].initHash);
            return new Feed(url, options);
        };
    """)
    with page.expect_response("**/ui/header"):          # the first event draws the header again
        page.goto("/jog")
    assert page.evaluate("window.feedOpenedOnReadPage") is True

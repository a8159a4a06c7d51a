"""Locks shown before they bite (issue 29 item 4), in Chromium with sign-in on: a measuring
screen opened by address at a level that may not run its task shows the lock when it opens
(NC Start disabled, the reason on the screen and in its title), a target the level may write
unlocks it; a form whose Save the level may not do is read-only and says why.

Levels (README "Access levels", app/access/levels.py): the operator panel with the keyswitch at
0 is level 7: measure (7) yes; write zero offsets (5), probe calibration (3), settings (3) and
probe data (3) no. anna has a password of level 3."""

from __future__ import annotations

import re

import pytest
from hmi_testdata import TEST_SCENARIO
from live import browser_tab, serve
from playwright.sync_api import expect

pytestmark = pytest.mark.e2e


@pytest.fixture(scope="module")
def locked_server(tmp_path_factory):
    from app.access.service import AccessService
    from db import Database

    root = tmp_path_factory.mktemp("locks")
    with Database(root / "hmi.db") as db:
        AccessService(db).add_user("anna", 3, "anna-pw-3")
    with serve(root, TEST_SCENARIO) as url:
        yield url


def at_the_panel(page, lang: str = "en") -> None:
    """Signed in as the operator panel, keyswitch position 0 (level 7)."""
    page.goto(f"/signin?lang={lang}")
    page.click("#panel-submit")
    page.wait_for_url("**/jog")


def as_anna(page) -> None:
    page.goto("/signin")
    page.fill("#signin-user", "anna")
    page.fill("#signin-password", "anna-pw-3")
    page.click("#signin-submit")
    page.wait_for_url(re.compile(r"/jog"))


def test_a_calibration_screen_opened_by_address_shows_its_lock(browser, locked_server):
    with browser_tab(browser, locked_server, timeout_ms=15000) as page:
        at_the_panel(page)
        starts = []
        page.on("request", lambda r: starts.append(r.url) if "/measure/task/" in r.url and r.url.endswith("/start")
                else None)
        page.goto("/measure/workpiece/calibrate/length")
        lock = page.locator("#start-lock")
        expect(lock).to_be_visible()
        expect(lock).to_contain_text("NC Start locked")
        expect(lock).to_contain_text("needs level 3")
        start = page.locator("#nc-start")
        expect(start).to_be_disabled()
        expect(start).to_have_attribute("title", re.compile("needs level 3"))
        page.keyboard.press("Control+Enter")                  # the key does nothing either
        # a workpiece screen: the proposed WO needs level 5 to write; "Measure only" may run
        page.goto("/measure/workpiece/edge/set")
        expect(page.locator("#start-lock")).to_contain_text("needs level 5")
        expect(start).to_be_disabled()
        page.locator("#f-target").select_option("measure_only")      # the screen is drawn again (htmx)
        expect(page.locator("#start-lock")).to_have_count(0)
        expect(start).to_be_enabled()
        expect(start).not_to_have_attribute("title", re.compile("level"))
        page.locator("#f-target").select_option("G54")               # a WO again: locked again
        expect(page.locator("#start-lock")).to_contain_text("needs level 5")
        expect(start).to_be_disabled()
        assert starts == []


def test_the_lock_in_german(browser, locked_server):
    with browser_tab(browser, locked_server, timeout_ms=15000) as page:
        at_the_panel(page, "de")
        page.goto("/measure/workpiece/calibrate/radius")
        lock = page.locator("#start-lock")
        expect(lock).to_contain_text("NC-Start gesperrt")
        expect(lock).to_contain_text("erfordert Stufe 3")
        expect(page.locator("#nc-start")).to_have_attribute("title", re.compile("erfordert Stufe 3"))
        page.goto("/settings")                                # a denied softkey says why in German too
        save = page.locator('#vsoftkeys [data-key="S-F1"]')
        expect(save).to_be_disabled()
        expect(save.locator(".why")).to_have_text("erfordert Stufe 3")
        expect(save).to_have_attribute("title", re.compile("Schlüsselschalter|Kennwort"))
        expect(page.locator("#settings-read-only")).to_contain_text("erfordert Stufe 3")
        page.goto("/offsets")                                 # a locked table cell says why in German
        cell = page.locator('td[data-offset="G54"][data-field="trans.X"] input')
        expect(cell).to_be_disabled()
        expect(cell).to_have_attribute("title", re.compile("erfordert Stufe 5"))


def test_a_level_that_may_calibrate_has_no_lock(browser, locked_server):
    with browser_tab(browser, locked_server, timeout_ms=15000) as page:
        as_anna(page)
        page.goto("/measure/workpiece/calibrate/length")
        expect(page.locator("#screen")).to_have_attribute("data-screen", "measure_workpiece")
        expect(page.locator("#start-lock")).to_have_count(0)
        expect(page.locator("#nc-start")).to_be_enabled()


def test_forms_are_read_only_when_save_is_not_allowed(browser, locked_server):
    with browser_tab(browser, locked_server, timeout_ms=15000) as page:
        at_the_panel(page)
        page.goto("/settings")
        expect(page.locator('#vsoftkeys [data-key="S-F1"]')).to_be_disabled()
        expect(page.locator("#settings-read-only")).to_contain_text("needs level 3")
        controls = page.locator("#settings-form input, #settings-form select")
        assert controls.count() > 10
        for i in range(controls.count()):
            expect(controls.nth(i)).to_be_disabled()
        expect(page.locator("#settings-form input").first).to_have_attribute("title", re.compile("needs level 3"))
        for url, form in (("/probes", "#probe-form"), ("/tool-probes", "#tool-probe-form")):
            page.goto(url)
            expect(page.locator("#screen .read-only-note")).to_contain_text("needs level 3")
            inputs = page.locator(f"{form} input:not([type=hidden]), {form} select")
            assert inputs.count() > 3, url
            for i in range(inputs.count()):
                expect(inputs.nth(i)).to_be_disabled()
    with browser_tab(browser, locked_server, timeout_ms=15000) as page:
        as_anna(page)                                         # level 3: Save allowed, the fields editable
        page.goto("/settings")
        expect(page.locator("#settings-read-only")).to_have_count(0)
        expect(page.locator("#settings-form input:not([type=checkbox])").first).to_be_enabled()
        page.goto("/probes")
        expect(page.locator("#screen .read-only-note")).to_have_count(0)
        expect(page.locator("#probe-form input:not([type=hidden])").first).to_be_editable()

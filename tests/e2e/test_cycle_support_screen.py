"""Cycle support in the program manager (design.md §10.2, manual §7.2–7.3): the operator opens a
program, chooses a measuring cycle, fills its input screen (the manual's parameter names beside
the texts), inserts the call at the cursor, and reads an existing call back into the form."""

from __future__ import annotations

import pytest
from playwright.sync_api import expect

pytestmark = pytest.mark.e2e


def test_insert_a_cycle_at_the_cursor_and_read_it_back(page, api):
    api.delete("/api/programs/CYCSUP")
    assert api.post("/api/programs", json={"name": "CYCSUP", "text": "N10 G54 G0 X0 Y0\nN20 M30"}).status_code == 201
    page.goto("/programs")
    page.locator('tr[data-program="CYCSUP"]').get_by_role("button", name="Edit").click()
    editor = page.locator("#program-editor textarea")
    expect(editor).to_have_value("N10 G54 G0 X0 Y0\nN20 M30")
    editor.click()
    page.keyboard.press("Control+End")
    page.keyboard.press("Home")                                   # the cursor on line 2 (N20 M30)
    page.locator("#cycle-choice").select_option("CYCLE977")
    page.locator("#cycle-show").click()
    fields = page.locator("#cycle-fields")
    expect(fields).to_have_attribute("data-cycle", "CYCLE977")
    expect(fields).to_contain_text("_MVAR")                       # the manual's name beside the text
    fields.locator('input[data-param="_MVAR"]').fill("101")
    fields.locator('input[data-param="_SETVAL"]').fill("20.5")
    fields.locator('input[data-param="_KNUM"]').fill("1")
    page.locator("#cycle-insert").click()
    expect(editor).to_have_value("N10 G54 G0 X0 Y0\n_MVAR=101 _SETVAL=20.5 _KNUM=1\nCYCLE977\nN20 M30")
    # open the call again: a new input screen, then read the call at the cursor (line 3)
    page.locator("#cycle-choice").select_option("CYCLE978")
    page.locator("#cycle-show").click()
    expect(page.locator("#cycle-fields")).to_have_attribute("data-cycle", "CYCLE978")
    editor.click()
    page.keyboard.press("Control+Home")
    for _ in range(2):
        page.keyboard.press("ArrowDown")
    page.locator("#cycle-read").click()
    fields = page.locator("#cycle-fields")
    expect(fields).to_have_attribute("data-cycle", "CYCLE977")
    expect(fields.locator('input[data-param="_MVAR"]')).to_have_value("101")
    expect(fields.locator('input[data-param="_SETVAL"]')).to_have_value("20.5")
    expect(fields.locator('input[data-param="_KNUM"]')).to_have_value("1")
    assert api.get("/api/programs/CYCSUP").json()["text"] == "N10 G54 G0 X0 Y0\nN20 M30"     # nothing saved yet

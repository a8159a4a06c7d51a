"""Cycle support in the program manager (design.md §10.2, manual §7.2–7.3): the operator opens a
program, chooses a measuring cycle, fills its input screen (the manual's parameter names beside
the texts), inserts the call at the cursor, and reads an existing call back into the form."""

from __future__ import annotations

import pytest
from playwright.sync_api import expect

pytestmark = pytest.mark.e2e


def insert_and_read_back(page, cycle: str, filled: dict[str, str], program: str, other: str,
                         read: dict[str, str]):
    """On ``cycle``'s open input screen (the cursor on line 2): fill ``filled``, insert, and the
    editor holds ``program``; then ``other``'s input screen, the cursor on the call (line 3), read
    back: ``cycle``'s form again with ``read``. Returns that form."""
    editor = page.locator("#program-editor textarea")
    fields = page.locator("#cycle-fields")
    for param, value in filled.items():
        fields.locator(f'input[data-param="{param}"]').fill(value)
    page.locator("#cycle-insert").click()
    expect(editor).to_have_value(program)
    page.locator("#cycle-choice").select_option(other)
    page.locator("#cycle-show").click()
    expect(fields).to_have_attribute("data-cycle", other)
    editor.click()
    page.keyboard.press("Control+Home")
    for _ in range(2):
        page.keyboard.press("ArrowDown")
    page.locator("#cycle-read").click()
    expect(fields).to_have_attribute("data-cycle", cycle)
    for param, value in read.items():
        expect(fields.locator(f'input[data-param="{param}"]')).to_have_value(value)
    return fields


def open_input_screen(page, program: str, text: str, cycle: str):
    """The program ``program`` (holding ``text``, two lines) opened in the editor, the cursor on its
    line 2, and the input screen of ``cycle`` shown there; its fields."""
    page.goto("/programs")
    page.locator(f'tr[data-program="{program}"] button[hx-get$="/{program}/edit"]').click()   # Edit, any language
    editor = page.locator("#program-editor textarea")
    expect(editor).to_have_value(text)
    editor.click()
    page.keyboard.press("Control+End")
    page.keyboard.press("Home")                                   # the cursor on line 2
    page.locator("#cycle-choice").select_option(cycle)
    page.locator("#cycle-show").click()
    fields = page.locator("#cycle-fields")
    expect(fields).to_have_attribute("data-cycle", cycle)
    return fields


def test_insert_a_cycle_at_the_cursor_and_read_it_back(page, api):
    api.delete("/api/programs/CYCSUP")
    assert api.post("/api/programs", json={"name": "CYCSUP", "text": "N10 G54 G0 X0 Y0\nN20 M30"}).status_code == 201
    fields = open_input_screen(page, "CYCSUP", "N10 G54 G0 X0 Y0\nN20 M30", "CYCLE977")
    expect(fields).to_contain_text("_MVAR")                       # the manual's name beside the text
    # inserted, then opened again: a new input screen, and the call at the cursor read back
    fields = insert_and_read_back(page, "CYCLE977", {"_MVAR": "101", "_SETVAL": "20.5", "_KNUM": "1"},
                                  "N10 G54 G0 X0 Y0\n_MVAR=101 _SETVAL=20.5 _KNUM=1\nCYCLE977\nN20 M30",
                                  "CYCLE978", {"_MVAR": "101", "_SETVAL": "20.5", "_KNUM": "1"})
    assert api.get("/api/programs/CYCSUP").json()["text"] == "N10 G54 G0 X0 Y0\nN20 M30"     # nothing saved yet

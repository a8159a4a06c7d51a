"""MDA in Chromium: type a program, run it single block with the MCP's NC Start, see the block
move, the mode in the header and the bore's result (design.md §9.4)."""

from __future__ import annotations

import pytest
from playwright.sync_api import expect

pytestmark = pytest.mark.e2e

# the test scenario's Ø20 hole at MCS (290, 180), block top at Z −120; the ideal probe T9
PROGRAM = """N10 G500 G17 G90 G0 Z-100
N20 X291 Y179.5
N30 Z-128
N40 _MVAR=1 _SETVAL=20 _KNUM=0 _FA=2
N50 CYCLE977
N60 G0 Z-100
N70 M30"""


def test_type_a_program_in_mda_run_it_single_block_and_see_the_result(page, api):
    assert api.post("/api/nc/reset").status_code == 200
    page.goto("/jog")
    page.locator("#hsoftkeys").get_by_text("MDA / AUTO").click()
    expect(page.locator("#screen")).to_have_attribute("data-screen", "mda")
    page.locator("#mda-text").fill(PROGRAM)
    expect(page.locator("#mda-gutter")).to_contain_text("8")           # the line numbers follow the text
    page.locator("#single-block").check()
    expect(page.locator("#nc-channel")).to_contain_text("SBL on")
    page.locator("#nc-start").click()                                   # the MCP key
    expect(page.locator("#nc-state")).to_have_text("stopped")
    expect(page.locator('#nc-listing tr.current')).to_have_attribute("data-line", "2")
    expect(page.locator("#header-status .mode")).to_have_text("MDA")
    for line in range(3, 8):
        page.keyboard.press("Control+Enter")                            # NC Start from the keyboard
        expect(page.locator('#nc-listing tr.current')).to_have_attribute("data-line", str(line))
    page.locator("#mda-start").click()                                  # the last block: M30
    expect(page.locator("#nc-state")).to_have_text("done")
    expect(page.locator('#nc-results dd[data-name="_OVR[4]"]')).to_have_text("20.0000")
    expect(page.locator('#nc-results dd[data-name="_OVR[5]"]')).to_have_text("290.0000")
    expect(page.locator('#nc-results dd[data-name="_OVI[2]"]')).to_have_text("977")
    expect(page.locator("#header-status .mode")).to_have_text("MDA")      # the selected mode (issue 29)
    entry = api.get("/api/log").json()[0]
    assert entry["program"] == "MDA" and "CYCLE977" in entry["block"]


def test_a_typo_is_shown_at_its_line_and_column(page, api):
    assert api.post("/api/nc/reset").status_code == 200
    page.goto("/mda")
    page.locator("#mda-text").fill("N10 G0 X10\nN20 G1 X")
    page.locator("#mda-start").click()
    expect(page.locator('#nc-listing tr[data-alarm-line="2"]')).to_contain_text("line 2, column 8")
    expect(page.locator("#nc-state")).to_have_text("idle")


def test_results_say_what_they_mean_and_belong_to_their_run(page, api):
    """Issue 29 item 6: each index with its meaning (the manual's CYCLE977 table), an empty
    program says so, a new run starts without the previous program's results."""
    assert api.post("/api/nc/reset").status_code == 200
    page.goto("/mda")
    page.locator("#single-block").uncheck()                             # the whole program at once
    expect(page.locator("#nc-channel")).to_contain_text("SBL off")
    page.locator("#mda-text").fill(PROGRAM)
    page.locator("#mda-start").click()
    expect(page.locator("#nc-state")).to_have_text("done", timeout=15000)
    expect(page.locator("#nc-results-cycle")).to_have_text("CYCLE977")
    expect(page.locator('#nc-results [data-meaning="_OVR[4]"]')).to_have_text("actual diameter / width")
    expect(page.locator('#nc-results [data-meaning="_OVR[5]"]')).to_have_text("actual centre abscissa")
    expect(page.locator('#nc-results [data-meaning="_OVI[2]"]')).to_have_text("measuring cycle")
    meaning = page.locator('#nc-results [data-meaning="_OVR[4]"]').bounding_box()
    value = page.locator('#nc-results dd[data-name="_OVR[4]"]').bounding_box()
    assert meaning and value and abs(meaning["y"] - value["y"]) < 8          # on the value's line
    page.locator("#mda-text").fill("; nothing but a comment\n")
    page.locator("#mda-start").click()
    expect(page.locator("#nc-channel .form-message")).to_have_text("The program is empty: nothing to run.")
    page.locator("#mda-text").fill("N10 G500 G90 G0 Z-100\nN20 M30")
    page.locator("#mda-start").click()
    expect(page.locator("#nc-state")).to_have_text("done")
    expect(page.locator('#nc-listing tr[data-line="2"]')).to_contain_text("M30")
    expect(page.locator("#nc-results")).to_have_count(0)

"""Cycle support of the program manager on the simulated lathe (issue 28 item 6, manual §7.2–7.3):
the cycle choice offers the lathe's CYCLE982/973/974/994 only; the operator fills CYCLE974's input
screen (the manual's parameter names beside the texts), inserts the call at the cursor, reads it
back into the form, and a bad value is refused naming the parameter."""

from __future__ import annotations

import re

import httpx
import pytest
from live import browser_tab
from playwright.sync_api import expect
from test_cycle_support_screen import insert_and_read_back, open_input_screen

pytestmark = pytest.mark.e2e


@pytest.fixture
def tab(browser, lathe_server):
    with browser_tab(browser, lathe_server, timeout_ms=15000) as page:
        yield page


def test_lathe_cycle_inserted_at_the_cursor_and_read_back(tab, lathe_server):
    with httpx.Client(base_url=lathe_server, timeout=30) as http:
        assert http.get("/api/machine").json()["kind"] == "lathe"
        http.delete("/api/programs/LATHECYC")
        made = http.post("/api/programs", json={"name": "LATHECYC", "text": "N10 G54 G18 T8 D1 DIAMON\nN20 M30"})
        assert made.status_code == 201, made.text
    fields = open_input_screen(tab, "LATHECYC", "N10 G54 G18 T8 D1 DIAMON\nN20 M30", "CYCLE974")
    expect(tab.locator("#cycle-choice option")).to_have_text(["CYCLE982", "CYCLE973", "CYCLE974", "CYCLE994"])
    expect(fields).to_contain_text("_STA1")                       # the manual's names beside the texts
    expect(fields).to_contain_text("Start angle of the reversal")
    # inserted, then another input screen, and the call at the cursor read back into the form
    fields = insert_and_read_back(tab, "CYCLE974", {"_MVAR": "1000", "_SETVAL": "45", "_MA": "2", "_FA": "2.5"},
                                  "N10 G54 G18 T8 D1 DIAMON\n_MVAR=1000 _SETVAL=45.0 _MA=2 _FA=2.5\nCYCLE974\nN20 M30",
                                  "CYCLE994", {"_MVAR": "1000", "_SETVAL": "45.0", "_MA": "2", "_FA": "2.5"})
    # a measuring axis the lathe has not: refused naming _MA, the program text unchanged
    fields.locator('input[data-param="_MA"]').fill("4")
    tab.locator("#cycle-insert").click()
    expect(tab.locator("#cycle-error")).to_contain_text("_MA")
    expect(tab.locator("#program-editor textarea")).to_have_value("N10 G54 G18 T8 D1 DIAMON\n_MVAR=1000 _SETVAL=45.0 _MA=2 _FA=2.5\nCYCLE974\nN20 M30")
    with httpx.Client(base_url=lathe_server, timeout=30) as http:
        assert http.get("/api/programs/LATHECYC").json()["text"] == "N10 G54 G18 T8 D1 DIAMON\nN20 M30"


@pytest.mark.parametrize(("lang", "words"), [("en", "both directions"), ("de", "beide Richtungen"),
                                             ("zh", "两个方向")])
def test_a_cycle973_variant_it_does_not_have_is_refused_naming_mvar(tab, lathe_server, lang, words):
    """CYCLE973 in one direction (thousands digit 1) with the position deviation (ten-thousands
    digit 1): the manual says it cannot be determined (turning.md §4.1); the form says why, in the
    operator's language, and writes nothing; the manual's 12013 (both directions) is written."""
    with httpx.Client(base_url=lathe_server, timeout=30) as http:
        http.delete("/api/programs/LATHEMVAR")
        made = http.post("/api/programs", json={"name": "LATHEMVAR", "text": "N10 G54 G18 T8 D1 DIAMON\nN20 M30"})
        assert made.status_code == 201, made.text
    tab.goto(f"/jog?lang={lang}")
    fields = open_input_screen(tab, "LATHEMVAR", "N10 G54 G18 T8 D1 DIAMON\nN20 M30", "CYCLE973")
    editor = tab.locator("#program-editor textarea")
    fields.locator('input[data-param="_MVAR"]').fill("11013")
    tab.locator("#cycle-insert").click()
    error = tab.locator("#cycle-error")
    expect(error).to_contain_text("_MVAR=11013")
    expect(error).to_contain_text(words)
    expect(editor).to_have_value("N10 G54 G18 T8 D1 DIAMON\nN20 M30")
    fields.locator('input[data-param="_MVAR"]').fill("12013")
    tab.locator("#cycle-insert").click()
    expect(editor).to_have_value(re.compile(r"_MVAR=12013\b[^\n]*\nCYCLE973\nN20 M30$"))

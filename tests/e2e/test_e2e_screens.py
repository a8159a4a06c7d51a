"""End to end in Debian Chromium: JOG, zero-offset table, Measure workpiece menu, machine view."""

from __future__ import annotations

import pytest
from hmi_testdata import TEST_SCENARIO
from playwright.sync_api import expect

pytestmark = pytest.mark.e2e


def wcs_value(page, axis: str):
    return page.locator(f'#position-values td.value[data-axis="{axis}"]')


def test_jog_x_plus_one_millimetre_with_inc_1000(page, api):
    page.goto("/jog")
    page.locator('#mcp button[data-axis="X"]').click()
    page.locator('#mcp button[data-increment="1000"]').click()
    expect(page.locator("#mcp")).to_have_attribute("data-increment", "1000")
    start = api.get("/api/machine").json()["wcs"]["X"]
    expect(wcs_value(page, "X")).to_have_text(f"{start:.3f}")
    page.locator('#mcp button[data-jog="+"]').click()
    expect(wcs_value(page, "X")).to_have_text(f"{start + 1:.3f}")
    assert api.get("/api/machine").json()["wcs"]["X"] == pytest.approx(start + 1)


def test_wcs_mcs_toggle(page, api):
    page.goto("/jog")
    page.locator('#position button[data-coords="MCS"]').click()
    expect(page.locator("#position-values")).to_have_attribute("data-coords", "MCS")
    mcs_z = api.get("/api/machine").json()["mcs"]["Z"]
    expect(wcs_value(page, "Z")).to_have_text(f"{mcs_z:.3f}")
    page.locator('#position button[data-coords="WCS"]').click()
    expect(page.locator("#position-values")).to_have_attribute("data-coords", "WCS")


def test_edit_g54_x_in_the_table_and_read_it_back(page, api):
    page.goto("/offsets")
    field = page.locator('td[data-offset="G54"][data-field="trans.X"] input')
    field.fill("123.4561")
    field.press("Tab")
    # the server's answer re-renders the cell with 3 decimals: waiting for it avoids a race
    expect(page.locator('td[data-offset="G54"][data-field="trans.X"] input')).to_have_value("123.456")
    frame = api.get("/api/offsets/G54").json()
    assert frame["trans"]["X"] == pytest.approx(123.4561, abs=1e-12)
    assert api.get("/api/audit").json()[0]["source"] == "screen"


def test_typing_abc_shows_the_error_and_keeps_the_stored_value(page, api):
    api.put("/api/offsets/G54", json={"trans": {"Y": 7.5}})
    page.goto("/offsets")
    cell = page.locator('td[data-offset="G54"][data-field="trans.Y"]')
    expect(cell.locator("input")).to_have_value("7.500")
    cell.locator("input").fill("abc")
    cell.locator("input").press("Enter")
    expect(cell.locator(".field-error")).to_contain_text("enter a number", ignore_case=True)
    expect(cell.locator("input")).to_have_value("abc")
    assert api.get("/api/offsets/G54").json()["trans"]["Y"] == 7.5


def test_measure_workpiece_softkeys_and_submenu(page, api):
    page.goto("/jog")
    page.keyboard.press("F1")                      # horizontal softkey 1 = Measure workpiece
    vkeys = page.locator("#vsoftkeys")
    expect(vkeys).to_contain_text("Measure edge >")
    for label in ("Measure corner >", "Measure pocket/hole >", "Measure spigot >", "Orient plane",
                  "Calibrate probe >", "Back"):
        expect(vkeys).to_contain_text(label)
    expect(page).to_have_url("/measure/workpiece")
    vkeys.get_by_text("Measure edge >").click()
    for label in ("Set edge", "Align edge", "Distance 2 edges"):
        expect(vkeys).to_contain_text(label)
    page.keyboard.press("Shift+F1")                # vertical softkey 1 = Set edge
    expect(page.locator("#screen")).to_have_attribute("data-task", "edge.set")
    expect(page).to_have_url("/measure/workpiece/edge/set")
    vkeys.get_by_text("Back").click()
    expect(vkeys).to_contain_text("Align edge")


def test_machine_view_renders_scene_and_probe(page, api):
    page.goto("/machine-view")
    for view in ("top", "front"):
        svg = page.locator(f"#view-{view}")
        expect(svg.locator("polygon.block")).to_have_count(1)
        expect(svg.locator(f"#probe-{view} circle.ball")).to_have_count(1)
    tip = page.locator("#scene-views .tip")
    x = TEST_SCENARIO["start"]["X"]                 # the probe's tip is on the spindle axis
    expect(tip).to_contain_text(f"X {x:.3f}")
    api.post("/api/machine/jog", json={"axis": "X", "distance": 25})
    expect(tip).to_contain_text(f"X {x + 25:.3f}")


def test_reset_key_clears_an_alarm(page, api):
    api.post("/api/machine/goto", json={"X": 300, "Y": 200, "coords": "MCS"})
    assert api.post("/api/machine/jog", json={"axis": "Z", "distance": -50}).status_code == 409
    page.goto("/jog")
    expect(page.locator("#alarm-line")).to_contain_text("61302")
    page.keyboard.press("Escape")
    expect(page.locator("#alarm-line")).not_to_contain_text("61302")
    assert api.get("/api/machine").json()["alarms"] == []


def test_press_and_hold_jogs_continuously_until_release(page, api):
    page.goto("/jog")
    page.locator('#mcp button[data-axis="Y"]').click()
    expect(page.locator("#mcp")).to_have_attribute("data-axis", "Y")   # the panel is swapped in first
    page.locator('#mcp button[data-increment="cont"]').click()
    expect(page.locator("#mcp")).to_have_attribute("data-increment", "cont")
    plus = page.locator('#mcp button[data-jog="+"]')
    plus.hover()
    page.mouse.down()
    # the test machine runs at time_scale 0: the held key drives Y straight to its limit (500)
    expect(wcs_value(page, "Y")).to_have_text("500.000", timeout=15000)   # generous on a loaded CI box
    page.mouse.up()
    state = api.get("/api/machine").json()
    assert state["busy"] is False and state["mcs"]["Y"] == pytest.approx(500.0)


def test_softkey_shortcuts_switch_screens(page, api):
    page.goto("/jog")
    page.keyboard.press("F3")
    expect(page.locator("#screen")).to_have_attribute("data-screen", "offsets")
    page.keyboard.press("F4")
    expect(page.locator("#screen")).to_have_attribute("data-screen", "tools")
    expect(page.locator('tr[data-tool="9"]')).to_contain_text("in spindle")
    page.keyboard.press("F8")
    expect(page.locator("#screen")).to_have_attribute("data-screen", "jog")

"""End to end in Chromium on the simulated lathe: every lathe task on its input screen (the
product extension "Measure on the lathe"), the machine view, the tool list and the probe data.

Pre-positioning goes through the API (what the operator does with the traverse keys); the task
fields, NC Start, the result and the correction are the screen's. Expected values come from the
scenario's truth (tests/lathe/lathe_kit.py), never from the HMI's answers.
"""

from __future__ import annotations

import re

import pytest
from lathe_kit import TRUE_FACES
from live import browser_tab
from playwright.sync_api import expect

pytestmark = pytest.mark.e2e


@pytest.fixture
def tab(browser, lathe_server):
    with browser_tab(browser, lathe_server, timeout_ms=15000) as page:
        yield page


def open_task(tab, label: str, slug: str) -> None:
    tab.goto("/measure/lathe")
    tab.locator("#vsoftkeys").get_by_text(re.compile(f"^{re.escape(label)}")).click()
    expect(tab).to_have_url(f"/measure/lathe/{slug}")
    expect(tab.locator(".product-extension")).to_contain_text("radius values")      # no spec reference (issue 29 item 5)


def fill(tab, **fields) -> None:
    """Type into the fields by API name (``tolerance__safe_area`` = ``tolerance.safe_area``)."""
    for name, value in fields.items():
        locator = tab.locator(f"#f-{name.replace('__', '-')}")
        if locator.evaluate("e => e.tagName") == "SELECT":
            locator.select_option(str(value))
        else:
            locator.fill(str(value))


def nc_start(tab) -> None:
    tab.locator("#nc-start").click()
    expect(tab.locator("#task-result")).to_be_visible(timeout=15000)


def result(tab, label: str):
    return tab.locator(f'#task-result [data-result="{label}"]')


def test_the_lathe_menu_is_the_f1_softkey_of_a_lathe(tab, lathe):
    tab.goto("/jog")
    tab.locator("#hsoftkeys").get_by_text("Measure turned part").click()
    expect(tab).to_have_url("/measure/lathe")
    expect(tab.locator("#screen h1")).to_have_text("Measure on the lathe (product extension)")
    expect(tab.locator(".product-extension")).to_contain_text("X values are diameters")
    keys = tab.locator("#vsoftkeys")
    for label in ("Calibrate tool probe", "Measure tool L1/L2", "Measure tool automatic", "Calibrate probe in groove",
                  "Calibrate probe on surface", "1-point measurement", "2-point measurement"):
        expect(keys).to_contain_text(label)
    expect(tab.locator("#hsoftkeys")).not_to_contain_text("Measure workpiece")
    expect(tab.locator('td.value[data-axis="X"] + td.unit')).to_have_text("mm Ø")


def test_tool_probe_and_the_turning_tool_on_the_screens(tab, lathe):
    lathe.tool(7)
    lathe.tip_to(7, 420.0, 240.0)
    open_task(tab, "Calibrate tool probe", "toolprobe")
    expect(tab.locator(".lathe-tool")).to_contain_text("T7")
    fill(tab, axis="X", measuring_path=1, tolerance__safe_area=1)
    nc_start(tab)
    expect(result(tab, "Trigger X-")).to_have_text(f"{TRUE_FACES['X-']:.3f}")
    expect(tab.locator('table.correction[data-target="TP1"] [data-after="Face X-"]')).to_have_text("400.250")
    # the other three faces as the API user would (the screen is the same)
    lathe.tip_to(7, 420.0, 240.0)
    lathe.task("lathe.toolprobe.calibrate", {"axis": "Z", "measuring_path": 1, "tolerance": {"safe_area": 1}})
    lathe.tip_to(7, 420.0, 240.0)
    lathe.goto(X=360.0)
    lathe.task("lathe.toolprobe.calibrate", {"axis": "X", "measuring_path": 1, "tolerance": {"safe_area": 1}})
    lathe.goto(Z=210.0)
    lathe.goto(X=430.0)
    lathe.task("lathe.toolprobe.calibrate", {"axis": "Z", "measuring_path": 1, "tolerance": {"safe_area": 1}})
    lathe.goto(X=430.0)
    lathe.tool(3)
    lathe.tip_to(3, 420.0, 240.0)
    open_task(tab, "Measure tool automatic", "toolauto")
    fill(tab, compensation="geometry", measuring_path=1, tolerance__safe_area=1, tolerance__dim_difference=0.8)
    nc_start(tab)
    expect(result(tab, "L1 measured")).to_have_text("100.700")
    expect(result(tab, "L2 measured")).to_have_text("60.300")
    correction = tab.locator('table.correction[data-target="T3 D1"]')
    expect(correction.locator('[data-after="L1"]')).to_have_text("100.700")
    expect(correction.locator('[data-after="L2"]')).to_have_text("60.300")
    tool = lathe.ok(lathe.c.get("/api/tools/3"))
    assert abs(tool["l1"] - 100.70) <= 2e-3 and abs(tool["l2"] - 60.30) <= 2e-3
    # one length as a re-measurement into the wear
    lathe.tip_to(3, 420.0, 240.0)
    open_task(tab, "Measure tool L1/L2", "tool")
    fill(tab, axis="Z", compensation="wear", measuring_path=1, tolerance__safe_area=1)
    nc_start(tab)
    expect(result(tab, "L2 difference")).to_have_text("0.000")


def test_groove_calibration_and_the_eccentric_shaft_with_reversal(tab, lathe):
    lathe.tool(8)
    lathe.ball_to(80.0, 40.0)
    open_task(tab, "Calibrate probe in groove", "groove")
    fill(tab, axis="X", direction="both", skew="yes", ball_diameter="yes", measuring_path=2, tolerance__safe_area=4)
    nc_start(tab)
    expect(result(tab, "Position deviation X")).to_have_text("0.004")
    expect(result(tab, "Trigger X-")).to_have_text("2.995")
    expect(result(tab, "Effective ball diameter")).to_have_text("5.990")
    expect(tab.locator('table.correction[data-target="WP1"]')).to_be_visible()
    lathe.ball_to(60.0, 30.0, coords="WCS")
    open_task(tab, "1-point measurement", "point")
    fill(tab, axis="X", setpoint=45, reversal="yes", start_angle=0, measuring_path=2)
    nc_start(tab)
    expect(result(tab, "Actual value")).to_have_text("45.006")
    expect(tab.locator('#task-result tr:has([data-result="Actual value"]) td.unit')).to_have_text("mm Ø")
    expect(tab.locator("#task-result")).to_contain_text("Measure only")


def test_face_into_g54_on_the_one_point_screen(tab, lathe):
    lathe.calibrate_probe_in_groove()
    lathe.ok(lathe.c.put("/api/offsets/G54", json={"trans": {"Z": 0.5}}))
    lathe.ok(lathe.c.post("/api/machine/activate", json={"offset": "G54"}))
    lathe.ball_to(40.0, 80.0, coords="WCS")
    open_task(tab, "1-point measurement", "point")
    fill(tab, target="G54", axis="Z", setpoint=60, measuring_path=2)
    nc_start(tab)
    expect(result(tab, "Actual value")).to_have_text("59.500")
    expect(tab.locator('table.correction[data-target="G54"] [data-after="Offset Z"]')).to_have_text("0.000")
    expect(tab.locator("#task-result .activation")).to_contain_text("written and activated")
    assert abs(lathe.ok(lathe.c.get("/api/offsets/G54"))["trans"]["Z"]) < 1e-9


def test_two_point_diameter_corrects_the_tool(tab, lathe):
    lathe.calibrate_probe_in_groove()
    lathe.ball_to(60.0, 30.0, coords="WCS")
    open_task(tab, "2-point measurement", "twopoint")
    expect(tab.locator('[data-field="target.tool"]')).to_be_hidden()
    fill(tab, target="tool")
    expect(tab.locator('[data-field="target.tool"]')).to_be_visible()
    fill(tab, target__tool=1, target__correct="length", target__mode="wear", axis="X", setpoint=45, zone__Z=70,
         zone__X=60, measuring_path=2, tolerance__upper=0.003, tolerance__lower=-0.003)
    nc_start(tab)
    expect(result(tab, "Diameter")).to_have_text("45.006")
    expect(result(tab, "Compensation (radius)")).to_have_text("-0.003")
    expect(tab.locator("#task-result .decision")).to_contain_text("Oversize")
    expect(tab.locator('table.correction [data-after="Wear L1"]')).to_have_text("-0.003")
    assert abs(lathe.ok(lathe.c.get("/api/tools/1"))["wear"]["l1"] + 0.003) < 1e-9


def test_probe_on_a_surface_screen(tab, lathe):
    lathe.tool(8)
    lathe.ball_to(20.0, 80.0)
    open_task(tab, "Calibrate probe on surface", "surface")
    fill(tab, axis="Z", direction="-", setpoint=60, measuring_path=3, tolerance__safe_area=4)
    nc_start(tab)
    expect(result(tab, "Trigger Z-")).to_have_text("2.995")


def test_an_alarm_on_the_screen(tab, lathe):
    """A turning tool cannot measure the workpiece: 61315, nothing stored."""
    lathe.tool(1)
    open_task(tab, "1-point measurement", "point")
    fill(tab, axis="X", setpoint=45)
    tab.locator("#nc-start").click()
    expect(tab.locator(".task-alarm")).to_contain_text("61315")


def test_machine_view_draws_the_lathe(tab, lathe):
    lathe.ball_to(30.0, 30.0)
    tab.goto("/machine-view")
    svg = tab.locator('svg[data-kind="lathe"]')
    expect(svg).to_be_visible()
    expect(svg.locator('rect[data-kind="part"]')).to_have_count(1)
    expect(svg.locator('rect[data-kind="bore"]')).to_have_count(1)
    expect(svg.locator('rect[data-kind="tool_probe"]')).to_have_count(1)
    expect(svg.locator('rect[data-kind="chuck"]')).to_have_count(1)
    expect(svg.locator('circle[data-kind="probe"]')).to_have_count(1)
    # the view shows the truth: the ball centre 0.004 above where the NC's nominal L1 puts it
    expect(tab.locator("#scene-views .tip")).to_contain_text("X 30.004 · Z 30.000")


def test_tool_list_and_probe_data_show_l1_l2_sl(tab, lathe):
    tab.goto("/tools")
    header = tab.locator("table.tools-table thead")
    for label in ("SL", "L1 (X)", "L2 (Z)", "Wear L1", "Wear L2"):
        expect(header).to_contain_text(label)
    cell = tab.locator('td[data-tool="3"][data-field="l1"] input')
    expect(cell).to_have_value("100.650")
    cell.fill("100.7")
    cell.dispatch_event("change")
    expect(tab.locator('td[data-tool="3"][data-field="l1"] input')).to_have_value("100.700")
    assert lathe.ok(lathe.c.get("/api/tools/3"))["l1"] == 100.7
    tab.goto("/probes")
    expect(tab.locator(".lathe-tool [data-field='sl']")).to_have_text("7")
    expect(tab.locator(".lathe-tool [data-field='l1']")).to_contain_text("40.1230")
    expect(tab.locator('[data-field="position_deviation.X"]')).to_be_visible()
    groove = tab.locator('form.groove-form[data-groove="1"]')
    expect(groove.locator('input[name="groove.x_plus"]')).to_have_value("60.1230")
    tab.goto("/tool-probes")
    expect(tab.locator('[data-field="trigger.Z-"] input')).to_have_value("220.0000")
    expect(tab.locator("#screen")).to_contain_text("leading point")


LATHE_SCREENS = ("toolprobe", "tool", "toolauto", "groove", "surface", "point", "twopoint")
PARAMETER_NAME = re.compile(r"(^|[\s(])_[A-Z]{2,}")          # _TZL, _FA, _CHBIT[3], (_MVAR=1000)


@pytest.mark.parametrize("lang", ["en", "de", "zh"])
def test_lathe_screens_speak_the_operators_words(tab, lathe, lang):
    """Issue 29 item 5: every label in the operator's words, the cycle parameter under it (a
    secondary line), no spec reference; the feed's unit whole; the tool screens say that the
    operator positions the tool."""
    tab.goto(f"/jog?lang={lang}")
    for slug in LATHE_SCREENS:
        tab.goto(f"/measure/lathe/{slug}")
        screen = tab.locator("#screen")
        expect(screen).to_have_attribute("data-task", re.compile(r"^lathe\."))
        assert "turning.md" not in screen.inner_text() and "§" not in screen.inner_text()
        mains = screen.locator(".task-form .field > label .label-main").all_text_contents()
        assert len(mains) >= 6, (slug, mains)
        for text in mains:
            assert not PARAMETER_NAME.search(text), (slug, text)
            assert "DIAMON" not in text, (slug, text)
        params = screen.locator(".task-form .field > label .cycle-param").all_text_contents()
        assert {"_FA", "_VMS", "_PRNUM", "_NMSP"} <= set(params), (slug, params)
        for option in screen.locator(".task-form select option").all_text_contents():
            assert not PARAMETER_NAME.search(option), (slug, option)
        path = screen.locator('[data-field="measuring_path"]')
        expect(path.locator(".cycle-param")).to_have_text("_FA")
        # the unit column shows "mm/min" on one line, nothing cut (it read "mm/m")
        unit = screen.locator('[data-field="feed"] .unit')
        expect(unit).to_have_text("mm/min")
        fits = unit.evaluate("e => e.scrollWidth <= e.clientWidth + 1 && e.getBoundingClientRect().height < 20")
        assert fits, slug
        hint = screen.locator(".task-left > p.hint")
        if slug in ("toolprobe", "tool", "toolauto"):
            expect(hint).to_contain_text({"en": "Position the tool", "de": "Werkzeug", "zh": "刀具"}[lang])
        else:
            expect(hint).to_contain_text({"en": "Position the probe", "de": "Messtaster", "zh": "测量头"}[lang])
    if lang == "en":
        mains = tab.locator(".task-form .field > label .label-main").all_text_contents()
        assert "Measuring feed (0: 150 or 300)" in mains and "Zero offset range (Ø on X)" in mains
    else:
        feed = tab.locator('[data-field="feed"] .label-main')
        expect(feed).not_to_have_text(re.compile("Measuring feed"))
        expect(tab.locator('[data-field="tolerance.zero_range"] .label-main')).not_to_have_text(
            re.compile("Zero offset range"))


def test_lathe_results_in_the_operators_language(tab, lathe):
    """The result and correction rows and the set-up picture of a lathe screen in German."""
    lathe.tool(8)
    lathe.ball_to(20.0, 80.0)
    tab.goto("/jog?lang=de")
    tab.goto("/measure/lathe/surface")
    fill(tab, axis="Z", direction="-", setpoint=60, measuring_path=3, tolerance__safe_area=4)
    nc_start(tab)
    expect(result(tab, "Schaltwert Z-")).to_have_text(re.compile(r"^2[.,]995$"))
    box = tab.locator("#task-result")
    for english in ("Trigger", "Position deviation", "Effective", "Written"):
        expect(box).not_to_contain_text(english)
    expect(tab.locator("#task-svg figcaption").first).to_contain_text("Reale Aufspannung")


def test_the_feed_unit_whole_in_inch_and_chinese(tab, lathe):
    """Chinese with inch (issue 29): the feed's unit reads inch/min on one line, nothing cut."""
    assert lathe.c.put("/api/settings", json={"units": "inch"}).status_code == 200
    try:
        tab.set_viewport_size({"width": 1024, "height": 768})
        tab.goto("/jog?lang=zh")
        tab.goto("/measure/lathe/twopoint")
        unit = tab.locator('[data-field="feed"] .unit')
        expect(unit).to_have_text("inch/min")
        assert unit.evaluate("e => e.scrollWidth <= e.clientWidth + 1 && e.getBoundingClientRect().height < 20")
    finally:
        assert lathe.c.put("/api/settings", json={"units": "mm"}).status_code == 200

"""End to end in Chromium: the help picture on each measuring screen shows the points in their
order and the direction each is probed in, as the spec's tables say (jog-measuring.md §2.5.1,
§2.6 [I] corner table, §2.7.1), and follows the operator's choices; the equipment the function
uses is shown beside it (the probe data, the calibration ring, the tool probe of the scenario)."""

from __future__ import annotations

import pytest
from hmi_testdata import TEST_SCENARIO
from playwright.sync_api import expect

pytestmark = pytest.mark.e2e


def directions(page) -> dict[str, str]:
    touches = page.locator("#task-help .help-touch")
    return {touches.nth(i).get_attribute("data-point"): touches.nth(i).get_attribute("data-dir")
            for i in range(touches.count())}


def test_a_corner_shows_p1_to_p3_toward_the_material_and_follows_position_and_kind(page, api):
    page.goto("/measure/workpiece/corner/right")
    help_box = page.locator("#task-help")
    expect(help_box.locator("figure.help-picture")).to_have_attribute("data-touches", "3")
    # outside, front-left: P1, P2 on the front edge probed +Y, P3 on the left edge probed +X
    assert directions(page) == {"P1": "+Y", "P2": "+Y", "P3": "+X"}
    page.locator('#task-form .pos-choice:has(input[value="3"])').click()     # back-right
    expect(help_box.locator('[data-point="P1"]')).to_have_attribute("data-dir", "-Y")
    assert directions(page) == {"P1": "-Y", "P2": "-Y", "P3": "-X"}
    page.locator('#task-form [name="kind"]').select_option("inside")         # toward the walls
    expect(help_box.locator('[data-point="P1"]')).to_have_attribute("data-dir", "+Y")
    assert directions(page) == {"P1": "+Y", "P2": "+Y", "P3": "+X"}
    expect(help_box.locator('[data-point="P0"]')).to_have_count(1)
    expect(help_box.locator("figcaption")).to_contain_text("P3 on the second edge")


def test_set_edge_follows_axis_and_direction(page, api):
    page.goto("/measure/workpiece/edge/set")
    assert directions(page) == {"P1": "+X"}
    page.locator('#task-form [name="axis"]').select_option("Y")
    expect(page.locator('#task-help [data-point="P1"]')).to_have_attribute("data-dir", "+Y")
    page.locator('#task-form [name="direction"]').select_option("-")
    expect(page.locator('#task-help [data-point="P1"]')).to_have_attribute("data-dir", "-Y")
    page.locator('#task-form [name="axis"]').select_option("Z")
    expect(page.locator('#task-help [data-point="P1"]')).to_have_attribute("data-dir", "-Z")   # down onto the top


def test_one_hole_is_probed_outwards_and_a_spigot_inwards(page, api):
    page.goto("/measure/workpiece/pocket/hole1")
    assert directions(page) == {"+X": "+X", "-X": "-X", "+Y": "+Y", "-Y": "-Y"}
    page.goto("/measure/workpiece/spigot/spigot1")
    assert directions(page) == {"+X": "-X", "-X": "+X", "+Y": "-Y", "-Y": "+Y"}    # each side from outside
    page.goto("/measure/workpiece/spigot/rect")
    assert directions(page) == {"+X": "-X", "-X": "+X", "+Y": "-Y", "-Y": "+Y"}


def test_the_equipment_is_shown_where_it_is_used(page, api):
    assert api.put("/api/settings", json={"cal_ring_diameter": 25.0}).status_code == 200
    page.goto("/measure/workpiece/calibrate/radius")
    equipment = page.locator("#task-help dl.equipment")
    expect(equipment.locator('[data-equipment="Calibration ring"]')).to_have_text("Ø 25.000 mm")
    ball = TEST_SCENARIO["probe"]["ball_diameter"]
    expect(equipment.locator('[data-equipment="Probe data"]')).to_contain_text(f"ball Ø {ball:.3f} mm")
    expect(page.locator("#task-help figure.help-picture")).to_have_attribute("data-touches", "4")

    page.goto("/measure/tool/length")
    disc = TEST_SCENARIO["tool_probe"]["disc_diameter"]
    expect(page.locator('#task-help [data-equipment="Tool probe"]')).to_contain_text(f"disc Ø {disc:.3f} mm")
    assert directions(page) == {"P1": "-Z"}
    api.put("/api/settings", json={"cal_ring_diameter": 0.0})


def test_the_picture_speaks_chinese_and_german_with_the_manuals_terms(page, api):
    """The ring calibration's picture in Chinese: the label and caption use the manual's 钻孔中心
    (seed 001 line 5107) and carry no English; in German the edge picture's start label is "Start"."""
    page.goto("/measure/workpiece/calibrate/radius?lang=zh")
    figure = page.locator("#task-help figure.help-picture")
    expect(figure.locator("svg .help-probe text")).to_have_text("钻孔中心")
    expect(figure.locator("figcaption")).to_contain_text("大约定位在钻孔中心和校准深度处")
    page.goto("/measure/workpiece/edge/set?lang=de")
    expect(page.locator("#task-help svg .help-probe text")).to_have_text("Start")
    page.goto("/measure/workpiece/edge/set?lang=en")

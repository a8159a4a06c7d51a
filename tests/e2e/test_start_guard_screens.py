"""The start guard on the screens (issue 24 §1) in Chromium: the machine view's 3D panel marks the
segment the guard refuses before NC Start, and NC Start on the measuring screen says why nothing
moved. Truth: the test scenario's Ø20 hole at part (40, 30), block top at MCS z −120; a hole.1
with a typed diameter of 130 mm starts its first approach 13 mm from the centre: into the wall."""

from __future__ import annotations

import re

import pytest
from hmi_testdata import BLOCK_TOP_Z, PROBE_LENGTH, TEST_SCENARIO
from playwright.sync_api import expect

pytestmark = pytest.mark.e2e

CORNER = TEST_SCENARIO["workpiece"]["pose"]["trans"]
HOLE = (CORNER[0] + 40.0, CORNER[1] + 30.0)


def into_the_hole(api) -> dict:
    for target in ({"Z": 0.0}, {"X": HOLE[0], "Y": HOLE[1]}, {"Z": BLOCK_TOP_Z - 10.0 + PROBE_LENGTH}):
        assert api.post("/api/machine/goto", json={**target, "coords": "MCS"}).status_code == 200
    return api.get("/api/machine").json()["mcs"]


def hole1_screen_with_diameter(page, diameter: float):
    """The hole.1 screen, measuring only, with ``diameter`` typed in; returns the diameter field."""
    page.goto("/measure/workpiece/pocket/hole1")
    expect(page.locator("#task-form")).to_be_visible()
    target = page.locator('#task-form select[name="target"]')
    if target.count():
        with page.expect_response("**/refresh"):        # the choice re-draws the screen
            target.select_option("measure_only")
    field = page.locator('#task-form [name="diameter"]')
    field.fill(f"{diameter:g}")
    field.press("Tab")
    expect(page.locator(".htmx-request, .htmx-settling")).to_have_count(0)
    expect(field).to_have_value(f"{diameter:g}")
    return field


def test_the_3d_view_marks_the_refused_segment(page, api):
    into_the_hole(api)
    assert api.post("/api/measure", json={"task": "hole.1", "params": {"diameter": 130}}).status_code == 200
    page.goto("/machine-view")
    view = page.locator("#view3d")
    expect(view).to_have_attribute("data-state", "ready", timeout=15000)
    expect(view).to_have_attribute("data-plan-refused", "1")
    expect(page.locator('[data-out="plan"]')).to_have_text(re.compile(r"^P1 ✕ 1$"))
    assert api.post("/api/measure", json={"task": "hole.1", "params": {"diameter": 20}}).status_code == 200
    expect(view).to_have_attribute("data-plan-refused", "", timeout=5000)      # a path that fits: nothing marked


def test_nc_start_on_the_screen_says_why_nothing_moved(page, api):
    before = into_the_hole(api)
    hole1_screen_with_diameter(page, 130)
    expect(page.locator(".htmx-request")).to_have_count(0)       # the form's own request has answered
    page.locator("#nc-start").click()
    expect(page.locator("body")).to_contain_text("65300", timeout=5000)
    state = api.get("/api/machine").json()
    assert state["mcs"] == before and not state["busy"] and not state["alarms"]


def test_the_measuring_screens_picture_marks_the_refused_segment(page, api):
    before = into_the_hole(api)
    field = hole1_screen_with_diameter(page, 130)
    top = page.locator("#task-svg-top")
    expect(top).to_have_attribute("data-guard-refused", re.compile(r"^P1"), timeout=5000)
    expect(top.locator(".guard-refused")).to_have_count(1)
    field.fill("20")
    field.press("Tab")
    expect(page.locator("#task-svg-top .guard-refused")).to_have_count(0, timeout=5000)
    assert api.get("/api/machine").json()["mcs"] == before

"""The server's measuring session is the truth (design.md §9.1): a refresh or a second tab shows
the stored points and loses nothing; a measurement at real speed shows its progress and then its
outcome on the screen."""

from __future__ import annotations

import re

import httpx
import numpy as np
import pytest
from hmi_testdata import BLOCK_TOP_Z, PROBE_LENGTH, test_scenario
from live import browser_tab
from playwright.sync_api import expect

pytestmark = pytest.mark.e2e

POSE_T = np.array(test_scenario()["workpiece"]["pose"]["trans"])   # the block's top-front-left corner
URL = "/measure/workpiece/corner/right"


def ball_to(http: httpx.Client, p) -> None:
    for target in ({"Z": 0.0}, {"X": float(p[0]), "Y": float(p[1])}, {"Z": float(p[2]) + PROBE_LENGTH}):
        response = http.post("/api/machine/goto", json={**target, "coords": "MCS"})
        assert response.status_code == 200, response.text


def stored(page, n: int):
    return page.locator(f'#vsoftkeys [data-point="{n}"]')


def test_a_refresh_and_a_second_tab_keep_the_stored_points(browser, live_server, api):
    with browser_tab(browser, live_server) as tab_a, browser_tab(browser, live_server) as tab_b:
        tab_a.goto(URL)
        expect(tab_a.locator("#task-form")).to_be_visible()
        tab_a.locator('#task-form select[name="target"]').select_option("G54")
        ball_to(api, POSE_T + [30.0, -10.0, -10.0])           # in front of the front face: P1 probes +Y
        tab_a.locator("#nc-start").click()
        expect(stored(tab_a, 1)).to_have_class(re.compile(r"\bstored\b"))
        tab_a.reload()
        expect(stored(tab_a, 1)).to_have_class(re.compile(r"\bstored\b"))
        expect(tab_a.locator('#task-form select[name="target"]')).to_have_value("G54")
        tab_b.goto(URL)
        expect(stored(tab_b, 1)).to_have_class(re.compile(r"\bstored\b"))
        assert api.get("/api/measure/current").json()["points"][0]["stored"] is True


def test_a_long_measurement_shows_its_progress_then_its_result(browser, live_server, api):
    scenario = test_scenario()
    scenario["machine"]["time_scale"] = 1.0
    assert api.post("/api/sim/scenario", json={**scenario, "reset_data": True}).status_code == 200
    assert api.put("/api/settings", json={"measuring_feed": 600.0}).status_code == 200
    ball_to(api, [POSE_T[0] + 40.0, POSE_T[1] + 30.0, BLOCK_TOP_Z + 15.0])   # 15 mm above the top face
    with browser_tab(browser, live_server) as tab:
        tab.goto("/measure/workpiece/edge/set")
        tab.locator('#task-form select[name="axis"]').select_option("Z")
        tab.locator('#task-form select[name="direction"]').select_option("-")
        tab.locator("#nc-start").click()
        progress = tab.locator("#task-progress")
        expect(progress).to_contain_text("Measuring P1")
        expect(progress).to_contain_text(re.compile(r"step \d+ of \d+"))
        expect(tab.locator("#task-result")).to_be_visible(timeout=15000)
        expect(progress).to_have_count(0)
        expect(tab.locator("#message")).to_contain_text("Measurement done")
    assert api.put("/api/settings", json={"measuring_feed": 300.0}).status_code == 200

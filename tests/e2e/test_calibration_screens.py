"""Calibrate probe > Radius / Length through the screens, and the probe data screen (Chromium).

Test scenario (tests/hmi_testdata.py): ideal probe (no pre-travel, skew, latency or noise), true
length = nominal, ring gauge of 25 mm at MCS (600, 100, -160): the calibration must give the ideal
values (trigger ±r, skew 0, L1 = 100) and the records must show them.
"""

from __future__ import annotations

import re

import pytest
from hmi_testdata import PROBE_LENGTH, TEST_SCENARIO
from playwright.sync_api import expect

pytestmark = pytest.mark.e2e

RING = TEST_SCENARIO["ring_gauge"]


def _travel(api, x: float, y: float, z: float) -> None:
    for body in ({"Z": -100.0}, {"X": x, "Y": y}, {"Z": z}):
        response = api.post("/api/machine/goto", json={**body, "coords": "WCS"})
        assert response.status_code == 200, response.text


def test_calibrate_radius_then_length_on_the_screens(page, api):
    cx, cy, top = RING["center"]
    assert api.post("/api/machine/activate", json={"offset": "G500"}).status_code == 200
    _travel(api, cx + 0.2, cy - 0.1, top - 8.0)
    page.goto("/measure/workpiece")
    page.get_by_role("link", name=re.compile("Calibrate probe")).first.click()
    expect(page).to_have_url("/measure/workpiece/calibrate")
    page.get_by_role("link", name=re.compile("^Radius")).first.click()
    expect(page).to_have_url("/measure/workpiece/calibrate/radius")
    field = page.locator('input[name="diameter"]')
    field.fill(str(RING["diameter"]))
    field.dispatch_event("change")
    page.locator("#nc-start").click()
    expect(page.locator("#task-result")).to_be_visible()
    record = api.get("/api/probes/1").json()
    assert record["calibrated_radius"] is True
    assert record["trigger"]["X+"] == pytest.approx(-2.0, abs=1e-6)
    assert record["skew"] == pytest.approx([0.0, 0.0], abs=1e-6)

    outer = RING.get("outer_diameter") or RING["diameter"] + 30.0
    _travel(api, cx + (RING["diameter"] + outer) / 4.0, cy, top + 4.0)
    page.goto("/measure/workpiece/calibrate/length")
    field = page.locator('input[name="setpoint"]')
    field.fill(str(top))
    field.dispatch_event("change")
    page.locator("#nc-start").click()
    expect(page.locator("#task-result")).to_be_visible()
    expect(page.locator('[data-result="Length L"]')).to_have_text(f"{PROBE_LENGTH:.3f}")
    assert api.get(f"/api/tools/{TEST_SCENARIO['probe']['t']}").json()["length"] == pytest.approx(PROBE_LENGTH)

    page.goto("/probes")
    expect(page.locator('#screen[data-screen="probes"]')).to_be_visible()
    expect(page.locator('.calibration [data-field="calibrated_radius"]')).to_contain_text("calibrated in a ring")
    expect(page.locator('.calibration [data-field="calibrated_length"]')).to_contain_text("calibrated on a surface")
    expect(page.locator("#wp-trigger\\.X\\+")).to_have_value("-2.0000")


def test_probe_data_screen_validates_and_saves(page, api):
    before = api.get("/api/probes/2")
    page.goto("/probes?n=2")
    expect(page.locator("#screen")).to_have_attribute("data-record", "2")
    page.locator("#wp-trigger\\.X\\+").fill("abc")
    page.locator("#wp-trigger\\.X-").fill("-1.9")
    page.get_by_role("button", name=re.compile("Save")).click()
    expect(page.locator('[data-field="trigger.X+"] .field-error')).to_contain_text("enter a number", ignore_case=True)
    expect(page.locator('[data-field="trigger.X-"] .field-error')).to_contain_text("positive")
    after = api.get("/api/probes/2")                                   # nothing stored
    assert (after.status_code, after.json()) == (before.status_code, before.json())
    page.locator("#wp-trigger\\.X\\+").fill("-1.98")
    page.locator("#wp-trigger\\.X-").fill("1.97")
    page.locator("#wp-skew\\.X").fill("0.01")
    page.get_by_role("button", name=re.compile("Save")).click()
    expect(page.locator(".form-message")).to_contain_text("Probe 2 saved")
    stored = api.get("/api/probes/2").json()
    assert stored["trigger"]["X+"] == -1.98 and stored["trigger"]["X-"] == 1.97
    assert stored["skew"][0] == 0.01

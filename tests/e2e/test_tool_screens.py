"""Measure tool > Calibrate probe / Length / Diameter through the screens, and the tool-probe data
screen (Chromium). Truth: the scenario's cutters (the tool table starts from nominal values tens
of µm off); the calibration tool's data are exact (spec/jog-measuring.md §7.2, §7.3)."""

from __future__ import annotations

import copy
import re

import pytest
from hmi_testdata import test_scenario
from playwright.sync_api import expect

pytestmark = pytest.mark.e2e

TOL = 0.002
CAL_T, CUTTER_T = 5, 1
TRUE_L, TRUE_R = 85.0, 5.0


def _scenario() -> dict:
    sc = copy.deepcopy(test_scenario())
    sc["machine"]["latency_s"] = 0.004
    sc["tool_probe"]["pretravel"] = 0.001
    sc["tools"] = [{"t": CAL_T, "type": 120, "length": 100.0, "radius": 6.0},
                   {"t": CUTTER_T, "type": 120, "length": TRUE_L, "radius": TRUE_R,
                    "nominal": {"length": 85.041, "radius": 5.023}}]
    return sc


@pytest.fixture
def tool_api(api):
    sc = _scenario()
    response = api.post("/api/sim/scenario", json={**sc, "reset_data": True})
    assert response.status_code == 200, response.text
    api.scenario = sc
    return api


def _place(api, t: int, dx: float, dy: float, above: float) -> None:
    """Tool change and positioning (what the operator does with the traverse keys)."""
    cx, cy, top = api.scenario["tool_probe"]["center"]
    for body in ({"Z": 0.0}, ):
        assert api.post("/api/machine/goto", json={**body, "coords": "MCS"}).status_code == 200
    assert api.post("/api/machine/tool", json={"tool": t}).status_code == 200
    length = api.get(f"/api/tools/{t}").json()["length"]
    for body in ({"X": cx + dx, "Y": cy + dy}, {"Z": top + length + above}):
        response = api.post("/api/machine/goto", json={**body, "coords": "MCS"})
        assert response.status_code == 200, response.text


def _open(page, label: str, url: str) -> None:
    page.goto("/measure/tool")
    page.locator("#vsoftkeys").get_by_text(re.compile(f"^{label}")).click()
    expect(page).to_have_url(url)


def test_calibrate_then_length_and_diameter_on_the_screens(page, tool_api):
    api = tool_api
    # Calibrate probe: Select toggles "Length only" -> "Length and diameter"
    _place(api, CAL_T, 0.5, -0.4, 6.0)
    _open(page, "Calibrate probe", "/measure/tool/calibrate")
    expect(page.locator("#f-mode")).to_have_value("length")
    page.locator("#vsoftkeys").get_by_text("Select").click()
    expect(page.locator("#f-mode")).to_have_value("length_diameter")
    page.locator("#nc-start").click()
    expect(page.locator("#task-result")).to_be_visible()
    record = api.get("/api/tool-probes/1").json()
    assert record["calibrated_length"] and record["calibrated_diameter"]
    assert record["calibration_tool"] == CAL_T

    # Length: T1 with nominal data, above the probe
    _place(api, CUTTER_T, 0.3, 0.2, 7.0)
    _open(page, "Length", "/measure/tool/length")
    expect(page.locator("#screen")).to_contain_text("T1")
    page.locator("#nc-start").click()
    expect(page.locator("#task-result")).to_be_visible()
    expect(page.locator('[data-result="Length L1"]')).to_have_text(f"{TRUE_L:.3f}")
    assert abs(api.get(f"/api/tools/{CUTTER_T}").json()["length"] - TRUE_L) <= TOL

    # Diameter: beside and above the probe; writes the radius and shows radius and diameter
    _place(api, CUTTER_T, 30.0, 0.0, 5.0)
    _open(page, "Diameter", "/measure/tool/diameter")
    page.locator("#nc-start").click()
    expect(page.locator("#task-result")).to_be_visible()
    expect(page.locator('[data-result="Radius R"]')).to_have_text(f"{TRUE_R:.3f}")
    expect(page.locator('[data-result="Diameter"]')).to_have_text(f"{2 * TRUE_R:.3f}")
    tool = api.get(f"/api/tools/{CUTTER_T}").json()
    assert abs(tool["radius"] - TRUE_R) <= TOL and tool["wear"]["radius"] == 0.0


def test_negative_offset_v_is_shown_at_the_field_and_nothing_moves(page, tool_api):
    api = tool_api
    _place(api, CUTTER_T, 0.3, 0.2, 7.0)
    before = api.get("/api/machine").json()["mcs"]
    _open(page, "Length", "/measure/tool/length")
    field = page.locator("#f-offset_v")
    field.fill("-1")
    field.dispatch_event("change")
    expect(page.locator("#err-offset_v")).to_contain_text("enter 0 or more")
    page.locator("#nc-start").click()
    expect(page.locator("#err-offset_v")).to_contain_text("enter 0 or more")
    assert api.get("/api/machine").json()["mcs"] == before
    assert api.get(f"/api/tools/{CUTTER_T}").json()["length"] == pytest.approx(85.041)


def test_length_without_calibration_shows_the_alarm(page, tool_api):
    _place(tool_api, CUTTER_T, 0.3, 0.2, 7.0)
    _open(page, "Length", "/measure/tool/length")
    page.locator("#nc-start").click()
    expect(page.locator(".task-alarm")).to_contain_text("61341")


def test_tool_probe_data_screen(page, tool_api):
    api = tool_api
    _place(api, CAL_T, 0.5, -0.4, 6.0)
    _open(page, "Calibrate probe", "/measure/tool/calibrate")
    page.locator("#nc-start").click()                          # length only
    expect(page.locator("#task-result")).to_be_visible()
    record = api.get("/api/tool-probes/1").json()
    page.goto("/tool-probes")
    expect(page.locator('#screen[data-screen="tool_probes"]')).to_be_visible()
    expect(page.locator("#tp-trigger\\.Z-")).to_have_value(f"{record['trigger']['Z-']:.4f}")
    expect(page.locator('.calibration [data-field="calibration_tool"]')).to_have_text(f"T{CAL_T}")
    expect(page.locator('.calibration [data-field="calibrated_diameter"]')).to_have_text("not calibrated")
    page.locator("#tp-axes").fill("143")
    page.locator("#tp-disc_diameter").fill("abc")
    page.get_by_role("button", name=re.compile("Save")).click()
    expect(page.locator('[data-field="axes"] .field-error')).to_contain_text("digit")
    expect(page.locator('[data-field="disc_diameter"] .field-error')).to_contain_text("enter a number", ignore_case=True)
    expect(page.locator("#tp-disc_diameter")).to_have_value("abc")             # typed text kept
    page.locator("#tp-axes").fill("133")
    page.locator("#tp-disc_diameter").fill("20.5")
    page.get_by_role("button", name=re.compile("Save")).click()
    expect(page.locator(".form-message")).to_contain_text("Tool probe 1 saved")
    stored = api.get("/api/tool-probes/1").json()
    assert stored["disc_diameter"] == 20.5 and stored["trigger"] == record["trigger"]

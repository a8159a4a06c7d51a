"""The mode group on the screens (issue 24 §4): while a program runs the control panel greys out
its jog keys and says which program holds them; while a JOG measurement runs the MDA screen's NC
Start is greyed out and names the measurement. The panel's Reset ends either, and the keys come
back."""

from __future__ import annotations

import re

import pytest
from hmi_testdata import test_scenario
from playwright.sync_api import expect

pytestmark = pytest.mark.e2e


def real_time(api) -> None:
    scenario = test_scenario()
    scenario["machine"]["time_scale"] = 1.0
    assert api.post("/api/sim/scenario", json=scenario).status_code == 200


def test_a_running_program_greys_out_the_jog_keys_and_reset_gives_them_back(page, api):
    real_time(api)
    page.goto("/jog")
    jog_key = page.locator("#mcp .key.jog").first
    expect(page.locator("#mcp-lock")).to_be_hidden()
    expect(jog_key).to_be_enabled()
    # X100 -> X600 at 300 mm/min: runs until Reset
    assert api.post("/api/nc/run", json={"mda": "G91 G1 F300 X500", "wait": False}).status_code == 202
    expect(page.locator("#mcp")).to_have_class(re.compile(r"\blocked\b"))
    expect(jog_key).to_be_disabled()
    expect(page.locator("#mcp-lock")).to_be_visible()
    expect(page.locator("#mcp-lock .lock-program")).to_have_text("MDA MDA")
    page.locator("#reset").click()                                   # the panel's Reset ends the program
    expect(page.locator("#mcp-lock")).to_be_hidden()
    expect(jog_key).to_be_enabled()
    assert api.get("/api/nc").json()["state"] == "idle"
    assert api.get("/api/machine").json()["busy"] is False


def test_a_running_jog_measurement_greys_out_nc_start_of_mda(page, api):
    real_time(api)
    moved = api.post("/api/machine/goto", json={"X": 290, "Y": 180, "Z": -100})   # tip (WCS G500) 20 mm above the hole
    assert moved.status_code == 200, moved.text
    session = api.post("/api/measure", json={"task": "hole.1", "params": {}}).json()
    page.goto("/mda")
    expect(page.locator("#mda-start")).to_be_enabled()
    expect(page.locator("#mda-lock")).to_be_hidden()
    started = api.post(f"/api/measure/{session['id']}/start", json={"wait": False})
    assert started.status_code == 202, started.text
    expect(page.locator("#mda-start")).to_be_disabled()
    expect(page.locator("#mda-lock")).to_be_visible()
    expect(page.locator("#mda-lock .lock-program")).to_have_text("hole.1")
    page.locator("#reset").click()
    expect(page.locator("#mda-start")).to_be_enabled()
    expect(page.locator("#mda-lock")).to_be_hidden()
    assert api.get(f"/api/measure/{session['id']}").json()["running"] is False

"""End to end: the PLC test page /plc (DB19.DBB43, spec §3.2) in Chromium.

P1 of "Distance 2 edges" is stored through the API (as the operator's NC Start would); the PLC's
discard request is toggled on the page; the workflow API is the independent check.
"""

from __future__ import annotations

import re

import pytest
from hmi_testdata import BLOCK_TOP_Z, PROBE_LENGTH, TEST_SCENARIO
from playwright.sync_api import expect

pytestmark = pytest.mark.e2e
ON = re.compile(r"\bon\b")
P1_START = (TEST_SCENARIO["workpiece"]["pose"]["trans"][0] - 12.0, 210.0, BLOCK_TOP_Z - 10.0)


def store_p1(api) -> str:
    x, y, z = P1_START
    for target in ({"Z": 0.0}, {"X": x, "Y": y}, {"Z": z + PROBE_LENGTH}):
        assert api.post("/api/machine/goto", json={**target, "coords": "MCS"}).status_code == 200
    session = api.post("/api/measure", json={"task": "edge.distance", "params": {"axis": "X", "direction": "+"}})
    sid = session.json()["id"]
    answer = api.post(f"/api/measure/{sid}/start")
    assert answer.status_code == 200, answer.text
    return sid


def p1_stored(api, sid) -> bool:
    return api.get(f"/api/measure/{sid}").json()["points"][0]["stored"]


def test_toggle_bit_0_discards_p1(page, api):
    sid = store_p1(api)
    page.goto("/plc")
    led4, led0 = page.locator('[data-led="4"]'), page.locator('[data-led="0"]')
    expect(led4).to_have_class(ON)
    expect(led0).not_to_have_class(ON)
    page.locator('[data-toggle="0"]').click()
    expect(led4).not_to_have_class(ON)                  # HMI cleared "P1 stored"
    expect(led0).not_to_have_class(ON)                  # PLC released its request (auto-release)
    expect(page.locator("#plc-db19 .events")).to_contain_text("HMI invalidated P1")
    assert p1_stored(api, sid) is False
    assert api.get("/api/plc/db19").json()["dbb43"] == 0
    expect(page.locator('[data-check="probe_active"]')).to_have_attribute("data-ok", "yes")
    page.screenshot(path="/tmp/plc_page.png")


def test_manual_release_shows_each_handshake_step(page, api):
    sid = store_p1(api)
    page.goto("/plc")
    try:
        page.locator("#auto-release").uncheck()
        expect(page.locator("#auto-release")).not_to_be_checked()
        page.locator('[data-toggle="0"]').click()
        expect(page.locator('[data-led="0"]')).to_have_class(ON)       # PLC holds the request
        expect(page.locator('[data-led="4"]')).not_to_have_class(ON)   # HMI acknowledged
        assert p1_stored(api, sid) is False
        expect(page.locator('[data-toggle="0"]')).to_have_text("Clear")
        page.locator('[data-toggle="0"]').click()                        # handshake step 4
        expect(page.locator('[data-led="0"]')).not_to_have_class(ON)
    finally:
        api.put("/api/plc/db19/mode", json={"auto_release": True})
        api.put("/api/plc/db19/dbb43", json={"bit": 0, "value": False})


def test_commissioning_section_shows_a_wrong_machine_datum_in_chinese(page, api):
    """The control commissioned with MD 18130 = 100 (manual §9.1.1: 130 with "Measure in JOG"): its
    row fails with the rule in the operator's language, the others pass."""
    scenario = {**TEST_SCENARIO, "machine": {**TEST_SCENARIO.get("machine", {}), "machine_data": {"18130": 100}}}
    assert api.post("/api/sim/scenario", json={**scenario, "reset_data": True}).status_code == 200
    page.goto("/plc?lang=zh")
    row = page.locator('#commissioning [data-commissioning="md18130"]')
    expect(row).to_have_attribute("data-ok", "no")
    expect(row).to_contain_text("至少 130")
    expect(row).to_contain_text("未通过")
    expect(page.locator('#commissioning [data-ok="no"]')).to_have_count(1)
    expect(page.locator('#commissioning [data-commissioning="md28082"]')).to_contain_text("§9.1.1")
    page.goto("/plc?lang=en")

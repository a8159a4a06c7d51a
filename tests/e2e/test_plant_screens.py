"""End to end in Chromium: the plant screens (design.md §10.5). Two HMIs share one database: this
live server is machine "mill-1"; a second HMI process's rows (machine "mill-2": a G54, a part, a
measurement, an open alarm) are written through its own database connection, as a second HMI on the
network would. The operator opens Log → Plant, reads both machines, opens mill-2 and reads its part
and measurement, in English and German."""

from __future__ import annotations

import pytest
from hmi_testdata import TEST_SCENARIO
from live import browser_tab, serve
from playwright.sync_api import expect

from db import Database, acting_as
from db.repository import Actor

pytestmark = pytest.mark.e2e


@pytest.fixture
def plant(tmp_path):
    with serve(tmp_path / "mill-1", TEST_SCENARIO, settings={"machine_name": "mill-1"}) as url:
        with Database(tmp_path / "mill-1" / "hmi.db", machine="mill-2") as other:
            with acting_as(Actor("user:bert", 3)), other.unit() as unit:
                unit.put_offset("G54", {"trans": {"X": 5.0}}, source="test")
                part = unit.add_part({"part_number": "PN-7", "serial": "S-0042"})
                unit.add_characteristic(part["id"], {"name": "D1", "nominal": 10.0, "upper": 10.1, "lower": 9.9,
                                                     "actual": 10.2, "verdict": "scrap"})
                unit.add_log({"task": "hole.1", "target": "G54", "status": "ok"})
            other.report_status({"alarms": [{"code": 61303, "text": "Probe not calibrated"}],
                                 "active_offset": "G54", "mode": "JOG"})
            yield url


def test_the_operator_finds_the_other_machine_and_its_part(browser, plant):
    with browser_tab(browser, plant, 1280, 800) as tab:
        tab.goto("/log")
        tab.locator("#vsoftkeys .softkey", has_text="Plant").click()
        expect(tab.locator("#screen")).to_have_attribute("data-screen", "plant")
        rows = tab.locator("table.plant-table tbody tr")
        expect(rows).to_have_count(2)
        this, other = tab.locator('tr[data-machine="mill-1"]'), tab.locator('tr[data-machine="mill-2"]')
        expect(this).to_have_class("this")
        expect(this.locator("td").first).to_have_text("online")
        expect(other).to_contain_text("G54")                     # mill-2's active zero offset
        expect(other).to_contain_text("hole.1")                  # its last measurement
        expect(other.locator('[data-field="alarms"]')).to_have_text("1")

        other.get_by_role("link", name="mill-2").click()
        expect(tab.locator("h1")).to_contain_text("mill-2")
        expect(tab.locator('[data-field="alarms"]')).to_contain_text("61303")
        part = tab.locator("table.plant-parts tbody tr").first
        expect(part).to_contain_text("PN-7")
        expect(part).to_contain_text("S-0042")
        expect(part.locator("td.verdict-scrap")).to_have_text("Scrap")
        expect(tab.locator("table.plant-measurements tbody tr").first).to_contain_text("hole.1")

        tab.goto("/plant/mill-2?lang=de")
        expect(tab.locator("table.plant-parts td.verdict-scrap")).to_have_text("Ausschuss")
        expect(tab.locator("h2").first).to_have_text("Teile")

"""End to end in Chromium: the parts screen, the printable per-part protocol and the run chart
(design.md §10.3). The operator starts a job on the screen, measures three bores of known true
diameter (noise-free scenario: the measured diameter is the true one), goes on part by part with
the "Next part" softkey, reads the verdicts, prints a part's protocol (page.pdf) and opens the
run chart. Expected verdicts follow from the tolerance set here (docs/results.md: a bore below its
lower limit keeps material: rework; above its upper limit: scrap)."""

from __future__ import annotations

import re

import httpx
import pytest
from hmi_testdata import PROBE_LENGTH, test_scenario
from live import browser_tab
from playwright.sync_api import expect

pytestmark = pytest.mark.e2e

HOLE = (100.0, 60.0)
POSE_T = (250.0, 150.0, -120.0)
NOMINAL = 32.0
TOLERANCE = {"setpoint": NOMINAL, "upper": 0.02, "lower": -0.02}
SERIES = ((32.005, "OK"), (32.03, "scrap"), (31.97, "rework"))


def bore_scenario(diameter: float) -> dict:
    s = test_scenario()
    s["workpiece"]["features"] = [{"type": "block", "size": [200, 120, 60]},
                                  {"type": "hole", "center": list(HOLE), "diameter": diameter, "depth": 25}]
    return s


@pytest.fixture
def station(live_server):
    with httpx.Client(base_url=live_server, timeout=20) as http:
        assert http.post("/api/sim/scenario", json={**bore_scenario(NOMINAL), "reset_data": True}).status_code == 200
        assert http.post("/api/machine/tool", json={"tool": 9}).status_code == 200
        yield http
        http.delete("/api/job")
        http.post("/api/sim/scenario", json={**test_scenario(), "reset_data": True})


def measure_bore(http: httpx.Client, diameter: float) -> None:
    assert http.post("/api/sim/scenario", json=bore_scenario(diameter)).status_code == 200
    x, y = POSE_T[0] + HOLE[0], POSE_T[1] + HOLE[1]
    for target in ({"Z": 0.0}, {"X": x, "Y": y}, {"Z": POSE_T[2] - 8.0 + PROBE_LENGTH}):
        assert http.post("/api/machine/goto", json={**target, "coords": "MCS"}).status_code == 200
    session = http.post("/api/measure", json={"task": "hole.1", "target": "measure_only",
                                              "params": {"diameter": NOMINAL, "tolerance": TOLERANCE}}).json()
    assert http.post(f"/api/measure/{session['id']}/start", json={}).status_code == 200


def test_job_parts_protocol_and_run_chart(browser, live_server, station, tmp_path):
    with browser_tab(browser, live_server, 1280, 800, timeout_ms=8000) as tab:
        tab.goto("/log")
        tab.locator("#vsoftkeys .softkey", has_text="Parts").click()
        expect(tab.locator("#screen")).to_have_attribute("data-screen", "parts")

        tab.fill("#job-part_number", "x" * 70)                   # too long: refused, the field marked
        tab.click("#job-start")
        expect(tab.locator('.field[data-field="part_number"]')).to_have_class("field invalid")
        assert station.get("/api/job").json()["active"] is False

        tab.fill("#job-part_number", "E2E-BORE")
        tab.fill("#job-order", "A-77")
        tab.fill("#job-operator", "anna")
        tab.click("#job-start")
        expect(tab.locator(".job-now")).to_contain_text("E2E-BORE")
        for index, (diameter, _verdict) in enumerate(SERIES):
            if index:
                tab.locator("#vsoftkeys .softkey", has_text="Next part").click()
                expect(tab.locator(".job-now")).to_contain_text(f"part {index + 1} ")
            measure_bore(station, diameter)

        tab.goto("/parts")
        rows = tab.locator("table.parts-table tbody tr")
        expect(rows).to_have_count(3)
        for row, (_diameter, verdict) in zip(range(3), reversed(SERIES), strict=True):   # newest first
            expect(rows.nth(row).locator("td.verdict")).to_have_text(verdict)

        scrap_part = station.get("/api/parts", params={"part_number": "E2E-BORE"}).json()[1]
        tab.goto(f"/parts/{scrap_part['id']}/protocol")
        expect(tab.locator("#p-part")).to_have_text("E2E-BORE")
        expect(tab.locator("#p-serial")).to_have_text("2")
        expect(tab.locator("#p-verdict")).to_have_text("scrap")
        expect(tab.locator('tr[data-name="diameter"] td.mark')).to_have_text("#")
        expect(tab.locator(".signatures")).to_contain_text("Operator")
        pdf = tab.pdf(format="A4", print_background=True)
        assert pdf.startswith(b"%PDF")
        assert len(re.findall(rb"/Type\s*/Page[^s]", pdf)) == 1        # one clean A4 page
        tab.emulate_media(media="print")
        expect(tab.locator(".no-print")).to_be_hidden()          # the print button stays off the paper

        tab.emulate_media(media="screen")
        tab.goto("/spc?part_number=E2E-BORE")
        expect(tab.locator("svg.run-chart circle.value")).to_have_count(3)
        expect(tab.locator('td[data-key="n"]')).to_have_text("3")
        expect(tab.locator("svg.run-chart line.upper")).to_have_count(1)
        expect(tab.locator("#spc-char")).to_have_value("diameter")

"""End to end in Chromium: workpiece measuring with automatic tool offset (design.md §9.3).

The operator types the empirical value on the EV/MV memories screen, measures a bore on the
"1 hole" screen with the target "Tool offset", and reads the strategy's decision and the tool's
wear before/after. The expected numbers are measuring-math §3.5's rule applied by hand to the
bore's true diameter (noise-free scenario): D = actual - setpoint - EV, k = 1 so Mv = D, and
_TZL < Mv <= _TMV corrects the radius wear by Mv/2.
"""

from __future__ import annotations

import httpx
import pytest
from hmi_testdata import PROBE_LENGTH, test_scenario
from live import browser_tab
from playwright.sync_api import expect

pytestmark = pytest.mark.e2e

TRUE_DIAMETER, SETPOINT, EV = 32.019, 32.0, 0.004
HOLE = (100.0, 60.0)                                  # part coordinates of the bore
POSE_T = (250.0, 150.0, -120.0)                       # the test scenario's block pose (top face)


def bore_scenario() -> dict:
    s = test_scenario()
    s["workpiece"]["features"] = [{"type": "block", "size": [200, 120, 60]},
                                  {"type": "hole", "center": list(HOLE), "diameter": TRUE_DIAMETER, "depth": 25}]
    s["tools"] = [*s["tools"], {"t": 20, "type": 120, "length": 90.0, "radius": 8.0}]
    return s


@pytest.fixture
def station(live_server):
    with httpx.Client(base_url=live_server, timeout=20) as http:
        assert http.post("/api/sim/scenario", json={**bore_scenario(), "reset_data": True}).status_code == 200
        assert http.post("/api/machine/tool", json={"tool": 9}).status_code == 200
        yield http
        http.post("/api/sim/scenario", json={**test_scenario(), "reset_data": True})


def ball_into_bore(http: httpx.Client) -> None:
    x, y = POSE_T[0] + HOLE[0], POSE_T[1] + HOLE[1]
    for target in ({"Z": 0.0}, {"X": x, "Y": y}, {"Z": POSE_T[2] - 8.0 + PROBE_LENGTH}):
        assert http.post("/api/machine/goto", json={**target, "coords": "MCS"}).status_code == 200


def test_memory_then_bore_corrects_the_tool_wear(browser, live_server, station):
    with browser_tab(browser, live_server, 1280, 800, timeout_ms=8000) as tab:
        tab.goto("/tools")
        tab.locator("#vsoftkeys .softkey", has_text="EV / MV memories").click()
        expect(tab.locator("#screen")).to_have_attribute("data-screen", "memories")
        cell = tab.locator('td[data-memory="ev10"] input')
        cell.fill("0,004")
        cell.press("Tab")
        expect(tab.locator('td[data-memory="ev10"] input')).to_have_value("0.0040")
        assert station.get("/api/memories/ev/10").json()["value"] == pytest.approx(EV, abs=1e-12)

        bad = tab.locator('td[data-memory="mv10"] input')
        bad.fill("lots")
        bad.press("Tab")
        expect(tab.locator('td[data-memory="mv10"] .field-error')).to_contain_text("enter a number")
        assert station.get("/api/memories/mv/10").json()["value"] == 0.0           # nothing written

        ball_into_bore(station)
        tab.goto("/measure/workpiece/pocket/hole1")
        tool_fields = tab.locator('#task-form [data-group="tool"]')
        expect(tool_fields.first).to_be_hidden()
        tab.locator('#task-form [name="target"]').select_option("tool")
        expect(tab.locator('#task-form [name="tool_target.tool"]')).to_be_visible()
        for name, value in {"diameter": SETPOINT, "tool_target.tool": 20, "tolerance.setpoint": SETPOINT,
                            "tolerance.upper": 0.03, "tolerance.lower": -0.03, "tolerance.zero_range": 0.005,
                            "tolerance.mean_range": 0.02, "tolerance.dim_difference": 0.06,
                            "tolerance.safe_area": 1, "tolerance.k": 1, "tolerance.evnum": 10}.items():
            field = tab.locator(f'#task-form [name="{name}"]')
            field.fill(str(value))
            field.press("Tab")
        tab.locator("#nc-start").click()
        expect(tab.locator("#task-result")).to_be_visible()
        expect(tab.locator(".decision")).to_contain_text("Corrected by the mean value")

        deviation = TRUE_DIAMETER - SETPOINT - EV                      # 0.015 = Mv with k = 1
        wear = station.get("/api/tools/20").json()["wear"]["radius"]
        assert wear == pytest.approx(deviation / 2.0, abs=1e-6)
        row = tab.locator("#task-result tr", has_text="Wear radius")
        before, after = (float(t) for t in row.locator("td").all_inner_texts()[-2:])
        assert before == 0.0 and after == pytest.approx(deviation / 2.0, abs=5.01e-4)   # 3 decimals shown
        assert station.get("/api/offsets/G54").json()["trans"]["X"] == 0.0     # no zero offset written

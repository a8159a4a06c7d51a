"""End to end: the set-up support activation screen (spec §6.2, manual §4.3.9) in Chromium.

Example 1: 4 holes measured under G500 into G54 -> "You are compensating in an inactive WO!",
NC Start activates G54, no axis motion. Example 2: orient plane into G54 on a machine without
swivel -> re-alignment not possible, NC Start activates. Rotary table: align edge with C ->
NC Start turns C. Measurements run through the API (the operator's probe positions come from
the truth, tests/flows/test_chain_truth.Operator); the activation screen is driven in the browser.
"""

from __future__ import annotations

import copy
import sys
from pathlib import Path

import pytest
from live import browser_tab, serve
from playwright.sync_api import expect

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "flows"))
from test_chain_truth import CHAIN_SCENARIO, Operator, run_points  # noqa: E402

pytestmark = pytest.mark.e2e
SCREENSHOT = Path("/tmp/setup_support.png")

FLAT = copy.deepcopy(CHAIN_SCENARIO)
FLAT["rotary_axes"] = {"C": {"limits": [-360, 360]}}
FLAT["machine"]["rotary_table"] = {"axis": "C", "center": [350.0, 210.0]}
FLAT["workpiece"] = {
    "pose": {"trans": [250.0, 150.0, -120.0], "rot": [0.0, 0.0, 4.0]},
    "features": [{"type": "block", "size": [200, 120, 60]}] + [
        {"type": "hole", "center": list(c), "diameter": 16, "depth": 20}
        for c in ((40, 30), (160, 30), (160, 90), (40, 90))]}
TILTED = copy.deepcopy(FLAT)
TILTED["workpiece"]["pose"]["rot"] = [2.0, -1.5, 4.0]


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    with serve(tmp_path_factory.mktemp("setup_support"), FLAT) as url:
        yield url


@pytest.fixture
def http(server):
    import httpx

    with httpx.Client(base_url=server, timeout=20) as client:
        yield client


@pytest.fixture
def tab(browser, server):
    with browser_tab(browser, server, 1280, 800, timeout_ms=8000) as page:
        yield page


def load(http, scenario: dict) -> Operator:
    r = http.post("/api/sim/scenario", json={**scenario, "reset_data": True})
    assert r.status_code == 200, r.text
    return Operator(http, scenario)


def test_example1_four_holes_into_inactive_wo(tab, http):
    op = load(http, FLAT)
    http.post("/api/machine/activate", json={"offset": "G500"})
    answer = run_points(http, op, "hole.4",
                        {"diameter": 16, "angle_correction": "rotation", "setpoint_angle": 0.0,
                         "setpoint": {"X": 0, "Y": 0}},
                        [(40, 30, -8), (160, 30, -8), (160, 90, -8), (40, 90, -8)], target="G54")
    assert [r["code"] for r in answer["setup_support"]["reasons"]] == ["inactive_wo"]
    tab.goto(f"/measure/setup-support/{answer['_session']}")
    expect(tab.locator("#ss-top-line")).to_have_text("You are compensating in an inactive WO!")
    expect(tab.locator("#ss-dialog")).to_have_text("Press NC Start to activate!")
    expect(tab.locator("#ss-hint")).to_contain_text("WCS rotated around Z")
    expect(tab.locator('[data-toggle="activate"] select')).to_have_value("yes")
    expect(tab.locator("#ss-target")).to_have_text("G54")
    tab.screenshot(path=str(SCREENSHOT), full_page=True)
    before = http.get("/api/machine").json()["mcs"]
    tab.locator("#nc-start").click()                       # NC Start on the machine control panel
    tab.wait_for_url("**/measure/workpiece/pocket/hole4")  # back to the measuring function
    status = http.get("/api/machine").json()
    assert status["active_offset"] == "G54"
    assert status["mcs"] == before                          # example 1: no axis motion


def test_example1_leave_without_activating(tab, http):
    op = load(http, FLAT)
    http.post("/api/machine/activate", json={"offset": "G500"})
    answer = run_points(http, op, "hole.4",
                        {"diameter": 16, "angle_correction": "rotation", "setpoint_angle": 0.0,
                         "setpoint": {"X": 0, "Y": 0}},
                        [(40, 30, -8), (160, 30, -8), (160, 90, -8), (40, 90, -8)], target="G54")
    tab.goto(f"/measure/setup-support/{answer['_session']}")
    tab.locator('#vsoftkeys .softkey:has-text("<<")').click()
    tab.wait_for_url("**/measure/workpiece/pocket/hole4")
    assert http.get("/api/machine").json()["active_offset"] == "G500"
    assert http.get("/api/offsets/G54").json()["rot"]["Z"] != 0.0       # the correction stays written


def test_example2_orient_plane_without_swivel(tab, http):
    op = load(http, TILTED)
    http.post("/api/machine/activate", json={"offset": "G500"})
    answer = run_points(http, op, "plane.align", {}, [(30, 25, 8), (170, 30, 8), (100, 100, 8)], target="G54")
    tab.goto(f"/measure/setup-support/{answer['_session']}")
    expect(tab.locator("#ss-top-line")).to_have_text("You are compensating in an inactive WO!")
    expect(tab.locator('[data-toggle="realign"] select')).to_be_disabled()
    expect(tab.locator('[data-toggle="retract"]')).to_be_visible()
    expect(tab.locator(".ss-message")).to_contain_text("not possible on this machine")
    tab.screenshot(path="/tmp/setup_support_plane.png", full_page=True)
    tab.locator('[data-toggle="activate"] select').select_option("no")
    expect(tab.locator("#ss-top-line")).not_to_have_text("You are compensating in an inactive WO!")
    tab.locator('[data-toggle="activate"] select').select_option("yes")
    expect(tab.locator("#ss-top-line")).to_have_text("You are compensating in an inactive WO!")
    tab.locator("#nc-start").click()
    tab.wait_for_url("**/measure/workpiece/plane")
    assert http.get("/api/machine").json()["active_offset"] == "G54"


def test_rotary_table_case(tab, http):
    op = load(http, FLAT)
    http.post("/api/machine/activate", json={"offset": "G54"})
    answer = run_points(http, op, "edge.align",
                        {"axis": "Y", "direction": "+", "reference_axis": "X", "angle_correction": "C",
                         "setpoint_angle": 0.0}, [(30, -8, -6), (170, -8, -6)])
    tab.goto(f"/measure/setup-support/{answer['_session']}")
    expect(tab.locator("#ss-top-line")).to_have_text("Rotary axis must be positioned!")
    expect(tab.locator('[data-toggle="position_rotary"]')).to_contain_text("Position rotary axis C")
    op.goto_mcs(Z=5.0)
    tab.locator("#nc-start").click()
    tab.wait_for_url("**/measure/workpiece/edge/align")
    status = http.get("/api/machine").json()
    assert status["mcs"]["C"] == pytest.approx(4.0, abs=1e-6)      # the part's true turn
    assert status["wcs"]["C"] == pytest.approx(0.0, abs=1e-6)

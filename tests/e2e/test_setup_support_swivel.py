"""End to end: set-up support WITH a swivel head (spec §6.2 example 2) and the guided
"tilted workpiece set-up" screen (chain measuring, spec §6.1) in Chromium.

Measurements run through the API (the operator's probe positions come from the truth and its own
head model, tests/flows/test_chain_swivel.SwivelOperator); the screens are driven in the browser.
Truth: the scenario pose (the plane's normal, the part's position).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest
from live import browser_tab, serve, wait_for_requests
from playwright.sync_api import expect

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "flows"))
from test_chain_swivel import TOP_POINTS, SwivelOperator, swivel  # noqa: E402
from test_chain_truth import CHAIN_SCENARIO, pose_errors, rpy, run_points  # noqa: E402

pytestmark = pytest.mark.e2e
SWIVEL = swivel(CHAIN_SCENARIO, ("A", "B"))


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    with serve(tmp_path_factory.mktemp("setup_support_swivel"), SWIVEL) as url:
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


def load(http) -> SwivelOperator:
    r = http.post("/api/sim/scenario", json={**SWIVEL, "reset_data": True})
    assert r.status_code == 200, r.text
    return SwivelOperator(http, SWIVEL)


def angle_deg(u, v) -> float:
    return math.degrees(math.acos(min(1.0, float(np.dot(u, v)) / float(np.linalg.norm(u) * np.linalg.norm(v)))))


def test_example2_orient_plane_with_swivel(tab, http):
    op = load(http)
    http.post("/api/machine/activate", json={"offset": "G500"})
    answer = run_points(http, op, "plane.align", {}, TOP_POINTS, target="G54")
    tab.goto(f"/measure/setup-support/{answer['_session']}")
    expect(tab.locator("#ss-top-line")).to_have_text("The new WCS needs a new alignment!")
    expect(tab.locator('[data-toggle="realign"] select')).to_be_enabled()
    expect(tab.locator('[data-toggle="realign"] select')).to_have_value("yes")
    expect(tab.locator('[data-toggle="retract"] select')).to_have_value("yes")
    expect(tab.locator('[data-toggle="retract"]')).to_contain_text("dry run")
    expect(tab.locator(".ss-message")).to_have_count(0)            # re-alignment is possible here
    # the top line follows the answers (spec §6.2 example 2)
    tab.locator('[data-toggle="realign"] select').select_option("no")
    expect(tab.locator("#ss-top-line")).to_have_text("You are compensating in an inactive WO!")
    held = []                       # the first answer is late: the second choice is made meanwhile
    tab.route("**/toggle", lambda route: held.append(route))
    tab.locator('[data-toggle="retract"] select').select_option("no")
    wait_for_requests(tab, held)
    tab.locator('[data-toggle="realign"] select').select_option("yes")
    tab.wait_for_timeout(300)
    for route in list(held):
        route.continue_()
        tab.wait_for_timeout(300)
    tab.unroute("**/toggle")
    expect(tab.locator("#ss-top-line")).to_have_text("The new WCS needs a new alignment!")
    expect(tab.locator('[data-toggle="realign"] select')).to_have_value("yes")
    tab.locator('[data-toggle="retract"] select').select_option("yes")
    expect(tab.locator("#ss-dialog")).to_have_text("Press NC Start to activate!")
    tab.screenshot(path="/tmp/setup_support_swivel.png", full_page=True)
    tab.locator("#nc-start").click()
    tab.wait_for_url("**/measure/workpiece/plane")
    status = http.get("/api/machine").json()
    assert status["active_offset"] == "G54"
    assert status["mcs"]["Z"] == pytest.approx(SWIVEL["machine"]["limits"]["Z"][1])   # retracted
    normal = rpy(SWIVEL["workpiece"]["pose"]["rot"])[:, 2]                           # the truth
    assert angle_deg(status["tool_axis"], normal) < 1e-6
    assert angle_deg(op.head()[:, 2], normal) < 1e-6                                  # the head model


def test_guided_tilted_setup_one_pass(tab, http):
    op = load(http)
    tab.goto("/measure/workpiece")
    tab.locator('#vsoftkeys .softkey:has-text("Tilted set-up")').click()
    tab.wait_for_url("**/measure/workpiece/tilted-setup")
    tab.locator("#ts-target").select_option("G54")
    tab.locator("#ts-start-button").click()
    expect(tab.locator('[data-step="1"]')).to_have_attribute("data-done", "no")
    # 1 orient plane: the step activates G500; the operator selects Zero offset = G54 and measures
    tab.locator("#ts-open-1").click()
    tab.wait_for_url("**/measure/workpiece/plane")
    assert http.get("/api/machine").json()["active_offset"] == "G500"
    answer = run_points(http, op, "plane.align", {}, TOP_POINTS, target="G54")
    tab.goto("/measure/workpiece/tilted-setup")
    expect(tab.locator('[data-step="1"]')).to_have_attribute("data-done", "yes")
    # 2 set-up support: activate + retract + re-align (NC Start on the activation screen)
    tab.locator("#ts-open-2").click()
    tab.wait_for_url(f"**/measure/setup-support/{answer['_session']}")
    tab.locator("#nc-start").click()
    tab.wait_for_url("**/measure/workpiece/plane")
    tab.goto("/measure/workpiece/tilted-setup")
    expect(tab.locator('[data-step="2"]')).to_have_attribute("data-done", "yes")
    expect(tab.locator("#ts-jm-i6")).to_have_text("G54")
    expect(tab.locator("#ts-state")).to_contain_text("perpendicular to the plane")
    # 3 corner in the tilted plane: the input screen's Zero offset is preset to the proposal G54
    tab.locator("#ts-open-3").click()
    tab.wait_for_url("**/measure/workpiece/corner/right")
    expect(tab.locator('select[name="target"]')).to_have_value("G54")
    run_points(http, op, "corner.right", {"kind": "outside", "position": 1, "setpoint": {"X": 0, "Y": 0}},
            [(40, -8, -6), (150, -8, -6), (-8, 50, -6)], target="G54")
    tab.goto("/measure/workpiece/tilted-setup")
    expect(tab.locator('[data-step="3"]')).to_have_attribute("data-done", "yes")
    # 4 set edge Z
    tab.locator("#ts-open-4").click()
    tab.wait_for_url("**/measure/workpiece/edge/set")
    expect(tab.locator('select[name="target"]')).to_have_value("G54")
    run_points(http, op, "edge.set", {"axis": "Z", "direction": "-", "setpoint": 0}, [(100, 60, 6)], target="G54")
    tab.goto("/measure/workpiece/tilted-setup")
    expect(tab.locator("#screen")).to_have_attribute("data-complete", "yes")
    expect(tab.locator("#ts-complete")).to_be_visible()
    tab.screenshot(path="/tmp/tilted_setup.png", full_page=True)
    # the G54 shown equals the hidden pose (noise-free probe)
    g54 = http.get("/api/offsets/G54").json()
    rot_err, trans_err = pose_errors(g54, SWIVEL)
    assert rot_err < 1e-6 and trans_err < 1e-6
    shown_x = float(tab.locator('#ts-result [data-field="trans.X"]').inner_text())
    assert shown_x == pytest.approx(SWIVEL["workpiece"]["pose"]["trans"][0], abs=1e-4)

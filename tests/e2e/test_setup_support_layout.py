"""The set-up support screen on a portrait panel (800 x 1280) and at 1024 x 768: the orient-plane
case (the longest screen: the changed Z, re-alignment, retraction) shows everything, nothing cut
off (issue [operator-ux] item 8)."""

from __future__ import annotations

import pytest
from live import browser_tab
from playwright.sync_api import expect
from test_setup_support import TILTED, http, load, run_points, server  # noqa: F401  (fixtures)
from test_touch_layout import CUT_OFF

pytestmark = pytest.mark.e2e


@pytest.mark.parametrize("size", [(800, 1280), (1024, 768)])
def test_setup_support_fits_portrait_and_4to3(browser, server, http, size):  # noqa: F811
    op = load(http, TILTED)
    http.post("/api/machine/activate", json={"offset": "G500"})
    answer = run_points(http, op, "plane.align", {}, [(30, 25, 8), (170, 30, 8), (100, 100, 8)], target="G54")
    with browser_tab(browser, server, *size, timeout_ms=15000) as tab:
        tab.goto(f"/measure/setup-support/{answer['_session']}")
        expect(tab.locator("#ss-top-line")).to_have_text("You are compensating in an inactive WO!")
        expect(tab.locator('[data-toggle="retract"]')).to_be_visible()
        assert tab.evaluate(CUT_OFF) == []
        tab.screenshot(path=f"/tmp/setup_support_{size[0]}x{size[1]}.png", full_page=True)

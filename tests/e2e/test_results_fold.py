"""At 1280 × 800 (and 1024 × 768) a measuring screen's result and its set-up support box are
seen without scrolling (issue 29 item 3): both lie inside the window and inside the screen
area's visible part, measured by their bounding boxes in Chromium. The case: four holes measured
under G500 into G54 (test_setup_support example 1), the input screen opened afterwards."""

from __future__ import annotations

import pytest
from live import browser_tab
from playwright.sync_api import expect
from test_setup_support import FLAT, http, load, run_points, server  # noqa: F401  (fixtures)

pytestmark = pytest.mark.e2e

VISIBLE = """sel => {
  const box = document.querySelector(sel).getBoundingClientRect();
  const screen = document.getElementById("screen");
  const area = screen.getBoundingClientRect();
  const bottom = Math.min(innerHeight, area.top + screen.clientHeight);
  return {top: box.top, bottom: box.bottom, areaTop: area.top, limit: bottom,
          scrolled: screen.scrollTop, pageScroll: document.scrollingElement.scrollTop};
}"""


@pytest.mark.parametrize("size,lang", [((1280, 800), "en"), ((1280, 800), "de"), ((1024, 768), "zh")])
def test_result_and_setup_support_are_seen_without_scrolling(browser, server, http, size, lang):  # noqa: F811
    op = load(http, FLAT)
    http.post("/api/machine/activate", json={"offset": "G500"})
    run_points(http, op, "hole.4", {"diameter": 16, "angle_correction": "rotation", "setpoint_angle": 0.0,
                                    "setpoint": {"X": 0, "Y": 0}},
               [(40, 30, -8), (160, 30, -8), (160, 90, -8), (40, 90, -8)], target="G54")
    with browser_tab(browser, server, *size, timeout_ms=15000) as tab:
        tab.goto(f"/measure/workpiece/pocket/hole4?lang={lang}")
        expect(tab.locator("#task-result")).to_be_visible()
        expect(tab.locator("#setup-support")).to_be_visible()
        for sel in ("#task-result", "#setup-support"):
            box = tab.evaluate(VISIBLE, sel)
            assert box["scrolled"] == 0 and box["pageScroll"] == 0, box
            assert box["top"] >= box["areaTop"] - 1 and box["bottom"] <= box["limit"] + 1, (sel, size, lang, box)
        # the result's values and the activation line are among what is seen
        expect(tab.locator("#task-result .activation")).to_be_in_viewport(ratio=1)
        expect(tab.locator("#setup-support .dialog-line")).to_be_in_viewport(ratio=1)

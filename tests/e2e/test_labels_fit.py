"""Chromium: every label fits, in every language, at 1024 × 768 and 800 × 1280 (issue 29 item 3).

For each screen × language × size the page measures what an operator reads on keys and panels:
a softkey's label, a control-panel key, a panel label, a field label, a table heading. A label is
cut when its text needs more room than its box (scrollWidth/scrollHeight beyond clientWidth/
clientHeight: clipped, or spilling over its neighbour) or runs beyond the window; a control-panel
label is hidden when it is not displayed. The screens are those an operator opens from the
softkeys (one browser context per language and size keeps the run short).
"""

from __future__ import annotations

import pytest
from live import browser_tab

pytestmark = pytest.mark.e2e

SCREENS = ["/jog", "/measure/workpiece", "/measure/workpiece/corner/right", "/measure/workpiece/edge/set",
           "/measure/workpiece/pocket/hole1", "/measure/workpiece/calibrate/radius", "/measure/tool",
           "/measure/tool/length", "/offsets", "/offsets/audit", "/tools", "/machine-view", "/settings", "/log",
           "/mda", "/programs", "/probes", "/tool-probes", "/memories", "/plc", "/parts"]
SIZES = {"1024x768": (1024, 768), "800x1280": (800, 1280)}

CUT_LABELS = """() => {
  const out = [], width = document.documentElement.clientWidth;
  const labels = '.softkey .label, .softkey, .mcp .key, .mcp-label, .mcp select, .status-line > *, '
               + '.pos-title, .toggle button, .task-form label, table.grid th, .tabs a, h1';
  for (const el of document.querySelectorAll(labels)) {
    const r = el.getBoundingClientRect(), cs = getComputedStyle(el);
    if (!r.width || !r.height || cs.visibility === 'hidden' || el.closest('[hidden], .softkey.empty')) continue;
    const text = (el.innerText || el.value || '').trim().replace(/\\s+/g, ' ').slice(0, 40);
    if (!text) continue;
    if (el.scrollWidth > el.clientWidth + 1 || el.scrollHeight > el.clientHeight + 1)
      out.push(`cut: "${text}" needs ${el.scrollWidth}x${el.scrollHeight}, has ${el.clientWidth}x${el.clientHeight}`);
    else if (r.right > width + 1) out.push(`beyond the window: "${text}" ends at ${Math.round(r.right)}`);
  }
  for (const el of document.querySelectorAll('.mcp-label'))
    if (getComputedStyle(el).display === 'none' && !el.closest('[hidden]')) out.push(`hidden panel label: "${el.textContent.trim()}"`);
  return out;
}"""


@pytest.mark.parametrize("size", list(SIZES))
@pytest.mark.parametrize("lang", ["de", "zh", "en"])
def test_no_label_is_cut(browser, live_server, api, lang, size):
    found = {}
    with browser_tab(browser, live_server, *SIZES[size], timeout_ms=15000) as page:
        page.goto(f"/jog?lang={lang}")                  # the cookie keeps the language
        for screen in SCREENS:
            page.goto(screen)
            page.wait_for_selector("#screen")
            cut = page.evaluate(CUT_LABELS)
            if cut:
                found[screen] = cut
    assert not found, "\n".join(f"{s}: {c}" for s, c in found.items())

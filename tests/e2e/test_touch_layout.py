"""Touch and contrast at the machine (issue [operator-ux] item 8): on the JOG and a measuring
screen every control is at least 40 px in its smaller dimension at 1280 x 800, text at least
12 px with a contrast of at least 4.5:1 (WCAG); at 800 x 1280 portrait and 1024 x 768 nothing
is cut off (no element beyond the window, no table that must be scrolled sideways)."""

from __future__ import annotations

import pytest
from live import browser_tab

pytestmark = pytest.mark.e2e

SCREENS = ["/jog", "/measure/workpiece/edge/set", "/offsets", "/tools", "/probes", "/settings"]

SMALL_CONTROLS = """() => {
  const out = [];
  for (const el of document.querySelectorAll('button, input, select, textarea, a[href], summary')) {
    const r = el.getBoundingClientRect(), cs = getComputedStyle(el);
    if (!r.width || !r.height || cs.visibility === 'hidden' || el.type === 'hidden') continue;
    if (el.closest('.log-json, pre, p')) continue;                 // links inside running text
    if (Math.min(r.width, r.height) < 39.5)
      out.push(`${el.tagName}#${el.id}.${el.className} ${Math.round(r.width)}x${Math.round(r.height)}`);
  }
  return out;
}"""

SMALL_OR_FAINT_TEXT = """() => {
  function rgb(c) { const m = c.match(/[\\d.]+/g); return m ? m.map(Number) : [0, 0, 0, 0]; }
  function lum(c) { const a = c.slice(0, 3).map(v => { v /= 255; return v <= 0.03928 ? v / 12.92 : Math.pow((v + 0.055) / 1.055, 2.4); });
    return 0.2126 * a[0] + 0.7152 * a[1] + 0.0722 * a[2]; }
  function background(el) {            // the first opaque background up the tree (gradients: their darkest stop)
    for (; el; el = el.parentElement) {
      const cs = getComputedStyle(el);
      const stops = (cs.backgroundImage.match(/rgba?\\([^)]*\\)/g) || []).map(rgb);
      if (stops.length) return stops.reduce((a, b) => lum(a) < lum(b) ? a : b);
      const c = rgb(cs.backgroundColor);
      if (c.length < 4 || c[3] > 0.5) return c;
    }
    return [255, 255, 255];
  }
  const out = [];
  for (const el of document.querySelectorAll('body *')) {
    if (![...el.childNodes].some(n => n.nodeType === 3 && n.textContent.trim())) continue;
    const r = el.getBoundingClientRect(), cs = getComputedStyle(el);
    if (!r.width || cs.visibility === 'hidden' || el.closest('svg, .softkey.empty, [disabled], .denied')) continue;
    const size = parseFloat(cs.fontSize);
    const f = lum(rgb(cs.color)), b = lum(background(el));
    const ratio = (Math.max(f, b) + 0.05) / (Math.min(f, b) + 0.05);
    if (size < 11.95 || ratio < 4.5)
      out.push(`${el.tagName}.${el.className} "${el.textContent.trim().slice(0, 12)}" ${size}px ${ratio.toFixed(2)}:1`);
  }
  return out;
}"""

CUT_OFF = """() => {
  const width = document.documentElement.clientWidth, out = [];
  if (document.documentElement.scrollWidth > width) out.push(`page ${document.documentElement.scrollWidth} > ${width}`);
  for (const el of document.querySelectorAll('body *')) {
    if (el.closest('svg, canvas')) continue;
    const r = el.getBoundingClientRect();
    if (r.width && r.right > width + 1) out.push(`${el.tagName}.${el.className} ends at ${Math.round(r.right)}`);
    if (el.matches('.table-wrap, .screen, section, fieldset, form') && el.scrollWidth > el.clientWidth + 1)
      out.push(`${el.tagName}#${el.id}.${el.className} content wider than its box ${el.scrollWidth} > ${el.clientWidth}`);
  }
  return out.slice(0, 20);
}"""


@pytest.mark.parametrize("screen", SCREENS[:2])
def test_controls_are_touch_sized_and_text_is_readable_at_1280x800(browser, live_server, screen):
    with browser_tab(browser, live_server, 1280, 800, timeout_ms=15000) as page:
        page.goto(screen)
        page.wait_for_selector("#screen")
        assert page.evaluate(SMALL_CONTROLS) == []
        assert page.evaluate(SMALL_OR_FAINT_TEXT) == []


@pytest.mark.parametrize("size", [(800, 1280), (1024, 768)], ids=["portrait-800x1280", "4to3-1024x768"])
@pytest.mark.parametrize("screen", SCREENS)
def test_nothing_is_cut_off(browser, live_server, screen, size):
    with browser_tab(browser, live_server, *size, timeout_ms=15000) as page:
        page.goto(screen)
        page.wait_for_selector("#screen")
        assert page.evaluate(CUT_OFF) == []

"""The operator's complete job at real machine speed, in Chromium at 1280 x 800 (issue
[operator-ux]): calibrate the probe in the ring (radius, then length on its top face), then a right-angled corner and the Z edge into
G54, everything through the screens. Jogging by keyboard hold-to-run (Shift = rapid), the
softkeys by mouse, NC Start by Ctrl+Enter. Prints the time, clicks, keys and press-and-holds,
and the G54 error against the demo scenario's hidden pose.

    .venv/bin/python bench/bench_operator_job.py [WIDTHxHEIGHT, default 1280x800] [-v]
"""

from __future__ import annotations

import json
import math
import sys
import tempfile
import time
from pathlib import Path

import httpx
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "tests"), str(ROOT)]
from live import CHROMIUM_ARGS, browser_tab, serve  # noqa: E402

SCENARIO = json.loads((ROOT / "app/machine/demo_scenario.json").read_text())
VERBOSE = "-v" in sys.argv
SIZE = next((tuple(int(v) for v in a.split("x")) for a in sys.argv[1:] if "x" in a), (1280, 800))
KEYS = {"X": ("ArrowLeft", "ArrowRight"), "Y": ("ArrowDown", "ArrowUp"), "Z": ("PageDown", "PageUp")}


class Operator:
    def __init__(self, page, http):
        self.page, self.http = page, http
        self.clicks = self.keys = self.holds = 0

    def click(self, locator) -> None:
        locator.click()
        self.clicks += 1

    def key(self, name: str) -> None:
        self.page.keyboard.press(name)
        self.keys += 1

    def wcs(self) -> np.ndarray:
        w = self.http.get("/api/machine").json()["wcs"]
        return np.array([w["X"], w["Y"], w["Z"]])

    def hold(self, axis: str, target: float, rapid: bool) -> None:
        """Press and hold the axis key while watching the position display; let go just before
        the target (the operator's eye and hand: about 0.15 s of travel early)."""
        i = "XYZ".index(axis)
        left = target - self.wcs()[i]
        key = KEYS[axis][1 if left > 0 else 0]
        speed = (SCENARIO["machine"]["rapid"] * 0.25 if rapid else SCENARIO["machine"]["jog_feed"]) / 60.0
        if rapid:
            self.page.keyboard.down("Shift")
        self.page.keyboard.down(key)
        deadline = time.monotonic() + abs(left) / speed * 3 + 2.0
        while time.monotonic() < deadline:
            remaining = (target - self.wcs()[i]) * (1 if left > 0 else -1)
            if remaining <= (max(0.15 * speed, 20.0) if rapid else 0.25 * speed):   # slow down near a face
                break
            time.sleep(0.02)
        self.page.keyboard.up(key)
        if rapid:
            self.page.keyboard.up("Shift")
        self.holds += 1
        time.sleep(0.3)                                   # the axis brakes; the operator looks again
        if VERBOSE:
            print(f"hold {axis} {'rapid' if rapid else 'feed'}: target {target:.2f}, at {self.wcs()[i]:.2f}",
                  file=sys.stderr)

    def jog_to(self, axis: str, target: float, within: float = 1.5) -> None:
        """Rapid (Shift) when far, then at jog feed; as an operator with the display."""
        i = "XYZ".index(axis)
        for _attempt in range(4):
            left = target - self.wcs()[i]
            if abs(left) <= within:
                return
            self.hold(axis, target, rapid=abs(left) > 60)

    def travel(self, x: float, y: float, z: float, safe_z: float) -> None:
        # the keyboard jogs only when no input field has the focus: the operator taps outside
        if self.page.evaluate("() => !!document.activeElement && /^(INPUT|SELECT|TEXTAREA)$/"
                              ".test(document.activeElement.tagName)"):
            self.click(self.page.locator("#position-values, .position").first)
        self.jog_to("Z", safe_z)
        self.jog_to("X", x)
        self.jog_to("Y", y)
        self.jog_to("Z", z)

    def softkey(self, text: str) -> None:
        self.click(self.page.locator("#vsoftkeys, #hsoftkeys").get_by_text(text, exact=False).first)

    def nc_start(self, wait_for: str) -> None:
        time.sleep(1.0)                                   # the operator checks the screen first
        self.key("Control+Enter")
        self.page.locator(wait_for).first.wait_for(timeout=120_000)


def part_to_mcs(x: float, y: float, z: float) -> np.ndarray:
    pose = SCENARIO["workpiece"]["pose"]
    c = math.radians(pose["rot"][2])
    return np.array([math.cos(c) * x - math.sin(c) * y, math.sin(c) * x + math.cos(c) * y, z]) + pose["trans"]


def job(op: Operator) -> None:
    page = op.page
    page.goto("/jog")
    safe = -95.0
    cx, cy, ring_top = SCENARIO["ring_gauge"]["center"]
    # 1. calibrate in the ring
    op.travel(cx, cy, ring_top - 8.0, safe)
    op.softkey("Measure workpiece")
    op.click(page.get_by_role("link", name="Calibrate probe").first)
    op.click(page.get_by_role("link", name="Radius").first)
    field = page.locator('input[name="diameter"]')
    if field.input_value() != f"{SCENARIO['ring_gauge']['diameter']:g}":
        op.click(field)
        field.fill(f"{SCENARIO['ring_gauge']['diameter']:g}")
        op.keys += len(field.input_value()) + 1
        op.key("Tab")
    op.nc_start("#task-result")
    # 1b. the length on the ring's top face (its height is known in machine coordinates)
    ring = SCENARIO["ring_gauge"]
    r_mid = (ring["diameter"] / 2.0 + (ring.get("outer_diameter") or ring["diameter"] + 30) / 2.0) / 2.0
    op.travel(cx + r_mid, cy, ring_top + 4.0, safe)
    op.click(page.locator("#hsoftkeys").get_by_text("Measure workpiece").first)
    op.click(page.get_by_role("link", name="Calibrate probe").first)
    op.click(page.get_by_role("link", name="Length").first)
    field = page.locator('input[name="setpoint"]')
    op.click(field)
    field.fill(f"{ring_top:g}")
    op.keys += len(field.input_value()) + 1
    op.key("Tab")
    op.nc_start("#task-result")
    # 2. right-angled corner into G54 (proposed under G500), P1 and P2 on the front edge, P3 left
    op.jog_to("Z", safe)
    op.click(page.locator("#hsoftkeys").get_by_text("Measure workpiece").first)
    op.click(page.get_by_role("link", name="Measure corner").first)
    op.click(page.get_by_role("link", name="Right-angled corner").first)
    depth = -6.0                                       # part coordinates: 6 mm under the top
    for n, (x, y) in enumerate(((30.0, -10.0), (150.0, -10.0), (-10.0, 40.0)), start=1):
        p = part_to_mcs(x, y, depth)
        if n == 3:                                     # round the corner, outside the block
            q = part_to_mcs(-10.0, -10.0, depth)
            op.jog_to("X", q[0])
        op.travel(p[0], p[1], p[2], safe if n == 1 else p[2])
        op.nc_start(f'#vsoftkeys [data-point="{n}"].stored')
    op.click(page.locator("#vsoftkeys").get_by_text("Calculate").first)
    page.locator("#ss-top-line, #task-result").first.wait_for(timeout=30_000)
    if page.locator("#ss-top-line").count():
        op.key("Control+Enter")                        # set-up support: NC Start activates G54
        page.wait_for_timeout(1000)
    # 3. Z edge into the now active G54
    op.jog_to("Z", safe)
    op.click(page.locator("#hsoftkeys").get_by_text("Measure workpiece").first)
    op.click(page.get_by_role("link", name="Measure edge").first)
    op.click(page.get_by_role("link", name="Set edge").first)
    page.locator('#task-form select[name="axis"]').select_option("Z")
    op.clicks += 2
    page.locator('#task-form select[name="direction"]').select_option("-")
    op.clicks += 2
    # 8 mm over the top, inside the block (the display shows machine positions under G500)
    p = part_to_mcs(60.0, 40.0, 8.0)
    op.travel(p[0], p[1], p[2], safe)
    op.nc_start("#task-result")


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp, serve(Path(tmp), SCENARIO) as url:
        from playwright.sync_api import sync_playwright

        with sync_playwright() as pw, httpx.Client(base_url=url, timeout=30) as http:
            browser = pw.chromium.launch(executable_path="/usr/bin/chromium", args=CHROMIUM_ARGS)
            with browser_tab(browser, url, *SIZE, timeout_ms=30_000) as page:
                op = Operator(page, http)
                started = time.monotonic()
                try:
                    job(op)
                except Exception:
                    page.screenshot(path="/tmp/operator_job_failed.png")
                    print("failed; machine:", http.get("/api/machine").json(), file=sys.stderr)
                    raise
                seconds = time.monotonic() - started
            g54 = http.get("/api/offsets/G54").json()
            pose = SCENARIO["workpiece"]["pose"]
            dx = g54["trans"]["X"] - pose["trans"][0]
            dy = g54["trans"]["Y"] - pose["trans"][1]
            dz = g54["trans"]["Z"] - pose["trans"][2]
            drot = g54["rot"]["Z"] - pose["rot"][2]
            print(f"job at {SIZE[0]}x{SIZE[1]}: {seconds:.0f} s, {op.clicks} clicks, {op.keys} keys, {op.holds} press-and-holds")
            print(f"G54 error: X {dx * 1e3:+.2f} µm, Y {dy * 1e3:+.2f} µm, Z {dz * 1e3:+.2f} µm, "
                  f"rotation {math.radians(drot) * 1e6:+.1f} µrad")
            browser.close()


if __name__ == "__main__":
    main()

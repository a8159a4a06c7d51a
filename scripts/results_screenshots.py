"""Screenshots of the per-part protocol and the run chart for docs/screens/ (design.md §10.3):
a machined series of 12 bores through the tool-offset simulator (``POST /api/sim/machine-part``)
measured with the mean-value strategy, on a noise-free test scenario.

    .venv/bin/python scripts/results_screenshots.py
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import httpx

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "tests"), str(ROOT)]
from hmi_testdata import PROBE_LENGTH, test_scenario  # noqa: E402
from live import CHROMIUM_ARGS, browser_tab, serve  # noqa: E402

HOLE, POSE_T, NOMINAL = (100.0, 60.0), (250.0, 150.0, -120.0), 32.0
TOLERANCE = {"setpoint": NOMINAL, "upper": 0.02, "lower": -0.02, "zero_range": 0.002, "mean_range": 0.013,
             "dim_difference": 0.06, "safe_area": 1.0, "k": 2}


def series_scenario() -> dict:
    s = test_scenario()
    s["workpiece"]["features"] = [{"type": "block", "size": [200, 120, 60]},
                                  {"type": "hole", "center": list(HOLE), "diameter": NOMINAL, "depth": 25,
                                   "machined_by": {"t": 20}}]
    s["tools"] = [*s["tools"], {"t": 20, "type": 120, "length": 90.0, "radius": 8.0,
                                "wear_per_part": {"radius": 0.003}}]
    return s


def run_series(http: httpx.Client, parts: int) -> int:
    http.post("/api/sim/scenario", json={**series_scenario(), "reset_data": True}).raise_for_status()
    http.post("/api/machine/tool", json={"tool": 9}).raise_for_status()
    http.put("/api/job", json={"part_number": "4711-BORE32", "order": "A-2026-118", "operator": "Anna Berg",
                               "program": "BORE32"}).raise_for_status()
    part_id = 0
    for index in range(parts):
        if index:
            part_id = http.post("/api/job/next-part").json()["part_id"]
        http.post("/api/sim/machine-part", json={"scatter_sigma": 0.002}).raise_for_status()
        x, y = POSE_T[0] + HOLE[0], POSE_T[1] + HOLE[1]
        for target in ({"Z": 0.0}, {"X": x, "Y": y}, {"Z": POSE_T[2] - 8.0 + PROBE_LENGTH}):
            http.post("/api/machine/goto", json={**target, "coords": "MCS"}).raise_for_status()
        session = http.post("/api/measure", json={"task": "hole.1", "params": {"diameter": NOMINAL, "tolerance": TOLERANCE},
                                                  "target": {"tool": 20, "correct": "radius", "mode": "wear"}}).json()
        http.post(f"/api/measure/{session['id']}/start", json={}).raise_for_status()
    return part_id


def main() -> None:
    out = ROOT / "docs" / "screens"
    with tempfile.TemporaryDirectory() as tmp, serve(Path(tmp), test_scenario()) as url:
        with httpx.Client(base_url=url, timeout=30) as http:
            last = run_series(http, 12)
        from playwright.sync_api import sync_playwright

        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path="/usr/bin/chromium", args=CHROMIUM_ARGS)
            with browser_tab(browser, url, 820, 1000, timeout_ms=30_000) as page:
                page.goto(f"/parts/{last}/protocol")
                page.emulate_media(media="print")
                page.screenshot(path=str(out / "part-protocol.png"), full_page=True)
                (out / "part-protocol.pdf").write_bytes(page.pdf(format="A4", print_background=True))
            with browser_tab(browser, url, 1280, 800, timeout_ms=30_000) as page:
                page.goto("/spc?part_number=4711-BORE32&characteristic=diameter")
                page.wait_for_selector("svg.run-chart")
                page.screenshot(path=str(out / "run-chart.png"))
            browser.close()
    print("docs/screens/part-protocol.png, part-protocol.pdf, run-chart.png")


if __name__ == "__main__":
    main()

"""Screenshots of the main screens for docs/screens/ (issue [operator-ux] item 12): the demo
scenario at 1280 x 800, each screen in English, German and Chinese (issue [screens] item 8).

    .venv/bin/python scripts/screenshots.py
"""

from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "tests"), str(ROOT)]
from live import CHROMIUM_ARGS, browser_tab, serve  # noqa: E402

SCREENS = {"jog": "/jog", "measure-corner": "/measure/workpiece/corner/right", "offsets": "/offsets",
           "machine-view": "/machine-view", "probes": "/probes", "tools": "/tools", "log": "/log",
           "settings": "/settings", "mda": "/mda", "memories": "/memories", "plc": "/plc", "programs": "/programs",
           "tool-probes": "/tool-probes", "kinematics": "/kinematics", "parts": "/parts", "spc": "/spc"}
LANGUAGES = {"de": tuple(SCREENS), "zh": tuple(SCREENS)}


def main() -> None:
    scenario = json.loads((ROOT / "app/machine/demo_scenario.json").read_text())
    scenario["machine"]["time_scale"] = 0
    out = ROOT / "docs" / "screens"
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp, serve(Path(tmp), scenario) as url:
        from playwright.sync_api import sync_playwright

        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path="/usr/bin/chromium", args=CHROMIUM_ARGS)
            shots = [(name, path, "en") for name, path in SCREENS.items()]
            shots += [(name, SCREENS[name], lang) for lang, names in LANGUAGES.items() for name in names]
            for name, path, lang in shots:
                with browser_tab(browser, url, 1280, 800, timeout_ms=30_000) as page:
                    page.goto(f"{path}?lang={lang}")
                    page.wait_for_selector("#screen")
                    page.wait_for_timeout(800)
                    target = out / (f"{name}.png" if lang == "en" else f"{name}-{lang}.png")
                    page.screenshot(path=str(target))
                    print(target.relative_to(ROOT))
            browser.close()


if __name__ == "__main__":
    main()

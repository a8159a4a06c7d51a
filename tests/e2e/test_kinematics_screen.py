"""End to end in Chromium: the kinematics screen (design.md §10.6, docs/kinematics.md). The operator
opens JOG → Kinematics, types the calibration sphere (its centre from the truth: the operator sees
it), measures the A axis in check mode and reads the positions, the results and the deviation (the
scenario's true A line is tens of µm off the nominal), then optimises after confirming, and reads
the new machine data; then the screen in German and Chinese."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from live import browser_tab, serve
from playwright.sync_api import expect

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "flows"))
from test_kinematics_truth import TRUE_HEAD, kin_scenario, sphere_mcs  # noqa: E402

pytestmark = pytest.mark.e2e
SCENARIO = kin_scenario(sigma=0.0, true=TRUE_HEAD)


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    with serve(tmp_path_factory.mktemp("kinematics_screen"), SCENARIO) as url:
        yield url


def test_operator_checks_then_optimises_the_a_axis(browser, server):
    centre = sphere_mcs(SCENARIO)
    with browser_tab(browser, server, 1280, 800, timeout_ms=60000) as tab:
        tab.goto("/jog")
        tab.locator("#vsoftkeys .softkey", has_text="Kinematics").click()
        expect(tab.locator("#screen")).to_have_attribute("data-screen", "kinematics")
        lines = tab.locator("table.kin-lines tbody tr")
        expect(lines).to_have_count(2)
        expect(tab.locator('table.kin-lines tr[data-axis="A"]')).to_contain_text("0.0, 0.0, 0.0")
        for name, value in zip("xyz", centre, strict=True):
            tab.locator(f'#kin-form input[name="{name}"]').fill(f"{value:.4f}")
        tab.locator('#kin-form select[name="axis"]').select_option("A")
        tab.locator('#kin-form input[name="positions"]').fill("-45 0 45")
        tab.locator("#kin-start").click()
        expect(tab.locator("#kin-message")).to_contain_text("nothing written")
        expect(tab.locator("svg.kin-picture .kin-dot")).to_have_count(3)
        expect(tab.locator("table.kin-spheres tbody tr")).to_have_count(3)
        offset = float(tab.locator('[data-field="offset"]').inner_text().split()[0])
        true_offset = float(np.hypot(*TRUE_HEAD["A"]["point"][1:])) * 1000     # µm, across the A axis
        assert abs(offset - true_offset) < 1.0
        expect(tab.locator('[data-field="written"]')).to_have_text("unchanged")

        tab.locator('#kin-form select[name="mode"]').select_option("optimise")
        expect(tab.locator("#kin-form")).to_have_attribute("hx-confirm", "Write the measured kinematics into the machine data?")
        tab.once("dialog", lambda dialog: dialog.accept())
        tab.locator("#kin-start").click()
        expect(tab.locator("#kin-message")).to_contain_text("written into the machine data")
        expect(tab.locator('[data-field="written"]')).to_have_text("written")
        expect(tab.locator('table.kin-lines tr[data-axis="A"]')).to_contain_text("0.035")

        tab.goto("/kinematics?lang=de")
        expect(tab.locator("h1")).to_contain_text("Kinematik messen")
        expect(tab.locator("#kin-start")).to_have_text("Messen")
        tab.goto("/kinematics?lang=zh")
        expect(tab.locator("h1")).to_contain_text("测量运动学")

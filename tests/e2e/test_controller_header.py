"""The header names the controller and shows its E-stop and drives (issue 34 §6, design.md §10.7):
"Simulator" with the trainer banner on the simulator; "LinuxCNC · <INI file>" on the machine's own
LinuxCNC, no trainer banner there, and "E-stop" when LinuxCNC's emergency stop is pressed."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from hmi_testdata import TEST_SCENARIO
from live import browser_tab, serve
from playwright.sync_api import expect
from waiting import wait_until

pytestmark = pytest.mark.e2e

LINUXCNC_TESTS = Path(__file__).resolve().parent.parent / "linuxcnc"


def test_the_simulator_is_named_with_its_trainer_banner(page, api):
    page.goto("/jog")
    expect(page.locator("#hdr-controller")).to_have_text("Simulator")
    expect(page.locator("#hdr-drives")).to_have_text("Machine on")
    expect(page.locator("#trainer-banner")).to_be_visible()


@pytest.mark.linuxcnc
def test_the_machines_own_linuxcnc_is_named_and_its_e_stop_shown(browser, tmp_path, monkeypatch):
    from app.machine.linuxcnc.modules import available

    if not available():
        pytest.skip("LinuxCNC is not installed (scripts/test.sh installs it)")
    sys.path.insert(0, str(LINUXCNC_TESTS))
    from own_config import own_config

    monkeypatch.setenv("HMI_LINUXCNC_DIR", str(tmp_path / "linuxcnc"))
    ini = own_config(tmp_path / "config")
    apps = []
    with serve(tmp_path / "hmi", TEST_SCENARIO, settings={"machine": "linuxcnc", "linuxcnc_ini": ini},
               prepare=apps.append) as url, browser_tab(browser, url) as tab:
        tab.goto("/jog")
        expect(tab.locator("#hdr-controller")).to_have_text("LinuxCNC · axis_mm.ini")
        expect(tab.locator("#hdr-drives")).to_have_text("Machine on")
        expect(tab.locator("#trainer-banner")).to_have_count(0)
        expect(tab.locator("#open-banner")).to_be_visible()
        machine = apps[0].state.services.machine.machine
        machine._cmd.state(sys.modules["linuxcnc"].STATE_ESTOP)           # the operator presses E-stop
        wait_until(lambda: machine.linuxcnc_stat().task_state == sys.modules["linuxcnc"].STATE_ESTOP,
                   "LinuxCNC in E-stop", 10.0)
        tab.reload()
        expect(tab.locator("#hdr-drives")).to_have_text("E-stop")
    wait_until(lambda: not Path("/tmp/linuxcnc.lock").exists(), "LinuxCNC stopped with the HMI", 30.0)

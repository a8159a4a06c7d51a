"""LinuxCNC tests: a real LinuxCNC (Debian linuxcnc-uspace) in real time, skipped where it is not
installed (scripts/test.sh installs it). Each app or machine starts its own LinuxCNC with the
configuration generated into a temporary folder, and stops it at the end."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

TESTS = Path(__file__).resolve().parent.parent
for folder in (TESTS / "flows", TESTS / "contract"):     # flowkit, truthkit, the flows' and contract's helpers
    if str(folder) not in sys.path:
        sys.path.insert(0, str(folder))


def _installed() -> bool:
    from app.machine.linuxcnc.modules import available

    return available()


def pytest_collection_modifyitems(config, items):
    here = Path(__file__).resolve().parent
    skip = None if _installed() else pytest.mark.skip(
        reason="LinuxCNC is not installed (apt-get install linuxcnc-uspace linuxcnc-uspace-dev; scripts/test.sh does)")
    for item in items:
        if here in Path(str(item.fspath)).resolve().parents:
            item.add_marker(pytest.mark.linuxcnc)
            if skip is not None:
                item.add_marker(skip)


@pytest.fixture(autouse=True)
def _linuxcnc_folder(tmp_path, monkeypatch):
    monkeypatch.setenv("HMI_LINUXCNC_DIR", str(tmp_path / "linuxcnc"))


# real time: a machine tool's braking (5 m/s², the scenario's 1 m/s² by default) and a 20 m/min rapid
# keep the LinuxCNC tests short; the latch is interpolated inside the servo period, so what they
# measure does not depend on either (test_linuxcnc_machine.py: the latch at 300 to 3000 mm/min)
BRISK_MACHINE = {"decel": 5.0, "rapid": 20000.0}
BRISK_POSITIONING = {"position_feed": 20000.0, "position_feed_infeed": 20000.0}


def brisk(scenario: dict) -> dict:
    """``scenario`` (a copy) on a machine with BRISK_MACHINE's braking and rapid."""
    copy = json.loads(json.dumps(scenario))
    copy.setdefault("machine", {}).update(BRISK_MACHINE)
    return copy


def linuxcnc_client(tmp_path: Path, scenario: dict):
    """The app on LinuxCNC (``--machine linuxcnc``) for ``scenario``, as a TestClient."""
    from fastapi.testclient import TestClient

    from app.config import Settings
    from app.main import create_app

    tmp_path.mkdir(parents=True, exist_ok=True)
    path = tmp_path / "scenario.json"
    path.write_text(json.dumps(scenario))
    return TestClient(create_app(Settings(db_path=tmp_path / "hmi.db", scenario_path=path, machine="linuxcnc")))

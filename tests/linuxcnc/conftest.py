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


def linuxcnc_client(tmp_path: Path, scenario: dict):
    """The app on LinuxCNC (``--machine linuxcnc``) for ``scenario``, as a TestClient."""
    from fastapi.testclient import TestClient

    from app.config import Settings
    from app.main import create_app

    tmp_path.mkdir(parents=True, exist_ok=True)
    path = tmp_path / "scenario.json"
    path.write_text(json.dumps(scenario))
    return TestClient(create_app(Settings(db_path=tmp_path / "hmi.db", scenario_path=path, machine="linuxcnc")))

"""The LinuxCNC implementation writes its generated configuration into a temporary folder."""

from __future__ import annotations

import pytest


@pytest.fixture(autouse=True)
def _linuxcnc_folder(tmp_path, monkeypatch):
    monkeypatch.setenv("HMI_LINUXCNC_DIR", str(tmp_path / "linuxcnc"))

"""The machine is chosen by name: setting ``machine``, ``HMI_MACHINE``, ``--machine`` (design.md §9.6)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from app.__main__ import parse_args, settings_from_args
from app.config import Settings
from app.machine import registry
from app.machine.protocol import Machine
from app.machine.scenario import demo_scenario

ROOT = Path(__file__).resolve().parents[2]


def test_sim_is_registered_and_the_default():
    assert "sim" in registry.names() and registry.DEFAULT == "sim" == Settings().machine
    machine = registry.build_machine("sim", demo_scenario())
    assert isinstance(machine, Machine) and machine.controller == "sim"
    machine.close()


def test_an_unknown_machine_names_the_known_ones():
    with pytest.raises(registry.UnknownMachine, match=r"'plc5'.*known machines: sim"):
        registry.build_machine("plc5", demo_scenario())


def test_create_app_refuses_an_unknown_machine_before_touching_the_db(tmp_path):
    from app.main import create_app

    with pytest.raises(registry.UnknownMachine):
        create_app(Settings(db_path=tmp_path / "hmi.db", machine="plc5"))
    assert not (tmp_path / "hmi.db").exists()


def test_machine_from_the_command_line_and_the_environment(monkeypatch):
    monkeypatch.delenv("HMI_MACHINE", raising=False)
    assert settings_from_args(parse_args([])).machine == "sim"
    assert settings_from_args(parse_args(["--machine", "sim"])).machine == "sim"
    monkeypatch.setenv("HMI_MACHINE", "elsewhere")
    assert settings_from_args(parse_args([])).machine == "elsewhere"
    assert settings_from_args(parse_args(["--machine", "sim"])).machine == "sim"


def test_the_command_line_refuses_an_unknown_machine(tmp_path):
    flag = subprocess.run([sys.executable, "-m", "app", "--machine", "plc5"], cwd=ROOT, capture_output=True,
                          text=True, timeout=60)
    assert flag.returncode == 2 and "--machine" in flag.stderr and "sim" in flag.stderr
    env = {**os.environ, "HMI_MACHINE": "plc5", "HMI_DB_PATH": str(tmp_path / "hmi.db")}
    variable = subprocess.run([sys.executable, "-m", "app"], cwd=ROOT, capture_output=True, text=True,
                              timeout=60, env=env)
    assert variable.returncode == 1 and "unknown machine 'plc5'" in variable.stderr
    assert not (tmp_path / "hmi.db").exists()

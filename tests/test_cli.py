"""Command line: ``python -m app [--host] [--port] [--db] [--scenario]`` (design.md §4)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from app.__main__ import parse_args, settings_from_args

ROOT = Path(__file__).resolve().parents[1]


def test_defaults_bind_localhost_with_demo_and_data_db(monkeypatch):
    for name in ("HMI_HOST", "HMI_PORT", "HMI_DB_PATH", "HMI_SCENARIO_PATH", "HMI_TIME_SCALE"):
        monkeypatch.delenv(name, raising=False)
    settings = settings_from_args(parse_args([]))
    assert (settings.host, settings.port) == ("127.0.0.1", 8000)
    assert settings.db_path == Path("data/hmi.db")
    assert settings.scenario_path is None and settings.time_scale is None


def test_arguments_are_parsed(tmp_path):
    args = parse_args(["--host", "127.0.0.2", "--port", "8123", "--db", str(tmp_path / "x.db"),
                       "--scenario", str(tmp_path / "s.json"), "--time-scale", "0"])
    settings = settings_from_args(args)
    assert (settings.host, settings.port, settings.time_scale) == ("127.0.0.2", 8123, 0.0)
    assert settings.db_path == tmp_path / "x.db" and settings.scenario_path == tmp_path / "s.json"


def test_environment_prefix_and_arguments_win(monkeypatch):
    monkeypatch.setenv("HMI_PORT", "9001")
    monkeypatch.setenv("HMI_DB_PATH", "/tmp/elsewhere.db")
    assert settings_from_args(parse_args([])).port == 9001
    assert settings_from_args(parse_args(["--port", "9002"])).port == 9002
    assert str(settings_from_args(parse_args([])).db_path) == "/tmp/elsewhere.db"


def test_help_runs():
    result = subprocess.run([sys.executable, "-m", "app", "--help"], cwd=ROOT, capture_output=True, text=True,
                            timeout=60)
    assert result.returncode == 0
    for option in ("--host", "--port", "--db", "--scenario"):
        assert option in result.stdout


def test_bad_port_is_refused():
    result = subprocess.run([sys.executable, "-m", "app", "--port", "abc"], cwd=ROOT, capture_output=True,
                            text=True, timeout=60)
    assert result.returncode == 2 and "--port" in result.stderr


def test_commissioning_command_fails_on_a_wrong_machine_datum(tmp_path):
    """``python -m app commissioning``: MD 18130 = 100 (manual §9.1.1: 130 with "Measure in JOG")
    fails that check only, exit 1; the commissioned scenario passes every check, exit 0."""
    import json

    from hmi_testdata import test_scenario

    def run(machine_data: dict, *extra: str):
        scenario = test_scenario()
        scenario.setdefault("machine", {})["machine_data"] = machine_data
        path = tmp_path / f"s{len(machine_data)}.json"
        path.write_text(json.dumps(scenario))
        return subprocess.run([sys.executable, "-m", "app", "--db", str(tmp_path / "c.db"), "--scenario", str(path),
                               "commissioning", *extra], cwd=ROOT, capture_output=True, text=True, timeout=120)

    wrong = run({"18130": 100}, "--json")
    assert wrong.returncode == 1, wrong.stderr
    report = json.loads(wrong.stdout)
    assert [c["id"] for c in report["checks"] if c["ok"] is not True] == ["md18130"]
    right = run({})
    assert right.returncode == 0, right.stdout + right.stderr
    assert "FAIL" not in right.stdout and "MD 18130 MM_NUM_GUD_NAMES_CHAN" in right.stdout

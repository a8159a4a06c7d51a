"""Reading scenarios for the app: file or built-in demo, with the process's time_scale override."""

from __future__ import annotations

import json
from pathlib import Path

from app.config import Settings
from app.machine.lathe_scenario import LatheScenario
from app.machine.scenario import Scenario, demo_scenario, load_scenario


def read_scenario(settings: Settings) -> Scenario | LatheScenario:
    scenario: Scenario | LatheScenario
    if settings.scenario_path is None:
        scenario = demo_scenario()
    else:
        scenario = load_scenario(json.loads(Path(settings.scenario_path).read_text(encoding="utf-8")))
    return with_time_scale(scenario, settings.time_scale)


def with_time_scale(scenario: Scenario | LatheScenario, time_scale: float | None) -> Scenario | LatheScenario:
    """``machine.time_scale`` replaced when the process was started with an override (tests: 0)."""
    if time_scale is None:
        return scenario
    data = scenario.model_dump(mode="json")
    data["machine"]["time_scale"] = time_scale
    return load_scenario(data)

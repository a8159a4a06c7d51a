"""The plant view (design.md §10.5): GET /api/plant and the /plant screens list every machine on
the shared database with what it last reported. Runs on SQLite and on PostgreSQL (--db-engine)."""

from __future__ import annotations

import pytest
from pgcluster import database_settings

from db import Database, acting_as
from db.repository import Actor


@pytest.fixture
def plant_client(database_target, scenario_file):
    from fastapi.testclient import TestClient

    from app.config import Settings
    from app.main import create_app

    app = create_app(Settings(**database_settings(database_target), scenario_path=scenario_file,
                              machine_name="mill-a"))
    with TestClient(app) as client:
        yield client


@pytest.fixture
def mill_b(database_target, plant_client):
    """A second HMI's database connection: machine mill-b with a calibrated probe, a part, a log entry."""
    with Database(database_target, machine="mill-b") as db:
        with acting_as(Actor("user:bert", 3)), db.unit() as unit:
            unit.put_offset("G54", {"trans": {"X": 5.0}}, source="test")
            unit.put_probe(1, {"calibrated_at": "2026-01-01T00:00:00+00:00"})
            part = unit.add_part({"part_number": "PN-7", "serial": "S1"})
            unit.add_characteristic(part["id"], {"name": "D1", "nominal": 10.0, "upper": 10.1, "lower": 9.9,
                                                 "actual": 10.2, "verdict": "scrap"})
            unit.add_log({"task": "hole.1", "target": "G54", "status": "ok"})
        db.report_status({"alarms": [{"code": 61303, "text": "Probe not calibrated"}], "active_offset": "G54",
                          "mode": "JOG"})
        yield db


def test_the_plant_lists_every_machine_with_its_state(plant_client, mill_b):
    body = plant_client.get("/api/plant").json()
    assert body["machine"] == "mill-a"
    machines = {m["name"]: m for m in body["machines"]}
    assert set(machines) == {"mill-a", "mill-b"}
    a, b = machines["mill-a"], machines["mill-b"]
    assert a["this"] and a["online"] and a["alarms"] == [] and a["last_measurement"] is None
    assert not b["this"] and b["active_offset"] == "G54"
    assert b["alarms"] == [{"code": 61303, "text": "Probe not calibrated"}]
    assert b["last_measurement"]["task"] == "hole.1" and b["parts"] == 1
    assert b["calibrated_at"] == "2026-01-01T00:00:00+00:00" and b["calibration_age_h"] > 24 * 300
    assert b["links"] == {"screen": "/plant/mill-b", "api": "/api/plant/mill-b"}


def test_one_machine_with_its_parts_and_measurements(plant_client, mill_b):
    body = plant_client.get("/api/plant/mill-b").json()
    assert [p["serial"] for p in body["parts_list"]] == ["S1"] and body["parts_list"][0]["verdict"] == "scrap"
    assert [m["task"] for m in body["measurements"]] == ["hole.1"]
    missing = plant_client.get("/api/plant/nowhere")
    assert missing.status_code == 404 and missing.json()["error"]["field"] == "name"
    series = plant_client.get("/api/plant/series", params={"part_number": "PN-7", "characteristic": "D1"}).json()
    assert [v["actual"] for v in series["machines"]["mill-b"]] == [10.2] and "mill-a" not in series["machines"]


def test_the_plant_screens(plant_client, mill_b):
    page = plant_client.get("/plant").text
    assert 'data-machine="mill-a"' in page and 'data-machine="mill-b"' in page and "/plant/mill-b" in page
    detail = plant_client.get("/plant/mill-b?lang=de").text
    assert "S1" in detail and "hole.1" in detail
    assert plant_client.get("/plant/nowhere").status_code == 404

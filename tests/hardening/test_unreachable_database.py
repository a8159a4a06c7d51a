"""A plant database (PostgreSQL, docs/plant.md) that cannot be reached at the start (issue 25 item 4,
design.md §10.8, §9.1): the HMI starts read only as on a read-only SQLite file. Nothing stored can
be read, so the screens show the default data; every GET answers, every write answers 503
``storage_unavailable`` with nothing changed, a banner says why, and no answer names the server."""

from __future__ import annotations

import httpx
import pytest
from fastapi.testclient import TestClient
from live import free_port, hmi_process
from test_read_only_start import _screens

from app.config import Settings
from app.main import create_app


@pytest.fixture
def unreachable_url():
    """A PostgreSQL URL on a local port nothing listens on (connection refused at once)."""
    return f"postgresql://hmi@127.0.0.1:{free_port()}/plant"


@pytest.fixture
def unreachable_client(unreachable_url, scenario_file):
    app = create_app(Settings(db_url=unreachable_url, scenario_path=scenario_file, machine_name="mill-7"))
    assert app.state.services.db.read_only and app.state.services.db.unreachable
    with TestClient(app) as client:
        yield client


def test_every_screen_and_get_answers(unreachable_client):
    client = unreachable_client
    failed = {}
    for path in _screens(client):
        answer = client.get(path)
        if answer.status_code >= 500:
            failed[path] = (answer.status_code, answer.text[:200])
    assert failed == {}
    assert len(_screens(client)) > 30
    # the default data: the zero offsets exist and are zero (nothing stored could be read)
    assert client.get("/api/offsets/G54").json()["trans"]["X"] == 0


def test_writes_answer_503_and_change_nothing(unreachable_client, unreachable_url):
    client = unreachable_client
    before = client.get("/api/offsets/G54").json()
    feed = client.get("/api/settings").json()["measuring_feed"]
    tool = client.get("/api/machine").json()["tool"]
    port = unreachable_url.rsplit(":", 1)[1].split("/")[0]
    writes = [client.put("/api/offsets/G54", json={"trans": {"X": 1.0}}),
              client.put("/api/settings", json={"measuring_feed": feed + 50.0}),
              client.put("/api/tools/7", json={"length": 100.0, "radius": 4.0}),
              client.post("/api/machine/tool", json={"tool": 1})]
    for answer in writes:
        assert answer.status_code == 503, answer.text
        error = answer.json()["error"]
        assert error["code"] == "storage_unavailable" and "database cannot be reached" in error["message"]
        assert "127.0.0.1" not in answer.text and port not in answer.text and "postgresql" not in answer.text
    assert client.get("/api/offsets/G54").json() == before
    assert client.get("/api/settings").json()["measuring_feed"] == feed
    assert client.get("/api/tools/7").status_code == 404
    assert client.get("/api/machine").json()["tool"] == tool


def test_the_banner_says_why_in_the_operators_language(unreachable_client):
    page = unreachable_client.get("/jog")
    assert 'id="storage-banner"' in page.text and "Read only: the database cannot be reached." in page.text
    assert "127.0.0.1" not in page.text
    assert "Nur lesen: Die Datenbank ist nicht erreichbar." in unreachable_client.get("/jog?lang=de").text
    assert "只读：无法连接数据库。" in unreachable_client.get("/jog?lang=zh").text


def test_the_command_line_starts_read_only(unreachable_url, scenario_file):
    with hmi_process(unreachable_url, scenario_file, "the HMI answers on an unreachable database") as url:
        assert httpx.get(f"{url}/api/offsets/G54").status_code == 200
        refused = httpx.put(f"{url}/api/offsets/G54", json={"trans": {"X": 1.0}})
        assert refused.status_code == 503 and refused.json()["error"]["code"] == "storage_unavailable"

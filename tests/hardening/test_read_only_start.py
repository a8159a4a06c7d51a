"""A database that can be read but not written (issue 25 item 4, design.md §10.8, §9.1): the HMI
starts read only, every screen and GET answers with the stored data, every write answers 503
``storage_unavailable`` with nothing changed, a banner says why, and no answer shows a server path."""

from __future__ import annotations

import subprocess

import fastapi.routing
import httpx
import pytest
from fastapi.testclient import TestClient
from live import hmi_process

from app.config import Settings
from app.main import create_app

STORED_X = 12.5


def _immutable(path, on: bool) -> bool:
    """chattr +i/-i: read only even for root (the test machine's user); False where not allowed."""
    done = subprocess.run(["chattr", "+i" if on else "-i", str(path)], capture_output=True)
    return done.returncode == 0


@pytest.fixture(params=["read_only_folder", "read_only_uri"])
def read_only_db(request, tmp_path, scenario_file):
    """(the --db value, the folder): a database written once, then a folder nothing can be written
    in (chattr +i, or chmod for a user other than root), or a ``mode=ro`` SQLite URI."""
    folder = tmp_path / "data"
    folder.mkdir()
    path = folder / "hmi.db"
    app = create_app(Settings(db_path=path, scenario_path=scenario_file))
    with TestClient(app) as client:
        assert client.put("/api/offsets/G54", json={"trans": {"X": STORED_X}}).status_code == 200
    if request.param == "read_only_uri":
        yield f"sqlite:///file:{path}?mode=ro&uri=true", folder
        return
    if not _immutable(folder, True):
        folder.chmod(0o555)
        path.chmod(0o444)
    try:
        yield str(path), folder
    finally:
        _immutable(folder, False)
        folder.chmod(0o755)


@pytest.fixture
def read_only_client(read_only_db, scenario_file):
    target, folder = read_only_db
    where = {"db_url": target} if "://" in target else {"db_path": target}
    app = create_app(Settings(**where, scenario_path=scenario_file))
    assert app.state.services.db.read_only
    with TestClient(app) as client:
        yield client


def _screens(client) -> list[str]:
    """Every GET page and API call without path parameters (not the live feed, which never ends)."""
    flatten = getattr(fastapi.routing, "iter_route_contexts", None)
    paths = []
    for route in (flatten(client.app.routes) if flatten else client.app.routes):
        methods = getattr(route, "methods", None) or set()
        path = getattr(route, "path", "")
        if "GET" in methods and "{" not in path and not path.startswith(("/api/events", "/static", "/docs",
                                                                           "/openapi")):
            paths.append(path)
    return sorted(set(paths))


def test_every_screen_and_get_answers_with_the_stored_data(read_only_client):
    client = read_only_client
    assert client.get("/api/offsets/G54").json()["trans"]["X"] == STORED_X
    failed = {}
    for path in _screens(client):
        answer = client.get(path)
        if answer.status_code >= 500:
            failed[path] = (answer.status_code, answer.text[:200])
    assert failed == {}
    assert len(_screens(client)) > 30


def test_writes_answer_503_storage_unavailable_and_change_nothing(read_only_client, read_only_db):
    client = read_only_client
    _target, folder = read_only_db
    before = client.get("/api/offsets/G54").json()
    tool = client.get("/api/machine").json()["tool"]
    writes = [client.put("/api/offsets/G54", json={"trans": {"X": 1.0}}),
              client.put("/api/settings", json={"measuring_feed": 250.0}),
              client.post("/api/machine/tool", json={"tool": 1})]
    for answer in writes:
        assert answer.status_code == 503, answer.text
        error = answer.json()["error"]
        assert error["code"] == "storage_unavailable" and "database" in error["message"]
        assert str(folder) not in error["message"] and "/tmp" not in error["message"]
    assert client.get("/api/offsets/G54").json() == before
    assert client.get("/api/settings").json()["measuring_feed"] != 250.0
    assert client.get("/api/machine").json()["tool"] == tool


def test_the_screens_say_why_in_the_operators_language(read_only_client, read_only_db):
    _target, folder = read_only_db
    page = read_only_client.get("/jog")
    assert 'id="storage-banner"' in page.text and "Read only: the database cannot be written." in page.text
    assert str(folder) not in page.text
    german = read_only_client.get("/jog?lang=de").text
    assert "Nur lesen: Die Datenbank kann nicht beschrieben werden." in german
    chinese = read_only_client.get("/jog?lang=zh").text
    assert "只读：数据库无法写入。" in chinese


def test_a_writable_database_shows_no_banner(client):
    assert not client.app.state.services.db.read_only
    assert 'id="storage-banner"' not in client.get("/jog").text


def test_the_command_line_starts_on_a_read_only_database(read_only_db, scenario_file):
    target, folder = read_only_db
    with hmi_process(target, scenario_file, "the HMI answers on a read-only database") as url:
        assert httpx.get(f"{url}/api/offsets/G54").json()["trans"]["X"] == STORED_X
        refused = httpx.put(f"{url}/api/offsets/G54", json={"trans": {"X": 1.0}})
        assert refused.status_code == 503 and str(folder) not in refused.text

"""Fixtures: an app on a tmp db with a time_scale-0 test scenario, a live server and Chromium."""

from __future__ import annotations

import json

import pytest
from fastapi.testclient import TestClient
from hmi_testdata import TEST_SCENARIO, test_scenario
from live import CHROMIUM_ARGS, browser_tab, serve


@pytest.fixture
def scenario_file(tmp_path):
    path = tmp_path / "scenario.json"
    path.write_text(json.dumps(TEST_SCENARIO))
    return path


@pytest.fixture
def app(tmp_path, scenario_file):
    # imported here so a broken app never stops the db/engine/sim tests from being collected
    from app.config import Settings
    from app.main import create_app

    return create_app(Settings(db_path=tmp_path / "hmi.db", scenario_path=scenario_file))


@pytest.fixture
def client(app):
    with TestClient(app) as test_client:
        yield test_client


# --- end to end -------------------------------------------------------------------------

@pytest.fixture(scope="session")
def live_server(tmp_path_factory):
    """The app served by uvicorn in a thread; yields its base URL."""
    with serve(tmp_path_factory.mktemp("live"), TEST_SCENARIO) as url:
        yield url


@pytest.fixture(scope="session")
def browser():
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        chromium = playwright.chromium.launch(executable_path="/usr/bin/chromium", args=CHROMIUM_ARGS)
        yield chromium
        chromium.close()


@pytest.fixture
def page(browser, live_server):
    with browser_tab(browser, live_server) as tab:
        yield tab


@pytest.fixture
def api(live_server):
    """An HTTP client on the live server, with the machine and data reset to the test scenario."""
    import httpx

    with httpx.Client(base_url=live_server, timeout=10) as http:
        response = http.post("/api/sim/scenario", json={**test_scenario(), "reset_data": True})
        assert response.status_code == 200, response.text
        yield http

"""Fixtures: an app on a tmp db with a time_scale-0 test scenario, a live server and Chromium."""

from __future__ import annotations

import json
import os
import shutil
import sys
from pathlib import Path

import pytest
from fastapi.testclient import TestClient
from hmi_testdata import TEST_SCENARIO, test_scenario
from live import CHROMIUM_ARGS, MIN_WAIT_MS, browser_tab, serve
from pgcluster import database_settings

LATHE_KIT = str(Path(__file__).resolve().parent / "lathe")     # lathe_kit: the lathe scenario and operator
if LATHE_KIT not in sys.path:
    sys.path.append(LATHE_KIT)

# --- the database engine: SQLite by default, PostgreSQL with --db-engine=postgresql ------------

def pytest_addoption(parser):
    parser.addoption("--db-engine", choices=("sqlite", "postgresql"),
                     default=os.environ.get("HMI_TEST_DB_ENGINE", "sqlite"),
                     help="run the database, repository and app tests on this engine (postgresql: a private "
                          "cluster of Debian's postgresql, started and stopped by the tests)")


def pytest_configure(config):
    config.addinivalue_line("markers", "sqlite_only: reads the SQLite file itself (skipped on PostgreSQL)")
    _build_each_route_context_once()


def _build_each_route_context_once():
    """The tests build about a thousand apps from the same routers. FastAPI (>= 0.16x, routers
    included lazily) analyses every included route again for each app: about 0.5 s of CPU for the
    HMI's 400 routes, most of an app test's set-up. The analysis depends only on the route and how
    its router is included, so the tests share it between apps. (A shared context answers
    dependency overrides from the first app: no test uses them.) Older FastAPI copies the routes
    at `include_router` instead and has nothing to share."""
    from fastapi import routing

    context_class = getattr(routing, "_EffectiveRouteContext", None)
    build = getattr(context_class, "from_api_route", None)
    if build is None:
        return
    built: dict[tuple, object] = {}

    def from_api_route(cls, *, original_route, include_context):
        key = (id(original_route), id(include_context.included_router), include_context.prefix,
               tuple(map(id, include_context.dependencies)), include_context.include_in_schema,
               include_context.max_body_size)
        if key not in built:
            built[key] = (original_route, build(original_route=original_route, include_context=include_context))
        return built[key][1]

    context_class.from_api_route = classmethod(from_api_route)


@pytest.hookimpl(tryfirst=True)     # before `-m` deselects (the mark `linuxcnc` below)
def pytest_collection_modifyitems(config, items):
    if config.getoption("--db-engine") == "postgresql":
        skip = pytest.mark.skip(reason="reads the SQLite file itself")
        for item in items:
            if "sqlite_only" in item.keywords:
                item.add_marker(skip)
    # every test that starts a LinuxCNC carries the mark `linuxcnc`, set here before `-m` selects:
    # with pytest-xdist run them on their own, one at a time (one LinuxCNC per computer, and an
    # xdist worker that started one was interrupted): `pytest -n 2 -m "not linuxcnc"`, `pytest -m linuxcnc`
    for item in items:
        if (item.nodeid.startswith("tests/linuxcnc/") or "[linuxcnc" in item.nodeid
                or item.get_closest_marker("linuxcnc") is not None):
            item.add_marker(pytest.mark.linuxcnc)


@pytest.fixture(scope="session")
def pg_cluster():
    """A private PostgreSQL cluster for the session (tests/pgcluster.py); stopped at the end."""
    from pgcluster import PgCluster, available

    if not available():
        pytest.skip("PostgreSQL is not installed (scripts/test.sh installs Debian's postgresql)")
    with PgCluster() as cluster:
        yield cluster


@pytest.fixture
def database_target(request, tmp_path):
    """Where a test's database lives: a SQLite file, or a new database in the private cluster."""
    if request.config.getoption("--db-engine") == "postgresql":
        return request.getfixturevalue("pg_cluster").new_database()
    return tmp_path / "data" / "hmi.db"


@pytest.fixture
def scenario_file(tmp_path):
    path = tmp_path / "scenario.json"
    path.write_text(json.dumps(TEST_SCENARIO))
    return path


@pytest.fixture(scope="session")
def migrated_sqlite(tmp_path_factory):
    """An empty SQLite file migrated to the head revision once per session (db.upgrade_to_head,
    no rows). An app's SQLite database starts as a copy of it, so each app test does not run
    every migration again; the migrations themselves are tested from an empty file in tests/db."""
    from sqlalchemy import create_engine

    from db.database import upgrade_to_head

    path = tmp_path_factory.mktemp("migrated") / "hmi.db"
    engine = create_engine(f"sqlite:///{path}")
    try:
        with engine.begin() as connection:
            upgrade_to_head(connection)
    finally:
        engine.dispose()
    return path


@pytest.fixture
def app(request, database_target, scenario_file):
    # imported here so a broken app never stops the db/engine/sim tests from being collected
    from app.config import Settings
    from app.main import create_app

    if not isinstance(database_target, str):                  # SQLite: start from the migrated copy
        database_target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(request.getfixturevalue("migrated_sqlite"), database_target)
    return create_app(Settings(**database_settings(database_target), scenario_path=scenario_file))


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
    from playwright.sync_api import expect, sync_playwright

    expect.set_options(timeout=MIN_WAIT_MS)     # expect's own ceiling (5 s by default) as browser_tab's
    with sync_playwright() as playwright:
        chromium = playwright.chromium.launch(executable_path="/usr/bin/chromium", args=CHROMIUM_ARGS)
        yield chromium
        chromium.close()


@pytest.fixture
def page(browser, live_server):
    with browser_tab(browser, live_server) as tab:
        yield tab


@pytest.fixture(scope="module")
def lathe_server(tmp_path_factory):
    """The app on the simulated lathe (tests/lathe/lathe_kit.py's scenario) served by uvicorn, one
    per test module; yields its base URL."""
    from lathe_kit import LATHE_SCENARIO

    with serve(tmp_path_factory.mktemp("lathe-live"), LATHE_SCENARIO) as url:
        yield url


@pytest.fixture
def lathe(lathe_server):
    """The lathe server's API as lathe_kit's operator (``Lathe``), its machine and data reset to the
    scenario. (Tests on a TestClient define their own ``lathe``.)"""
    import httpx
    from lathe_kit import LATHE_SCENARIO, Lathe

    with httpx.Client(base_url=lathe_server, timeout=30) as http:
        response = http.post("/api/sim/scenario", json={**LATHE_SCENARIO, "reset_data": True})
        assert response.status_code == 200, response.text
        yield Lathe(http)


@pytest.fixture
def api(live_server):
    """An HTTP client on the live server, with the machine and data reset to the test scenario."""
    import httpx

    with httpx.Client(base_url=live_server, timeout=10) as http:
        response = http.post("/api/sim/scenario", json={**test_scenario(), "reset_data": True})
        assert response.status_code == 200, response.text
        yield http

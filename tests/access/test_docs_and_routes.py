"""Every write route names its function in the level table; /docs and /redoc are offline and show
the real error envelope; the command line's access subcommands and the non-loopback refusal."""

from __future__ import annotations

import io
import re
import subprocess
import sys
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path
from unittest.mock import patch

import fastapi.routing
from access_helpers import error_of

from app.access.deps import PUBLIC_ROUTES, declared_function
from app.access.levels import FUNCTIONS

ROOT = Path(__file__).resolve().parents[2]
UNSAFE = {"POST", "PUT", "PATCH", "DELETE"}


def _routes(app):
    flatten = getattr(fastapi.routing, "iter_route_contexts", None)
    return list(flatten(app.routes)) if flatten else list(app.routes)


def test_every_write_route_names_its_function(app):
    """A new write route must say which function of the level table it is (``needs(...)``); an
    undeclared one would need the settings level, which this test does not let pass unnoticed."""
    checked, missing = 0, []
    for route in _routes(app):
        if not (set(getattr(route, "methods", None) or ()) & UNSAFE) or route.name in PUBLIC_ROUTES:
            continue
        checked += 1
        function = declared_function(route)
        if function not in FUNCTIONS:
            missing.append(f"{sorted(route.methods)} {route.path} ({route.name})")
    assert checked >= 50 and not missing, missing


def test_the_guard_is_on_every_router(app):
    for route in _routes(app):
        if route.name in ("openapi", "static") or not hasattr(route, "dependant"):
            continue
        names = {getattr(d.call, "__name__", "") for d in route.dependant.dependencies}
        assert "guard" in names, route.path


def test_docs_are_served_from_the_vendored_files(client):
    page = client.get("/docs")
    assert page.status_code == 200
    sources = re.findall(r'(?:src|href)="([^"]+)"', page.text)
    assert sources and all(s.startswith("/static/") for s in sources), sources
    assert "cdn" not in page.text and "googleapis" not in page.text
    assert "/static/docs-csrf.js" in page.text and page.text.index("docs-csrf.js") < page.text.index("swagger-ui-bundle.js")
    csp = page.headers["content-security-policy"]
    assert "'sha256-" in csp and "frame-ancestors 'none'" in csp and "unsafe-inline" not in csp.split(";")[1]
    for path in sources:
        assert client.get(path).status_code == 200, path
    redoc = client.get("/redoc")
    assert redoc.status_code == 200 and "/static/vendor/redoc-2.5.4/redoc.standalone.js" in redoc.text
    assert "fonts.googleapis" not in redoc.text
    assert client.get("/static/docs-csrf.js").status_code == 200


def test_the_schema_shows_the_error_envelope_and_the_credentials(client):
    schema = client.get("/openapi.json").json()
    put = schema["paths"]["/api/offsets/{name}"]["put"]
    assert "4XX" in put["responses"]                    # the catch-all, and each status (app/openapi_doc.py)
    assert put["responses"]["422"]["content"]["application/json"]["schema"] == put["responses"]["4XX"][
        "content"]["application/json"]["schema"]
    ref = put["responses"]["4XX"]["content"]["application/json"]["schema"]["$ref"]
    envelope = schema["components"]["schemas"][ref.rsplit("/", 1)[1]]
    assert set(envelope["properties"]) == {"error"}
    body = schema["components"]["schemas"]["ErrorBody"]["properties"]
    assert {"code", "message", "field", "required_level"} <= set(body)
    schemes = schema["components"]["securitySchemes"]
    assert {"HTTPBearer", "APIKeyCookie"} <= set(schemes)
    assert "/api/session" in schema["paths"] and "/api/audit/{audit_id}/undo" in schema["paths"]
    assert put["operationId"] == "put_offset_api_offsets__name__put"        # ids unchanged


def test_docs_stay_reachable_with_sign_in_on_and_try_it_out_gets_the_levels(signin_client):
    assert signin_client.get("/docs").status_code == 200
    assert signin_client.get("/openapi.json").status_code == 200
    response = signin_client.put("/api/offsets/G54", json={"trans": {"X": 1.0}})
    assert response.status_code == 401 and error_of(response)["code"] == "unauthenticated"


# --- command line -------------------------------------------------------------------------------------

def run_cli(*args, stdin: str = "", env_db: Path) -> subprocess.CompletedProcess:
    """``python -m app --db <env_db> ...`` as a process, as the operator runs it."""
    return subprocess.run([sys.executable, "-m", "app", "--db", str(env_db), *args], cwd=ROOT, input=stdin,
                          capture_output=True, text=True, timeout=120)


def run_cli_here(*args, stdin: str = "", env_db: Path) -> subprocess.CompletedProcess:
    """The same command through ``app.__main__.main`` in this process (no interpreter start per
    call): the exit code and the printed lines as ``python -m app`` gives them (``sys.exit(text)``
    prints the text to stderr and exits 1)."""
    from app.__main__ import main

    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), redirect_stderr(err), patch.object(sys, "stdin", io.StringIO(stdin)):
        try:
            main(["--db", str(env_db), *args])
            code = 0
        except SystemExit as exc:
            if isinstance(exc.code, str):
                print(exc.code, file=sys.stderr)
            code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    return subprocess.CompletedProcess(args, code, out.getvalue(), err.getvalue())


def test_cli_user_and_token_add_then_the_api_answers_by_level(tmp_path, scenario_file):
    db = tmp_path / "cli.db"
    added = run_cli("user", "add", "anna", "--level", "3", stdin="s3cret-pw\n", env_db=db)
    assert added.returncode == 0, added.stderr
    assert "sign-in is on" in added.stdout
    low = run_cli_here("token", "add", "mes", "--level", "7", env_db=db)
    high = run_cli_here("token", "add", "writer", "--level", "5", env_db=db)
    assert low.returncode == 0 and low.stdout.strip().startswith("hmi_") and "shown only now" in low.stderr
    listed = run_cli_here("token", "list", env_db=db)
    assert "mes\tlevel 7" in listed.stdout and low.stdout.strip() not in listed.stdout
    assert run_cli_here("user", "add", "anna", "--level", "2", stdin="other-pw\n", env_db=db).returncode == 1
    assert run_cli_here("user", "add", "bob", "--level", "3", stdin="ab\n", env_db=db).returncode == 1   # too short
    assert run_cli_here("keyswitch", "2", env_db=db).stdout.strip() == "keyswitch turned to position 2 = level 5"

    from fastapi.testclient import TestClient

    from app.config import Settings
    from app.main import create_app

    app = create_app(Settings(db_path=db, scenario_path=scenario_file))
    with TestClient(app) as client:
        assert client.put("/api/offsets/G54", json={"trans": {"X": 1.0}}).status_code == 401
        weak = client.put("/api/offsets/G54", json={"trans": {"X": 1.0}},
                          headers={"Authorization": f"Bearer {low.stdout.strip()}"})
        assert weak.status_code == 403 and error_of(weak)["required_level"] == 5
        ok = client.put("/api/offsets/G54", json={"trans": {"X": 1.0}},
                        headers={"Authorization": f"Bearer {high.stdout.strip()}"})
        assert ok.status_code == 200
        row = client.get("/api/audit", params={"name": "G54"}, headers={"Authorization": f"Bearer {high.stdout.strip()}"})
        assert row.json()[0]["who"] == "token:writer"
        signed = client.post("/api/session", json={"user": "anna", "password": "s3cret-pw"})
        assert signed.status_code == 200 and signed.json()["level"] == 3
        kinds = {r["kind"] for r in client.get("/api/audit", params={"limit": 100}).json()}
        assert {"user", "token", "keyswitch"} <= kinds


def test_a_non_loopback_host_without_users_does_not_start(tmp_path):
    db = tmp_path / "open.db"
    refused = run_cli("--host", "0.0.0.0", "--port", "8999", env_db=db)
    assert refused.returncode != 0
    assert "no user is configured" in refused.stderr and "user add" in refused.stderr

    from app.__main__ import parse_args, refuse_open_trainer, settings_from_args

    settings = settings_from_args(parse_args(["--db", str(db), "--host", "0.0.0.0"]))
    assert refuse_open_trainer(settings)
    assert refuse_open_trainer(settings_from_args(parse_args(["--db", str(db)]))) is None
    assert run_cli_here("user", "add", "anna", "--level", "1", stdin="s3cret-pw\n", env_db=db).returncode == 0
    assert refuse_open_trainer(settings) is None


def test_the_bind_address_is_a_trusted_host():
    from app.config import Settings
    from app.main import trusted_hosts

    assert trusted_hosts(Settings()) == ["127.0.0.1", "localhost", "[::1]"]
    assert "10.0.0.5" in trusted_hosts(Settings(host="10.0.0.5"))
    assert "0.0.0.0" not in trusted_hosts(Settings(host="0.0.0.0", trusted_hosts=["hmi.local"]))

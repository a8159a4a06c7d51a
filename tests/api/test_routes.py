"""Named routes: every route of app/web and app/api has a unique name, and no URL is written out
anywhere else: templates build links, htmx attributes, form actions and static files with
``url_path(route, **path_params)``, Python code with ``url_path(request, ...)`` (app/web/templating.py),
static/hmi.js takes its URLs from the page. A route can then move without hunting strings; the
URLs that are contracts (design.md §4, the screens the Playwright tests open) are pinned below.

The sources are parsed, not imported, and each check first proves that it sees what it must
(the files, the decorators) and that it would catch a literal URL, so that none passes vacuously.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import fastapi.routing
import pytest

ROOT = Path(__file__).resolve().parents[2]
MODULE_DIRS = ("app/web", "app/api")
ROUTE_METHODS = {"get", "post", "put", "patch", "delete", "api_route"}
# routes FastAPI and the static mount bring (app/main.py); every other route is one of ours
FRAMEWORK_ROUTES = {"openapi", "swagger_ui_html", "swagger_ui_redirect", "redoc_html", "static"}
# at least the files of today (a moved directory must not leave a check with nothing to look at)
MIN_TEMPLATES, MIN_MODULES, MIN_DECORATORS = 17, 25, 102

# the URLs other programs and the Playwright tests rely on: route name -> "METHOD path"
CONTRACTS = {
    # design.md §4: the JSON API
    "api_health": "GET /api/health",
    "api_sim_scenario": "POST /api/sim/scenario",
    "api_machine": "GET /api/machine",
    "api_machine_jog": "POST /api/machine/jog",
    "api_machine_jog_continuous": "POST /api/machine/jog/continuous",
    "api_machine_goto": "POST /api/machine/goto",
    "api_machine_reset": "POST /api/machine/reset",
    "api_machine_override": "PUT /api/machine/override",
    "api_machine_tool": "POST /api/machine/tool",
    "api_machine_activate": "POST /api/machine/activate",
    "api_machine_probe": "POST /api/machine/probe",
    "api_measure_create": "POST /api/measure",
    "api_measure_current": "GET /api/measure/current",
    "api_measure_session": "GET /api/measure/{session_id}",
    "api_measure_start": "POST /api/measure/{session_id}/start",
    "api_measure_invalidate": "POST /api/measure/{session_id}/points/{n}/invalidate",
    "api_measure_calculate": "POST /api/measure/{session_id}/calculate",
    "api_measure_delete": "DELETE /api/measure/{session_id}",
    "api_setup_support": "GET /api/measure/{session_id}/setup-support",
    "api_offsets": "GET /api/offsets",
    "api_offset_get": "GET /api/offsets/{name}",
    "api_offset_put": "PUT /api/offsets/{name}",
    "api_audit": "GET /api/audit",
    "api_probe_get": "GET /api/probes/{n}",
    "api_probe_put": "PUT /api/probes/{n}",
    "api_tool_probe_get": "GET /api/tool-probes/{n}",
    "api_tool_get": "GET /api/tools/{t}",
    "api_tool_put": "PUT /api/tools/{t}",
    "api_settings_get": "GET /api/settings",
    "api_settings_put": "PUT /api/settings",
    "api_log": "GET /api/log",
    "api_log_entry": "GET /api/log/{log_id}",
    "api_plc_db19": "GET /api/plc/db19",
    "api_plc_dbb43_write": "PUT /api/plc/db19/dbb43",
    "api_readiness": "GET /api/readiness",
    # design.md §7: the screens (bookmarks, the Playwright tests)
    "root": "GET /",
    "jog_screen": "GET /jog",
    "offsets_screen": "GET /offsets",
    "offsets_audit_screen": "GET /offsets/audit",
    "tools_screen": "GET /tools",
    "machine_view_screen": "GET /machine-view",
    "settings_screen": "GET /settings",
    "log_screen": "GET /log",
    "log_detail": "GET /log/{log_id}",
    "log_export_csv": "GET /log/export.csv",
    "log_export_json": "GET /log/export.json",
    "probes_screen": "GET /probes",
    "tool_probes_screen": "GET /tool-probes",
    "plc_screen": "GET /plc",
    "measure_workpiece_menu": "GET /measure/workpiece",
    "measure_workpiece_group": "GET /measure/workpiece/{group}",
    "measure_workpiece_task": "GET /measure/workpiece/{group}/{task}",
    "measure_tool_menu": "GET /measure/tool",
    "measure_tool_task": "GET /measure/tool/{task}",
    "tilted_setup_screen": "GET /measure/workpiece/tilted-setup",
    "setup_support_screen": "GET /measure/setup-support/{session_id}",
}


# --- what the app serves ---------------------------------------------------------------------

def _routes(app) -> list:
    """Every route the app serves (newer FastAPI keeps included routers nested: flattened here)."""
    flatten = getattr(fastapi.routing, "iter_route_contexts", None)
    return list(flatten(app.routes)) if flatten else list(app.routes)


def _segments(app) -> set[str]:
    """The first path segments of the app's routes ("api", "measure", "static", ...)."""
    return {r.path.strip("/").split("/")[0] for r in _routes(app)} - {""}


def _literal_url(segments: set[str]) -> re.Pattern:
    """A quoted string that starts a URL of the app: ``"/measure/..."``, ``'/static/...'``."""
    alternatives = "|".join(sorted(map(re.escape, segments), key=len, reverse=True))
    return re.compile(rf"""["'`]/(?:{alternatives})(?![\w.-])""")


# --- what the sources say --------------------------------------------------------------------

def _modules() -> list[Path]:
    return sorted(p for d in MODULE_DIRS for p in (ROOT / d).glob("*.py"))


def _route_decorators(tree: ast.AST) -> list[ast.Call]:
    """``@router.get("/path", name=...)`` and the like."""
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            for deco in node.decorator_list:
                if (isinstance(deco, ast.Call) and isinstance(deco.func, ast.Attribute)
                        and deco.func.attr in ROUTE_METHODS):
                    found.append(deco)
    return found


def _decorator_name(deco: ast.Call) -> str | None:
    name = next((k.value for k in deco.keywords if k.arg == "name"), None)
    return name.value if isinstance(name, ast.Constant) and isinstance(name.value, str) else None


def _allowed_strings(tree: ast.AST) -> set[int]:
    """ids of the string nodes where a path belongs: the decorators' paths, routers' ``prefix=``,
    docstrings (documentation may name a URL)."""
    allowed: set[int] = set()
    for deco in _route_decorators(tree):
        allowed.update(id(a) for a in deco.args[:1])
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            allowed.update(id(k.value) for k in node.keywords if k.arg == "prefix")
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef) and node.body:
            first = node.body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
                allowed.add(id(first.value))
    return allowed


def _url_literals(source: str, pattern: re.Pattern) -> list[tuple[int, str]]:
    """(line, text) of every string (or f-string part) outside the allowed places that starts a URL."""
    tree = ast.parse(source)
    allowed = _allowed_strings(tree)
    hits = [(node.lineno, node.value) for node in ast.walk(tree)
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in allowed
            and pattern.search('"' + node.value)]       # a string that starts with a URL, or holds a quoted one
    return sorted(hits)


TEMPLATE_ATTRIBUTE = re.compile(r"""\b(?:href|src|action|hx-[a-z-]+)\s*=\s*["']?/""")


def _template_literals(text: str, pattern: re.Pattern) -> list[tuple[int, str]]:
    hits = []
    for n, line in enumerate(text.splitlines(), 1):
        if TEMPLATE_ATTRIBUTE.search(line) or pattern.search(line):
            hits.append((n, line.strip()))
    return hits


# --- (a) names ---------------------------------------------------------------------------------

def test_every_route_has_a_unique_name(app):
    routes = _routes(app)
    names = [r.name for r in routes]
    duplicates = sorted({n for n in names if names.count(n) > 1})
    assert not duplicates, f"route names used more than once: {duplicates}"
    assert None not in names and "" not in names

    decorators = {}
    modules = _modules()
    assert len(modules) >= MIN_MODULES, [str(p) for p in modules]
    for path in modules:
        for deco in _route_decorators(ast.parse(path.read_text())):
            where = f"{path.relative_to(ROOT)}:{deco.lineno}"
            assert _decorator_name(deco), f"{where}: the route has no name= (a string literal)"
            assert _decorator_name(deco) not in decorators, f"{where}: name used twice"
            decorators[_decorator_name(deco)] = where
    assert len(decorators) >= MIN_DECORATORS
    # the app serves exactly the named routes of app/web and app/api, and the framework's own
    expected = set(decorators) | FRAMEWORK_ROUTES
    assert set(names) == expected, set(names) ^ expected


def test_api_routes_are_named_api(app):
    for route in _routes(app):
        if route.path.startswith("/api/") or route.path == "/api":
            assert route.name.startswith("api_"), (route.path, route.name)
        elif route.name not in FRAMEWORK_ROUTES:
            assert not route.name.startswith("api_"), (route.path, route.name)


def test_the_contract_urls_are_where_they_were(app):
    served = {r.name: " ".join((*sorted(r.methods or ()), r.path)) for r in _routes(app)}
    assert {name: served.get(name) for name in CONTRACTS} == CONTRACTS
    hole1 = app.url_path_for("measure_workpiece_task", group="pocket", task="hole1")
    assert hole1 == "/measure/workpiece/pocket/hole1"
    assert app.url_path_for("static", path="htmx-2.0.11.min.js") == "/static/htmx-2.0.11.min.js"


# --- (b) templates and static JS ---------------------------------------------------------------

def test_templates_write_no_url(app):
    pattern = _literal_url(_segments(app))
    # the checks catch what they must ...
    for bad in ('<a href="/jog">', "hx-post='/ui/reset'", 'action="/measure/workpiece/tilted-setup/start"',
                '<script src="/static/hmi.js">', '{"label": "Back", "href": "/measure/workpiece"}',
                "edit_cell(\"/offsets/\" ~ cell.name"):
        assert _template_literals(bad, pattern), bad
    assert not _template_literals("""<a href="{{ url_path('jog_screen') }}">""", pattern)
    # ... and look at every template
    templates = sorted((ROOT / "templates").glob("*.html"))
    assert len(templates) >= MIN_TEMPLATES and {"base.html", "macros.html", "measure_task.html"} <= {
        p.name for p in templates}
    found = {str(p.relative_to(ROOT)): _template_literals(p.read_text(), pattern) for p in templates}
    assert not {k: v for k, v in found.items() if v}
    calls = sum(p.read_text().count("url_path(") for p in templates)
    assert calls >= 60, calls


def test_hmi_js_takes_its_urls_from_the_page(app):
    pattern = _literal_url(_segments(app))
    text = (ROOT / "static" / "hmi.js").read_text()
    assert "post(" in text and "dataset" in text
    assert not [line for line in text.splitlines() if pattern.search(line)]
    base = (ROOT / "templates" / "base.html").read_text()
    for attribute in ("data-url=\"{{ url_path('panel_nc_start') }}\"",
                      "data-jog-start=\"{{ url_path('panel_jog_start') }}\"",
                      "data-jog-stop=\"{{ url_path('panel_jog_stop') }}\""):
        assert attribute in base


# --- (c) Python modules ------------------------------------------------------------------------

def test_python_modules_write_no_url(app):
    pattern = _literal_url(_segments(app))
    # the check catches what it must, and lets the decorators, prefixes and docstrings be
    sample = '''
"""Docstring naming ``/jog``."""
router = APIRouter(prefix="/measure")
@router.get("/jog", name="jog_screen")
def jog(request):
    """Opens ``/jog``."""
    a = RedirectResponse("/jog")
    b = f"/measure/setup-support/{sid}/leave"
    c = {"label": "Back", "href": "/measure/workpiece"}
    d = "/static/hmi.css"
    e = ("mm/min", "text/csv", "/", "a/log")
'''
    assert [text for _line, text in _url_literals(sample, pattern)] == [
        "/jog", "/measure/setup-support/", "/measure/workpiece", "/static/hmi.css"]
    modules = _modules()
    assert len(modules) >= MIN_MODULES
    decorators = 0
    hits = {}
    for path in modules:
        source = path.read_text()
        decorators += len(_route_decorators(ast.parse(source)))
        found = _url_literals(source, pattern)
        if found:
            hits[str(path.relative_to(ROOT))] = found
    assert decorators >= MIN_DECORATORS, decorators
    assert not hits


@pytest.mark.parametrize("path, segment", [("/api/health", "api"), ("/measure/tool", "measure"),
                                           ("/static/hmi.js", "static"), ("/machine-view", "machine-view")])
def test_the_segments_come_from_the_app(app, path, segment):
    assert segment in _segments(app)
    assert _literal_url(_segments(app)).search(f'"{path}"')


def test_every_route_name_in_use_exists(app):
    """A misspelt name would only fail when its page is rendered: check every use against the app."""
    names = {r.name for r in _routes(app)}
    call = re.compile(r"""\b(?:url_path|softkey)\((?:request,\s*)?(?:"[^"]*",\s*)?["'](\w+)["']""")
    used: dict[str, str] = {}
    for path in sorted((ROOT / "templates").glob("*.html")) + _modules():
        for n, line in enumerate(path.read_text().splitlines(), 1):
            for name in call.findall(line):
                used.setdefault(name, f"{path.relative_to(ROOT)}:{n}")
    from app.web import measure, templating, tilted_setup

    used.update({key[2]: "HORIZONTAL_SOFTKEYS" for key in templating.HORIZONTAL_SOFTKEYS if key})
    used.update({route: "MENU_ROUTES" for route, _params in measure.MENU_ROUTES.values()})
    used[measure.TILTED_SETUP_KEY[1]] = "TILTED_SETUP_KEY"
    assert len(used) >= 50 and {"static", "panel_nc_start", "measure_task_start"} <= set(used)
    assert {name: where for name, where in used.items() if name not in names} == {}
    assert set(tilted_setup.STEP_TASKS.values()) <= set(tilted_setup.PAGES)


@pytest.mark.parametrize("root_path", ["", "/hmi"])
def test_url_path_is_url_for_of_every_route(app, root_path):
    """``url_path`` (an index of the routes, for speed) gives what Starlette's ``url_for`` gives."""
    from starlette.requests import Request
    from starlette.routing import NoMatchFound

    from app.web.templating import url_path

    request = Request({"type": "http", "app": app, "router": app.router, "root_path": root_path,
                       "path": "/", "headers": [(b"host", b"hmi.test")], "scheme": "http",
                       "server": ("hmi.test", 80), "query_string": b""})
    checked = 0
    for route in _routes(app):
        params = {p: "7" for p in re.findall(r"{(\w+)(?::\w+)?}", route.path)}
        if route.name == "static":                      # its version as the query (static_files)
            params = {"path": "hmi.css"}
            given, _, version = url_path(request, route.name, **params).partition("?v=")
            assert len(version) == 12, version
        else:
            given = url_path(request, route.name, **params)
        assert given == request.url_for(route.name, **params).path
        checked += 1
    assert checked >= MIN_DECORATORS and url_path(request, "jog_screen") == f"{root_path}/jog"
    with pytest.raises(NoMatchFound):
        url_path(request, "no_such_route")
    with pytest.raises(NoMatchFound):
        url_path(request, "offsets_edit_cell", name="G54")        # a path param missing

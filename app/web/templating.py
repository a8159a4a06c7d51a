"""Jinja2 + jinja2-fragments: full page on a normal GET, only the screen blocks on an htmx request.

A screen template extends ``base.html`` and fills ``content`` and ``vkeys``; ``render_screen``
returns the blocks ``screen``, ``vsoftkeys`` and ``hsoftkeys`` (the last two swap out of band).

URLs are never written out: templates call the global ``url_path(route, **path_params)``, Python
code ``url_path(request, route, **path_params)``; both give the path of the named route (a route
can move without hunting strings). Query strings are not part of a route: add them after the path.
"""

from __future__ import annotations

from pathlib import Path

import fastapi.routing
import jinja2_fragments
from fastapi import Request
from fastapi.responses import HTMLResponse
from jinja2 import pass_context
from jinja2_fragments.fastapi import Jinja2Blocks
from markupsafe import escape
from starlette.routing import NoMatchFound

from app import i18n
from app.access.deps import denied, identity_of
from app.gud import GudSettings
from app.i18n import N_, format_fixed
from app.web import texts, units
from app.web.panel_state import PanelState
from app.web.static_files import versioned

TEMPLATES_DIR = Path(__file__).resolve().parents[2] / "templates"
SCREEN_BLOCKS = ["screen", "vsoftkeys", "hsoftkeys"]

# Horizontal softkeys F1..F8 (design.md §7): (screen, label, route name); None = an empty key.
# Labels are catalogue texts (N_), translated where the macro shows them.
HORIZONTAL_SOFTKEYS: list[tuple[str, str, str] | None] = [
    ("measure_workpiece", N_("Measure workpiece"), "measure_workpiece_menu"),
    ("measure_tool", N_("Measure tool"), "measure_tool_menu"),
    ("offsets", N_("Zero offset"), "offsets_screen"),
    ("tools", N_("Tool list"), "tools_screen"),
    ("machine_view", N_("Machine view"), "machine_view_screen"),
    ("settings", N_("Settings"), "settings_screen"),
    ("log", N_("Log"), "log_screen"),
    ("jog", N_("JOG"), "jog_screen"),
    ("mda", N_("MDA / AUTO"), "mda_screen"),
    ("programs", N_("Programs"), "programs_screen"),
]


# on a lathe (turning.md §10.1) F1 opens the lathe's measuring menu, a product extension; F2 is empty
LATHE_HORIZONTAL_SOFTKEYS: list[tuple[str, str, str] | None] = [
    ("measure_lathe", N_("Measure turned part"), "measure_lathe_menu"), None, *HORIZONTAL_SOFTKEYS[2:]]


def _route_index(app) -> dict:
    """{route name: route} of the app, made on first use (``app.state.route_index``): the router's
    own lookup tries every route in turn (0.2-0.5 ms a URL), too slow for a table with a URL per
    cell. Routes are not added once the app serves."""
    index = getattr(app.state, "route_index", None)
    if index is None:
        flatten = getattr(fastapi.routing, "iter_route_contexts", None)    # included routers stay nested
        index = {}
        for route in (flatten(app.router.routes) if flatten else app.router.routes):
            index.setdefault(route.name, route)         # the first one, as the router's lookup finds it
        app.state.route_index = index
    return index


def url_path(request: Request, route: str, /, **path_params) -> str:
    """The path of the named route (under the app's root path): links, htmx attributes, headers.
    The same as ``request.url_for(route, **path_params).path``, from an index of the routes."""
    try:
        path = _route_index(request.app)[route].url_path_for(route, **path_params)
    except (KeyError, NoMatchFound):
        path = request.app.url_path_for(route, **path_params)      # the router's own lookup and its error
    query = versioned(path_params["path"]) if route == "static" else ""   # kept by the browser (static_files)
    return request.scope.get("root_path", "").rstrip("/") + str(path) + query


@pass_context
def _url_path(context, route: str, /, **path_params) -> str:
    return url_path(context["request"], route, **path_params)


def softkey(request: Request, label: str, route: str, /, *, post: bool = False, **path_params) -> dict:
    """A vertical softkey of ``ui.vsoftkeys``: opens the named route (GET), or posts to it. The
    label is translated here (a catalogue text; an already translated one stays as it is)."""
    return {"label": i18n.gettext(label), ("post" if post else "href"): url_path(request, route, **path_params)}

INCH = units.MM_PER_INCH


def fmt_length(value: float | None, gud: GudSettings, rotary: bool = False) -> str:
    """Display a stored mm value in the screen's unit (app/web/units.py: 3 decimals in mm, 4 in
    inch); rotary axes in degrees."""
    if value is None:
        return ""
    if rotary:
        return format_fixed(value, 3)
    return units.format_length(value, gud)


def fixed(value, decimals: int = 4) -> str:
    """Fixed-point display in the language's decimal sign, without a "-0.0000"."""
    return format_fixed(value, decimals)


def vkeys(keys: list, back: dict) -> list:
    """Vertical softkeys S-F1.. with ``back`` on S-F8 (the way out of a screen); None = an empty key."""
    return [*keys, *[None] * (7 - len(keys)), back]


# result keys in degrees (4 decimals); the others are mm (3 decimals), design.md §4
ANGLE_KEYS = frozenset({"angle", "alpha", "beta", "angle_2", "corner_angle", "setpoint_angle"})


def fmt_result(key: str, value, gud: GudSettings | None = None) -> str:
    """A measuring result value: yes/no, degrees with 4 decimals, lengths in the screen's unit
    (mm 3 decimals, inch 4), else as text."""
    if isinstance(value, bool):
        return i18n.gettext("yes") if value else i18n.gettext("no")
    if isinstance(value, int | float):
        if key in ANGLE_KEYS:
            return fixed(value, 4)
        return units.format_length(value, gud) if gud is not None else fixed(value, 3)
    return str(value)


templates = Jinja2Blocks(directory=str(TEMPLATES_DIR))
# operator texts: {{ _("text") }} and {% trans %} (jinja2.ext.i18n, Babel's extractor; docs/architecture.md)
templates.env.add_extension("jinja2.ext.i18n")
templates.env.policies["ext.i18n.trimmed"] = True
templates.env.install_gettext_callables(  # type: ignore[attr-defined]  # added by the i18n extension above
    i18n.gettext, i18n.ngettext, newstyle=True)
templates.env.globals["current_language"] = i18n.language
templates.env.globals["LANGUAGES"] = i18n.LANGUAGES
templates.env.filters["in_unit"] = units.format_length         # {{ mm|in_unit(gud) }} (not "length": Jinja's own)
templates.env.filters["feed"] = units.format_feed              # {{ mm_per_min|feed(gud) }}
templates.env.filters["field_text"] = units.field_text         # a stored mm value in an input field
templates.env.filters["unit"] = units.unit                     # {{ gud|unit("mm") }} -> mm or inch
templates.env.filters["datetime"] = i18n.format_datetime
templates.env.globals["record_places"] = units.record_places
templates.env.globals["alarm_text"] = texts.alarm_text
templates.env.globals["alarm_remedy"] = texts.alarm_remedy
templates.env.globals["program_state_text"] = texts.program_state_text
templates.env.globals["verdict_text"] = texts.verdict_text
templates.env.globals["increment_text"] = texts.increment_text
templates.env.globals["field_name"] = texts.field_name
templates.env.globals["label_text"] = texts.label_text
templates.env.globals["nc_state_text"] = texts.nc_state_text
templates.env.globals["result_value"] = texts.result_value
templates.env.globals["source_text"] = texts.source_text
templates.env.globals["log_status_text"] = texts.log_status_text
templates.env.filters["label_text"] = texts.label_text
templates.env.filters["breakable"] = texts.breakable          # soft hyphens in long key labels
templates.env.globals["say"] = texts.translate_message      # a service's message in the operator's words
templates.env.filters["say"] = texts.translate_message
templates.env.globals["HORIZONTAL_SOFTKEYS"] = HORIZONTAL_SOFTKEYS
templates.env.globals["url_path"] = _url_path
templates.env.globals["csrf_token"] = pass_context(lambda context: csrf_token(context["request"]))
# '' when the request may do the function of the level table, else why not (disabled softkeys)
templates.env.globals["access_denied"] = pass_context(lambda context, function: denied(context["request"], function))
templates.env.filters["mm"] = fmt_length
templates.env.filters["fixed"] = fixed


def _context(request: Request, context: dict | None) -> dict:
    """Render context: the request, the panel state and the macros as ``ui``: a module made for this
    request, so that blocks rendered on their own (htmx partials) can call them and the macros can
    build URLs with ``url_path``."""
    gud = request.app.state.services.settings.get()        # the macros show lengths in its units
    ui = templates.env.get_template("macros.html").make_module({"request": request, "gud": gud})
    return {"request": request, "ui": ui, **base_context(request), **(context or {})}


def is_htmx(request: Request) -> bool:
    return request.headers.get("HX-Request") == "true" and "HX-History-Restore-Request" not in request.headers


class AccessView:
    """The access levels as the templates see them: who acts, and why a softkey is disabled."""

    def __init__(self, request: Request):
        self._request = request
        self.identity = identity_of(request)

    def denied(self, function: str) -> str:
        """'' when allowed, else the reason ("needs level 5: keyswitch position 2 ...")."""
        return denied(self._request, function)

    def may(self, function: str) -> bool:
        return not self.denied(function)

    @property
    def trainer(self) -> bool:
        return self.identity.kind == "trainer"

    @property
    def signed_in(self) -> bool:
        return self.identity.kind in ("user", "panel")

    @property
    def keyswitch(self) -> int:
        return self._request.app.state.access.keyswitch()


def csrf_token(request: Request) -> str:
    """The CSRF token of this browser (asgi-csrf sets its cookie with this answer if needed)."""
    token = request.scope.get("csrftoken")
    return token() if callable(token) else ""


def base_context(request: Request) -> dict:
    services = request.app.state.services
    machine = services.machine
    lathe = machine.is_lathe
    return {
        "access": AccessView(request),
        "status": machine.status(),
        "panel": PanelState.of(request, machine.axes),
        "axes": machine.axes,
        "rotary_axes": machine.rotary_axes,
        "gud": services.settings.get(),
        "lathe": lathe,
        **({"HORIZONTAL_SOFTKEYS": LATHE_HORIZONTAL_SOFTKEYS} if lathe else {}),
    }


def _owner(template: str, block: str) -> str:
    """The template that defines ``block``: the screen's own, else the layout's default."""
    return template if block in templates.get_template(template).blocks else "base.html"


def render_screen(request: Request, template: str, context: dict | None = None, status_code: int = 200):
    """Full page on a normal GET; on an htmx request the blocks screen + vsoftkeys + hsoftkeys."""
    if not is_htmx(request):
        ctx = _context(request, context)
        return templates.TemplateResponse(request, template, ctx, status_code=status_code)
    ctx = _context(request, context)
    html = "".join(jinja2_fragments.render_block(templates.env, _owner(template, block), block, ctx)
                   for block in SCREEN_BLOCKS)
    title, mode = _screen_chrome(template, ctx)
    return HTMLResponse(title + html + mode, status_code=status_code)


def _screen_chrome(template: str, ctx: dict) -> tuple[str, str]:
    """What comes with the screen on an htmx navigation besides its blocks: the page title (first:
    htmx takes a top-level ``<title>`` only if it is the answer's first one) and the header's mode
    (the mode the screen selects, out of band)."""
    def block(name: str) -> str:
        return jinja2_fragments.render_block(templates.env, _owner(template, name), name, ctx).strip()

    title = f"<title>{block('title')} · {escape(i18n.gettext('Measure-in-JOG HMI'))}</title>"
    status = ctx["status"]
    selected = block("mode")
    shown = status["mode"] if status.get("mode", "JOG") != "JOG" else selected
    mode = (f'<span class="mode" id="hdr-mode" data-selected="{escape(selected)}" hx-swap-oob="true" '
            f'title="{escape(i18n.gettext("operating mode"))}">{escape(shown)}</span>')
    return title, mode


def render_blocks(request: Request, template: str, blocks: list[str], context: dict | None = None,
                  status_code: int = 200, headers: dict | None = None):
    """The named blocks, each from the template that defines it, one after the other."""
    ctx = _context(request, context)
    html = "".join(jinja2_fragments.render_block(templates.env, _owner(template, block), block, ctx)
                   for block in blocks)
    return HTMLResponse(html, status_code=status_code, headers=headers)


def render_block(request: Request, template: str, block: str, context: dict | None = None,
                 status_code: int = 200, headers: dict | None = None):
    return render_blocks(request, template, [block], context, status_code, headers)

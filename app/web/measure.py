"""Measure workpiece / Measure tool softkey menus (spec/jog-measuring.md §2.2) and input-screen slots.

The menu tree is data; a place in it is its slugs, e.g. ``("workpiece", "edge", "set")``, and
``menu_route`` names the route that shows it (the URL is made from the route, never written out).
The input screen of a leaf is the handler registered for its task id by
``app/web/task_screens.py``: ``INPUT_SCREENS["edge.set"] = handler`` with
``handler(request) -> Response`` (a registry, as that module builds on this one's menu tree).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from fastapi import APIRouter, HTTPException, Request, Response

from app.access.deps import denied, measuring_function
from app.errors import WorkflowError
from app.i18n import N_, _
from app.workflow.tasks import task_spec

from .templating import render_screen, softkey, url_path, vkeys

router = APIRouter()


@dataclass(frozen=True)
class Leaf:
    label: str          # softkey text of the manual (a catalogue text: translated where shown)
    slug: str           # URL part
    task: str           # task id of the API (design.md §4)


@dataclass(frozen=True)
class Menu:
    label: str
    slug: str
    items: tuple = field(default_factory=tuple)


def _circles(noun: tuple[str, ...], family: str) -> tuple[Leaf, ...]:
    """The "1 hole" .. "4 holes" (or circular spigots) leaves: slug ``hole1``, task ``hole.1``."""
    return tuple(Leaf(noun[k - 1], f"{family}{k}", f"{family}.{k}") for k in range(1, 5))


HOLES = (N_("1 hole"), N_("2 holes"), N_("3 holes"), N_("4 holes"))
SPIGOTS = (N_("1 circular spigot"), N_("2 circular spigots"), N_("3 circular spigots"), N_("4 circular spigots"))


WORKPIECE_MENU = Menu(N_("Measure workpiece"), "workpiece", (
    Menu(N_("Measure edge"), "edge", (
        Leaf(N_("Set edge"), "set", "edge.set"),
        Leaf(N_("Align edge"), "align", "edge.align"),
        Leaf(N_("Distance 2 edges"), "distance", "edge.distance"),
    )),
    Menu(N_("Measure corner"), "corner", (
        Leaf(N_("Right-angled corner"), "right", "corner.right"),
        Leaf(N_("Any corner"), "any", "corner.any"),
    )),
    Menu(N_("Measure pocket/hole"), "pocket", (
        Leaf(N_("Rectangular pocket"), "rect", "pocket.rect"),
        *_circles(HOLES, "hole"),
    )),
    Menu(N_("Measure spigot"), "spigot", (
        Leaf(N_("Rectangular spigot"), "rect", "spigot.rect"),
        *_circles(SPIGOTS, "spigot"),
    )),
    Leaf(N_("Orient plane"), "plane", "plane.align"),
    Menu(N_("Calibrate probe"), "calibrate", (
        Leaf(N_("Length"), "length", "probe.length"),
        Leaf(N_("Radius"), "radius", "probe.radius"),
    )),
))

TOOL_MENU = Menu(N_("Measure tool"), "tool", (
    Leaf(N_("Length"), "length", "tool.length"),
    Leaf(N_("Diameter"), "diameter", "tool.diameter"),
    Leaf(N_("Calibrate probe"), "calibrate", "toolprobe.calibrate"),
))

# the lathe (turning.md §10.1: the manual has no JOG turning functions): a product extension that
# offers the turning tasks of measuring-math §10.2 through the same interaction, shown when the machine is a lathe
LATHE_MENU = Menu(N_("Measure on the lathe (product extension)"), "lathe", (
    Leaf(N_("Calibrate tool probe"), "toolprobe", "lathe.toolprobe.calibrate"),
    Leaf(N_("Measure tool L1/L2"), "tool", "lathe.tool.measure"),
    Leaf(N_("Measure tool automatic"), "toolauto", "lathe.tool.auto"),
    Leaf(N_("Calibrate probe in groove"), "groove", "lathe.probe.groove"),
    Leaf(N_("Calibrate probe on surface"), "surface", "lathe.probe.surface"),
    Leaf(N_("1-point measurement"), "point", "lathe.point"),
    Leaf(N_("2-point measurement"), "twopoint", "lathe.two_point"),
))

# the guided "tilted workpiece set-up" (app/web/tilted_setup.py): an extra softkey of the menu
TILTED_SETUP_KEY = (N_("Tilted set-up >"), "tilted_setup_screen")

# a place in the menu tree -> its route: (top menu slug, depth below it) -> (route name, slug params)
MENU_ROUTES: dict[tuple[str, int], tuple[str, tuple[str, ...]]] = {
    (WORKPIECE_MENU.slug, 0): ("measure_workpiece_menu", ()),
    (WORKPIECE_MENU.slug, 1): ("measure_workpiece_group", ("group",)),     # a sub-menu or a leaf (plane)
    (WORKPIECE_MENU.slug, 2): ("measure_workpiece_task", ("group", "task")),
    (TOOL_MENU.slug, 0): ("measure_tool_menu", ()),
    (TOOL_MENU.slug, 1): ("measure_tool_task", ("task",)),
    (LATHE_MENU.slug, 0): ("measure_lathe_menu", ()),
    (LATHE_MENU.slug, 1): ("measure_lathe_task", ("task",)),
}

# task id -> handler(request) rendering its input screen (filled in by app/web/task_screens.py)
INPUT_SCREENS: dict[str, Callable[[Request], object]] = {}


def menu_route(slugs: tuple[str, ...]) -> tuple[str, dict[str, str]]:
    """Route name and path params of a place in the menu tree: ``("workpiece", "edge", "set")`` ->
    ``("measure_workpiece_task", {"group": "edge", "task": "set"})``."""
    name, params = MENU_ROUTES[(slugs[0], len(slugs) - 1)]
    return name, dict(zip(params, slugs[1:], strict=True))


def softkeys(request: Request, menu: Menu, slugs: tuple[str, ...], back: tuple[str, str]) -> list[dict]:
    """Vertical softkeys of the menu at ``slugs``: sub-menus get '>', the last key is Back
    (``back`` = (label, route name))."""
    keys = []
    for item in menu.items:
        is_menu = isinstance(item, Menu) or slugs[0] in (TOOL_MENU.slug, LATHE_MENU.slug)
        route, params = menu_route((*slugs, item.slug))
        key = softkey(request, _(item.label) + (" >" if is_menu else ""), route, post=False, **params)
        if isinstance(item, Leaf):          # calibration and tool measuring write: their level
            key["denied"] = _leaf_denied(request, item.task)
        keys.append(key)
    return vkeys(keys, softkey(request, *back))


def _leaf_denied(request: Request, task: str) -> str:

    try:
        function = measuring_function(task_spec(task).category, "measure_only")
    except WorkflowError:              # an unknown task: its screen names the error
        return ""
    return denied(request, function) if function else ""


def _find(menu: Menu, slug: str):
    return next((item for item in menu.items if item.slug == slug), None)


def _menu_screen(request: Request, menu: Menu, path: list[str], slugs: tuple[str, ...], back: tuple[str, str],
                 extra: tuple[str, str] | None = None):
    keys = softkeys(request, menu, slugs, back)
    if extra is not None:                 # an extra softkey (label, route name) in the first free slot
        keys[len(menu.items)] = softkey(request, *extra)
    screen = {TOOL_MENU.slug: "measure_tool", LATHE_MENU.slug: "measure_lathe"}.get(slugs[0], "measure_workpiece")
    return render_screen(request, "measure_menu.html", {
        "screen": screen, "menu": menu, "path": [_(p) for p in path], "vkeys": keys,
        "product_extension": slugs[0] == LATHE_MENU.slug})


def _leaf_screen(request: Request, leaf: Leaf):
    return INPUT_SCREENS[leaf.task](request)


@router.get("/measure/workpiece", name="measure_workpiece_menu")
def workpiece_menu(request: Request):
    return _menu_screen(request, WORKPIECE_MENU, [WORKPIECE_MENU.label], (WORKPIECE_MENU.slug,),
                        (N_("Back"), "jog_screen"), extra=TILTED_SETUP_KEY)


@router.get("/measure/workpiece/{group}", name="measure_workpiece_group")
def workpiece_group(request: Request, group: str):
    item = _find(WORKPIECE_MENU, group)
    if item is None:
        raise HTTPException(404, f"no menu {group!r}")
    if isinstance(item, Leaf):
        return _leaf_screen(request, item)
    return _menu_screen(request, item, [WORKPIECE_MENU.label, item.label], (WORKPIECE_MENU.slug, group),
                        (N_("Back"), "measure_workpiece_menu"))


@router.get("/measure/workpiece/{group}/{task}", name="measure_workpiece_task")
def workpiece_task(request: Request, group: str, task: str):
    menu = _find(WORKPIECE_MENU, group)
    leaf = _find(menu, task) if isinstance(menu, Menu) else None
    if leaf is None:
        raise HTTPException(404, f"no measuring function {group}/{task}")
    return _leaf_screen(request, leaf)


@router.get("/measure/tool", name="measure_tool_menu")
def tool_menu(request: Request):
    return _menu_screen(request, TOOL_MENU, [TOOL_MENU.label], (TOOL_MENU.slug,), (N_("<< Back"), "jog_screen"))


@router.get("/measure/tool/{task}", name="measure_tool_task")
def tool_task(request: Request, task: str):
    leaf = _find(TOOL_MENU, task)
    if leaf is None:
        raise HTTPException(404, f"no tool measuring function {task!r}")
    return _leaf_screen(request, leaf)


@router.get("/measure/lathe", name="measure_lathe_menu")
def lathe_menu(request: Request):
    return _menu_screen(request, LATHE_MENU, [LATHE_MENU.label], (LATHE_MENU.slug,), (N_("<< Back"), "jog_screen"))


@router.get("/measure/lathe/{task}", name="measure_lathe_task")
def lathe_task(request: Request, task: str):
    leaf = _find(LATHE_MENU, task)
    if leaf is None:
        raise HTTPException(404, f"no lathe measuring function {task!r}")
    return _leaf_screen(request, leaf)


def menu_screen(request: Request, slugs: tuple[str, ...]):
    """The menu at ``slugs`` as the answer to another request (Back from an input screen), with
    ``HX-Push-Url`` set to the menu's URL."""
    route, params = menu_route(slugs)
    handlers: dict[str, Callable[..., Response]] = {
        "measure_workpiece_menu": workpiece_menu, "measure_workpiece_group": workpiece_group,
        "measure_tool_menu": tool_menu, "measure_lathe_menu": lathe_menu}
    handler = handlers[route]
    response = handler(request, **params)
    response.headers["HX-Push-Url"] = url_path(request, route, **params)
    return response

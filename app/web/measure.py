"""Measure workpiece / Measure tool softkey menus (spec/jog-measuring.md §2.2) and input-screen slots.

The menu tree is data. The input screen of a leaf is the handler registered for its task id by
``app/web/task_screens.py``: ``INPUT_SCREENS["edge.set"] = handler`` with
``handler(request) -> Response`` (a registry, as that module builds on this one's menu tree).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from fastapi import APIRouter, HTTPException, Request

from .templating import render_screen, vkeys

router = APIRouter()


@dataclass(frozen=True)
class Leaf:
    label: str          # softkey text of the manual
    slug: str           # URL part
    task: str           # task id of the API (design.md §4)


@dataclass(frozen=True)
class Menu:
    label: str
    slug: str
    items: tuple = field(default_factory=tuple)


def _circles(noun: str, family: str) -> tuple[Leaf, ...]:
    """The "1 hole" .. "4 holes" (or circular spigots) leaves: slug ``hole1``, task ``hole.1``."""
    return tuple(Leaf(f"{k} {noun}{'s' if k > 1 else ''}", f"{family}{k}", f"{family}.{k}")
                 for k in range(1, 5))


WORKPIECE_MENU = Menu("Measure workpiece", "workpiece", (
    Menu("Measure edge", "edge", (
        Leaf("Set edge", "set", "edge.set"),
        Leaf("Align edge", "align", "edge.align"),
        Leaf("Distance 2 edges", "distance", "edge.distance"),
    )),
    Menu("Measure corner", "corner", (
        Leaf("Right-angled corner", "right", "corner.right"),
        Leaf("Any corner", "any", "corner.any"),
    )),
    Menu("Measure pocket/hole", "pocket", (
        Leaf("Rectangular pocket", "rect", "pocket.rect"),
        *_circles("hole", "hole"),
    )),
    Menu("Measure spigot", "spigot", (
        Leaf("Rectangular spigot", "rect", "spigot.rect"),
        *_circles("circular spigot", "spigot"),
    )),
    Leaf("Orient plane", "plane", "plane.align"),
    Menu("Calibrate probe", "calibrate", (
        Leaf("Length", "length", "probe.length"),
        Leaf("Radius", "radius", "probe.radius"),
    )),
))

TOOL_MENU = Menu("Measure tool", "tool", (
    Leaf("Length", "length", "tool.length"),
    Leaf("Diameter", "diameter", "tool.diameter"),
    Leaf("Calibrate probe", "calibrate", "toolprobe.calibrate"),
))

# the guided "tilted workpiece set-up" (app/web/tilted_setup.py): an extra softkey of the menu
TILTED_SETUP_KEY = {"label": "Tilted set-up >", "href": "/measure/workpiece/tilted-setup"}

# task id -> handler(request) rendering its input screen (filled in by app/web/task_screens.py)
INPUT_SCREENS: dict[str, Callable[[Request], object]] = {}


def softkeys(menu: Menu, base: str, back: tuple[str, str]) -> list[dict]:
    """Vertical softkeys of a menu: sub-menus get '>', the last key is Back."""
    keys = []
    for item in menu.items:
        is_menu = isinstance(item, Menu) or base.startswith("/measure/tool")
        keys.append({"label": item.label + (" >" if is_menu else ""), "href": f"{base}/{item.slug}"})
    return vkeys(keys, {"label": back[0], "href": back[1]})


def _find(menu: Menu, slug: str):
    return next((item for item in menu.items if item.slug == slug), None)


def _menu_screen(request: Request, menu: Menu, path: list[str], base: str, back: tuple[str, str],
                 extra: dict | None = None):
    keys = softkeys(menu, base, back)
    if extra is not None:                 # an extra softkey in the first free slot (before Back)
        keys[len(menu.items)] = extra
    return render_screen(request, "measure_menu.html", {
        "screen": "measure_tool" if base.startswith("/measure/tool") else "measure_workpiece",
        "menu": menu, "path": path, "vkeys": keys})


def _leaf_screen(request: Request, leaf: Leaf):
    return INPUT_SCREENS[leaf.task](request)


@router.get("/measure/workpiece")
def workpiece_menu(request: Request):
    return _menu_screen(request, WORKPIECE_MENU, [WORKPIECE_MENU.label], "/measure/workpiece",
                        ("Back", "/jog"), extra=TILTED_SETUP_KEY)


@router.get("/measure/workpiece/{group}")
def workpiece_group(request: Request, group: str):
    item = _find(WORKPIECE_MENU, group)
    if item is None:
        raise HTTPException(404, f"no menu {group!r}")
    if isinstance(item, Leaf):
        return _leaf_screen(request, item)
    return _menu_screen(request, item, [WORKPIECE_MENU.label, item.label], f"/measure/workpiece/{group}",
                        ("Back", "/measure/workpiece"))


@router.get("/measure/workpiece/{group}/{task}")
def workpiece_task(request: Request, group: str, task: str):
    menu = _find(WORKPIECE_MENU, group)
    leaf = _find(menu, task) if isinstance(menu, Menu) else None
    if leaf is None:
        raise HTTPException(404, f"no measuring function {group}/{task}")
    return _leaf_screen(request, leaf)


@router.get("/measure/tool")
def tool_menu(request: Request):
    return _menu_screen(request, TOOL_MENU, [TOOL_MENU.label], "/measure/tool", ("<< Back", "/jog"))


@router.get("/measure/tool/{task}")
def tool_task(request: Request, task: str):
    leaf = _find(TOOL_MENU, task)
    if leaf is None:
        raise HTTPException(404, f"no tool measuring function {task!r}")
    return _leaf_screen(request, leaf)

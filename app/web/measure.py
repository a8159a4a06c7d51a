"""Measure workpiece / Measure tool softkey menus (spec/jog-measuring.md §2.2) and input-screen slots.

The menu tree is data. An input screen is plugged in by registering a handler for its task id:
``INPUT_SCREENS["edge.set"] = handler`` with ``handler(request) -> Response``; until then the
route shows a placeholder naming the task.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from fastapi import APIRouter, HTTPException, Request

from .templating import render_screen

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
        Leaf("1 hole", "hole1", "hole.1"),
        Leaf("2 holes", "hole2", "hole.2"),
        Leaf("3 holes", "hole3", "hole.3"),
        Leaf("4 holes", "hole4", "hole.4"),
    )),
    Menu("Measure spigot", "spigot", (
        Leaf("Rectangular spigot", "rect", "spigot.rect"),
        Leaf("1 circular spigot", "spigot1", "spigot.1"),
        Leaf("2 circular spigots", "spigot2", "spigot.2"),
        Leaf("3 circular spigots", "spigot3", "spigot.3"),
        Leaf("4 circular spigots", "spigot4", "spigot.4"),
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

# task id -> handler(request) rendering its input screen (filled in by the measuring workflow)
INPUT_SCREENS: dict[str, Callable[[Request], object]] = {}


def softkeys(menu: Menu, base: str, back: tuple[str, str]) -> list[dict]:
    """Vertical softkeys of a menu: sub-menus get '>', the last key is Back."""
    keys = []
    for item in menu.items:
        is_menu = isinstance(item, Menu) or base.startswith("/measure/tool")
        keys.append({"label": item.label + (" >" if is_menu else ""), "href": f"{base}/{item.slug}"})
    keys += [None] * (7 - len(keys))
    keys.append({"label": back[0], "href": back[1]})
    return keys


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


def _leaf_screen(request: Request, leaf: Leaf, path: list[str], back: tuple[str, str]):
    handler = INPUT_SCREENS.get(leaf.task)
    if handler is not None:
        return handler(request)
    keys: list = [None] * 7 + [{"label": back[0], "href": back[1]}]
    return render_screen(request, "measure_placeholder.html", {
        "screen": "measure_tool" if leaf.task.startswith(("tool.", "toolprobe.")) else "measure_workpiece",
        "leaf": leaf, "path": path, "vkeys": keys})


@router.get("/measure/workpiece")
def workpiece_menu(request: Request):
    return _menu_screen(request, WORKPIECE_MENU, [WORKPIECE_MENU.label], "/measure/workpiece",
                        ("Back", "/jog"), extra=TILTED_SETUP_KEY)


@router.get("/measure/workpiece/{group}")
def workpiece_group(request: Request, group: str):
    item = _find(WORKPIECE_MENU, group)
    if item is None:
        raise HTTPException(404, f"no menu {group!r}")
    path = [WORKPIECE_MENU.label, item.label]
    if isinstance(item, Leaf):
        return _leaf_screen(request, item, path, ("Back", "/measure/workpiece"))
    return _menu_screen(request, item, path, f"/measure/workpiece/{group}", ("Back", "/measure/workpiece"))


@router.get("/measure/workpiece/{group}/{task}")
def workpiece_task(request: Request, group: str, task: str):
    menu = _find(WORKPIECE_MENU, group)
    leaf = _find(menu, task) if isinstance(menu, Menu) else None
    if leaf is None:
        raise HTTPException(404, f"no measuring function {group}/{task}")
    return _leaf_screen(request, leaf, [WORKPIECE_MENU.label, menu.label, leaf.label],
                        ("Back", f"/measure/workpiece/{group}"))


@router.get("/measure/tool")
def tool_menu(request: Request):
    return _menu_screen(request, TOOL_MENU, [TOOL_MENU.label], "/measure/tool", ("<< Back", "/jog"))


@router.get("/measure/tool/{task}")
def tool_task(request: Request, task: str):
    leaf = _find(TOOL_MENU, task)
    if leaf is None:
        raise HTTPException(404, f"no tool measuring function {task!r}")
    return _leaf_screen(request, leaf, [TOOL_MENU.label, leaf.label], ("<< Back", "/measure/tool"))

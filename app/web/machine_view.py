"""Machine view: the true scene (what the operator sees through the door) in 3D (static/view3d.js,
data from ``scene3d``) and in top and front view with a scale bar, live. In trainer mode (setting
``trainer_hide_part``) the part is left out, the probe is where the NC puts it, and the trainer
panel shows the simulator's set-up error (app/services/trainer.py). A lathe in one view, X up and
Z right (app/web/lathe_view.py), beside its 3D panel (static/view3d_lathe.js, ``scene3d.build_lathe``)."""

from __future__ import annotations

import math

from fastapi import APIRouter, Request
from fastapi.responses import JSONResponse
from markupsafe import Markup

from app.deps import MachineDep
from app.errors import HmiError
from app.services import trainer

from . import scene3d
from .lathe_view import lathe_svg
from .templating import render_block, render_screen, url_path

router = APIRouter()

# view name -> (horizontal axis index, vertical axis index) of MCS; SVG y grows downwards
VIEWS = {"top": (0, 1), "front": (0, 2)}
MARGIN = 20.0


def _hull(points: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """Convex hull (monotone chain) of 2D points, counter-clockwise."""
    pts = sorted(set(points))
    if len(pts) <= 2:
        return pts

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: list[tuple[float, float]] = []
    upper: list[tuple[float, float]] = []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return lower[:-1] + upper[:-1]


def _svg_points(points: list[tuple[float, float]]) -> str:
    return " ".join(f"{u:.2f},{-v:.2f}" for u, v in points)


def build_views(scene: dict, limits: dict, nose_z: float) -> dict:
    """SVG-ready shapes per view (coordinates in mm, y negated for SVG)."""
    all_points = []
    if scene.get("block"):
        all_points += scene["block"]["corners"]
    for c in scene.get("circles", []):
        all_points.append(c["center"])
        all_points.append([c["center"][0], c["center"][1], c["center"][2] - c["height"]])
    z_values = [p[2] for p in all_points] or [limits["Z"][0]]
    bounds = {
        "top": (limits["X"][0], limits["X"][1], limits["Y"][0], limits["Y"][1]),
        "front": (limits["X"][0], limits["X"][1], min(z_values) - 2 * MARGIN,
                  max(limits["Z"][1], max(z_values)) + MARGIN),
    }
    views = {}
    for name, (iu, iv) in VIEWS.items():
        u0, u1, v0, v1 = bounds[name]
        shapes = []
        if scene.get("block"):
            hull = _hull([(p[iu], p[iv]) for p in scene["block"]["corners"]])
            shapes.append({"kind": "block", "tag": "polygon", "points": _svg_points(hull)})
        for rect in scene.get("rects", []):
            pts = [(p[iu], p[iv]) for p in rect["corners"]]
            shapes.append({"kind": rect["kind"], "tag": "polygon", "points": _svg_points(_hull(pts) or pts)})
        for c in scene.get("circles", []):
            r = c["diameter"] / 2.0
            cu, cv = c["center"][iu], c["center"][iv]
            if name == "top":
                shapes.append({"kind": c["kind"], "tag": "circle", "cx": cu, "cy": -cv, "r": r})
            else:   # a vertical cylinder from its top face down by its height
                shapes.append({"kind": c["kind"], "tag": "rect", "x": cu - r, "y": -cv, "w": 2 * r,
                               "h": c["height"]})
        order = {"ring_outer": 0, "block": 1, "tool_probe": 1, "boss": 2, "spigot": 2, "pocket": 3,
                 "hole": 3, "ring_bore": 3}
        shapes.sort(key=lambda s: order.get(s["kind"], 2))
        probe = scene.get("probe") or {}
        tip = probe.get("tip")
        marker = None
        if tip is not None:
            marker = {"u": tip[iu], "v": -tip[iv], "r": max(probe.get("diameter", 0.0) / 2.0, 0.5),
                      "is_probe": probe.get("is_probe", False),
                      "nose_v": -nose_z if name == "front" else None}
        views[name] = {"viewbox": f"{u0:.1f} {-v1:.1f} {u1 - u0:.1f} {v1 - v0:.1f}", "shapes": shapes,
                       "probe": marker, "u_axis": "X", "v_axis": "Y" if name == "top" else "Z",
                       "u0": u0, "v1": v1, "scale": scale_bar(u0, u1, -v1, v1 - v0)}
    return views


def nice_length(span: float) -> float:
    """The 1-2-5 length nearest below a fifth of ``span`` (mm): the scale bar's length."""
    target = max(span / 5.0, 1e-6)
    base = 10.0 ** math.floor(math.log10(target))
    return max(m * base for m in (1.0, 2.0, 5.0) if m * base <= target)


def scale_bar(x0: float, x1: float, y0: float, height: float) -> dict:
    """A bar of ``nice_length`` at the view's bottom left (SVG user units = mm)."""
    width = x1 - x0
    length = nice_length(width)
    pad = 0.03 * width
    return {"x1": x0 + pad, "x2": x0 + pad + length, "y": y0 + height - pad, "tick": 0.012 * width,
            "label": f"{length:g} mm", "font": 0.028 * width}


def _context(request: Request) -> dict:
    services = request.app.state.services
    scene = trainer.visible_scene(services)
    if scene.get("kind") == "lathe":                       # one view, X up and Z right (turning.md §0.1)
        return {"lathe_svg": Markup(lathe_svg(scene, services.machine.limits())),
                "tip": scene.get("probe", {}).get("tip"), "lathe": True, "hidden": scene["hidden"],
                "spindle_angle": scene.get("spindle_angle"), "views": None,
                "lathe_part": [{"type": p["type"], "diameter": p["diameter"], "length": abs(p["z"][1] - p["z"][0])}
                               for p in scene.get("part") or []]}
    status = services.machine.status()
    return {"views": build_views(scene, services.machine.limits(), status["mcs"]["Z"]),
            "tip": scene.get("probe", {}).get("tip"), "hidden": scene["hidden"]}


def _trainer_context(request: Request, offset: str | None) -> dict:
    services = request.app.state.services
    names = [n for n in services.offsets.names() if n.startswith("G")]
    chosen = (offset or services.machine.active_offset or "").upper()
    ctx = {"trainer_offsets": names, "trainer_offset": chosen if chosen in names else None,
           "trainer_error": None, "trainer_message": ""}
    if ctx["trainer_offset"] is None:
        ctx["trainer_message"] = "Choose the zero offset you set up."
        return ctx
    try:
        ctx["trainer_error"] = trainer.setup_error(services, chosen)
    except HmiError as exc:
        ctx["trainer_message"] = exc.message
    return ctx


@router.get("/machine-view", name="machine_view_screen")
def machine_view_screen(request: Request, machine: MachineDep):
    ctx = {"screen": "machine_view", **_context(request)}
    if ctx["hidden"]:
        ctx.update(_trainer_context(request, None))
    ctx["events_url"] = _events_url(request)
    return render_screen(request, "machine_view.html", ctx)


@router.get("/machine-view/views", name="machine_view_views")
def machine_view_live(request: Request, machine: MachineDep):
    return render_block(request, "machine_view.html", "views", _context(request))


@router.get("/machine-view/scene", name="machine_view_scene")
def machine_view_scene(request: Request, machine: MachineDep):
    """The 3D view's data (``scene3d.build``), polled by static/view3d.js."""
    return JSONResponse(scene3d.build(request.app.state.services), headers={"Cache-Control": "no-store"})


@router.get("/machine-view/trainer", name="machine_view_trainer")
def machine_view_trainer(request: Request, machine: MachineDep, offset: str | None = None):
    """The trainer panel: the set-up error of ``offset`` (default the active WO) against the hidden part."""
    return render_block(request, "machine_view.html", "trainer", _trainer_context(request, offset))


EVENTS_ROUTE = "api_events"     # issue 17 item 3 (another branch): the 3D view follows it when present


def _events_url(request: Request) -> str:
    """The server-sent events stream when this build has one, else "" (the 3D view then polls)."""
    if any(getattr(r, "name", None) == EVENTS_ROUTE for r in request.app.routes):
        return url_path(request, EVENTS_ROUTE)
    return ""

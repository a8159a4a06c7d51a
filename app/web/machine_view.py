"""Machine view: the true scene (what the operator sees through the door) in top and front view, live."""

from __future__ import annotations

from fastapi import APIRouter, Request

from app.deps import MachineDep

from .templating import render_block, render_screen

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

    lower, upper = [], []
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
                       "u0": u0, "v1": v1}
    return views


def _context(machine: MachineDep) -> dict:
    scene = machine.scene_geometry()
    status = machine.status()
    return {"views": build_views(scene, machine.scenario.limits(), status["mcs"]["Z"]),
            "tip": scene.get("probe", {}).get("tip")}


@router.get("/machine-view")
def machine_view_screen(request: Request, machine: MachineDep):
    return render_screen(request, "machine_view.html", {"screen": "machine_view", **_context(machine)})


@router.get("/machine-view/views")
def machine_view_live(request: Request, machine: MachineDep):
    return render_block(request, "machine_view.html", "views", _context(machine))

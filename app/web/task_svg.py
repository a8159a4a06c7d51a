"""Live SVG of a measuring screen: planned probing path, stored P1..Pn, probe and result.

Top view (plane axes) always; a side view (1st axis / infeed) for tasks that probe along or
lower on the infeed axis. Everything is drawn in the measuring WCS; the SVG y axis points down,
so view coordinates are flipped there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from markupsafe import Markup, escape

from app.i18n import _
from app.workflow.tasks import task_spec
from engine.planes import Plane
from engine.tasks import Family
from engine.types import MoveStep, ProbeStep

from .templating import fixed

AXES = ("X", "Y", "Z")


@dataclass
class View:
    name: str            # "top" | "side"
    u: str               # horizontal axis name
    v: str               # vertical axis name
    shapes: list[str] = field(default_factory=list)
    points: list[tuple[float, float]] = field(default_factory=list)   # for the bounding box
    caption: str = ""                                                  # result text beside the title
    refused: str = ""          # the start guard's refused step ("P1 DZ"), marked in the picture

    def uv(self, p: dict | np.ndarray) -> tuple[float, float]:
        if isinstance(p, dict):
            return float(p.get(self.u, 0.0)), float(p.get(self.v, 0.0))
        return float(p[AXES.index(self.u)]), float(p[AXES.index(self.v)])

    def _keep(self, *pts):
        self.points.extend(pts)

    def line(self, a, b, cls: str, keep: bool = True):
        (u1, v1), (u2, v2) = a, b
        if keep:
            self._keep(a, b)
        self.shapes.append(f'<line class="{cls}" x1="{u1:.3f}" y1="{-v1:.3f}" x2="{u2:.3f}" y2="{-v2:.3f}"/>')

    def circle(self, c, r: float, cls: str, keep: bool = True):
        if keep:
            self._keep((c[0] - r, c[1] - r), (c[0] + r, c[1] + r))
        self.shapes.append(f'<circle class="{cls}" cx="{c[0]:.3f}" cy="{-c[1]:.3f}" r="{max(r, 0.01):.3f}"/>')

    def rect(self, c, w: float, h: float, cls: str):
        self._keep((c[0] - w / 2, c[1] - h / 2), (c[0] + w / 2, c[1] + h / 2))
        self.shapes.append(f'<rect class="{cls}" x="{c[0] - w / 2:.3f}" y="{-c[1] - h / 2:.3f}" '
                           f'width="{w:.3f}" height="{h:.3f}"/>')

    def text(self, p, label: str, cls: str = "label"):
        self.shapes.append(f'<text class="{cls}" x="{p[0]:.3f}" y="{-p[1]:.3f}">{escape(label)}</text>')

    def infinite_line(self, p, angle_deg: float, cls: str, half: float):
        d = (math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg)))
        a = (p[0] - half * d[0], p[1] - half * d[1])
        b = (p[0] + half * d[0], p[1] + half * d[1])
        self.line(a, b, cls, keep=False)

    def svg(self, title: str) -> Markup:
        if not self.points:
            self.points = [(-10.0, -10.0), (10.0, 10.0)]
        us = [p[0] for p in self.points]
        vs = [p[1] for p in self.points]
        span = max(max(us) - min(us), max(vs) - min(vs), 60.0)
        pad = 0.12 * span
        x0, x1 = min(us) - pad, max(us) + pad
        y0, y1 = -max(vs) - pad, -min(vs) + pad
        # stroke and text sizes follow the zoom so the picture reads the same at any scale
        scale = max(x1 - x0, y1 - y0) / 300.0
        style = f"--s:{scale:.4f}"
        body = "".join(self.shapes)
        refused = f' data-guard-refused="{escape(self.refused)}"' if self.refused else ""
        return Markup(
            f'<figure class="task-view"><figcaption>{escape(title)}'
            f'{" · " if self.caption else ""}<b class="result">{escape(self.caption)}</b></figcaption>'
            f'<svg id="task-svg-{self.name}" class="task-svg"{refused} viewBox="{x0:.3f} {y0:.3f} {x1 - x0:.3f} {y1 - y0:.3f}" '
            f'preserveAspectRatio="xMidYMid meet" role="img" aria-label="{escape(title)}" style="{style}" '
            f'font-size="{14 * scale:.3f}" stroke-width="{1.2 * scale:.4f}">'
            f'<g class="axes-cross">{self._cross(x0, x1, y0, y1)}</g>{body}</svg></figure>')

    @staticmethod
    def _cross(x0, x1, y0, y1) -> str:
        """The WCS zero lines, when they are in the picture."""
        out = ""
        if x0 < 0 < x1:
            out += f'<line class="zero" x1="0" y1="{y0:.3f}" x2="0" y2="{y1:.3f}"/>'
        if y0 < 0 < y1:
            out += f'<line class="zero" x1="{x0:.3f}" y1="0" x2="{x1:.3f}" y2="0"/>'
        return out


def needs_side_view(task: str, params: dict | None) -> bool:
    family = task_spec(task).family
    if task in ("plane.align", "probe.length") or family == Family.SPIGOT:
        return True
    return family == Family.EDGE and (params or {}).get("axis") == "Z"


def draw(task: str, plane: Plane, *, params: dict | None = None, start=None, steps=(), points=(),
         result: dict | None = None, ball_radius: float = 2.0, refused=None) -> list[Markup]:
    """SVG figures for the screen. ``points``: stored-point dicts (``PointSlot.to_api``);
    ``refused``: the start guard's refused segment (``engine.guard.Segment``, plan coordinates),
    drawn over the path with where it would hit (issue 24 §1)."""
    views = [View("top", plane.first, plane.second)]
    if needs_side_view(task, params) or _steps_leave_plane(steps, plane):
        views.append(View("side", plane.first, plane.infeed))
    for view in views:
        if result:
            # the result lives in the WCS of the measurement; the probe may already be in a new one
            _result_points(view, result)
            _result(view, task, result, plane)
            continue
        _path(view, start, steps)
        if refused is not None:
            _refused(view, refused, ball_radius)
        _stored(view, points)
        if start is not None:
            view.circle(view.uv(start), ball_radius, "ball")
    titles = {"top": _("Top view (%(a)s/%(b)s)", a=plane.first, b=plane.second),
              "side": _("Side view (%(a)s/%(b)s)", a=plane.first, b=plane.infeed)}
    return [v.svg(titles[v.name]) for v in views]


def _steps_leave_plane(steps, plane: Plane) -> bool:
    """A side view helps when the path moves along the infeed axis (spigots, Z edges, planes)."""
    unit = plane.infeed_unit
    for step in steps:
        if isinstance(step, ProbeStep) and abs(float(np.asarray(step.direction) @ unit)) > 0.5:
            return True
    return False


def _path(view: View, start, steps) -> None:
    if start is None:
        return
    pos = np.asarray(start, dtype=float)
    for step in steps:
        if isinstance(step, MoveStep):
            target = np.asarray(step.target, dtype=float)
            view.line(view.uv(pos), view.uv(target), "move")
            pos = target
        elif isinstance(step, ProbeStep):
            d = np.asarray(step.direction, dtype=float)
            travel = step.expected if step.expected is not None else step.distance / 2.0
            end = pos + travel * d
            view.line(view.uv(pos), view.uv(pos + step.distance * d), "probe-path", keep=False)
            view.line(view.uv(pos), view.uv(end), "probe-move")
            view.circle(view.uv(end), 0.6, "contact")
            pos = end


def _refused(view: View, seg, ball_radius: float) -> None:
    """The segment the start guard refuses: from its start to where the ball would touch (or its
    end), the ball there, and its step's name."""
    hit = seg.where if seg.where is not None else seg.end
    a, b = view.uv(np.asarray(seg.start, dtype=float)), view.uv(np.asarray(hit, dtype=float))
    view.line(a, b, "guard-refused")
    view.circle(b, ball_radius, "guard-hit")
    view.text((b[0] + ball_radius + 1, b[1] + ball_radius + 1), f"✕ {seg.label}", "label guard-label")
    view.refused = seg.label or str(seg.index)


def _stored(view: View, points) -> None:
    for point in points:
        value = point.get("value") if point.get("stored") else None
        if not value:
            continue
        label = f"P{point['n']}"
        if "surface" in value:
            p = view.uv(value["surface"])
            view.circle(p, 1.2, "stored")
            view.text((p[0] + 2, p[1] + 2), label)
        elif "center" in value:
            c = view.uv(value["center"])
            if view.name == "top" and "diameter" in value:
                view.circle(c, value["diameter"] / 2.0, "stored-circle")
            elif view.name == "top" and "length" in value:
                view.rect(c, value["length"], value["width"], "stored-circle")
            view.circle(c, 1.0, "stored")
            view.text((c[0] + 2, c[1] + 2), label)


def _result_points(view: View, r: dict) -> None:
    """The touches or centres the result was computed from, as P1..Pn."""
    for n, p in enumerate(r.get("points") or [], start=1):
        if isinstance(p, dict):
            q = view.uv(p)
            view.circle(q, 1.0, "stored")
            view.text((q[0] + 2, q[1] + 2), f"P{n}")
    for key in ("p1", "p2"):
        if isinstance(r.get(key), dict):
            q = view.uv(r[key])
            view.circle(q, 1.0, "stored")
            view.text((q[0] + 2, q[1] + 2), key.upper())


def _result(view: View, task: str, r: dict, plane: Plane) -> None:
    """The result drawn over the set-up: position lines, then the one feature figure (corner,
    aligned edge, edge distance or centred shape), the two points, the plane's trace."""
    pts = [view.uv(p) for p in r.get("points") or [] if isinstance(p, dict)]
    position = r.get("position")
    if isinstance(position, dict):
        for axis, value in position.items():
            _axis_line(view, axis, value, "result-line")
    if "corner" in r and view.name == "top":
        _corner(view, r)
    elif task == "edge.align" and len(pts) == 2 and view.name == "top":
        view.line(_extend(pts[0], pts[1], -0.5), _extend(pts[0], pts[1], 1.5), "result-line")
    elif task == "edge.distance" and len(pts) == 2:
        _edge_distance(view, r)
    elif "center" in r and view.name == "top":
        _centred_shape(view, r, bool(pts))
    if "p1" in r and "p2" in r and view.name == "top":
        view.line(view.uv(r["p1"]), view.uv(r["p2"]), "result-line")
    if "alpha" in r and "beta" in r:
        _plane_trace(view, r)


HALF = 1000.0          # half length of a line drawn across the whole view (mm)


def _axis_line(view: View, axis, value: float, cls: str) -> None:
    """A line across the view where ``axis`` has ``value`` (nothing when the view does not show it)."""
    if axis == view.u:
        view.line((value, -HALF), (value, HALF), cls, keep=False)
    elif axis == view.v:
        view.line((-HALF, value), (HALF, value), cls, keep=False)


def _corner(view: View, r: dict) -> None:
    p0 = view.uv(r["corner"])
    angle = float(r.get("angle", 0.0))
    angle2 = float(r["angle_2"]) if "angle_2" in r else angle + 90.0
    view.infinite_line(p0, angle, "result-line", HALF)
    view.infinite_line(p0, angle2, "result-line", HALF)
    view.circle(p0, 1.5, "result-point")
    view.text((p0[0] + 2, p0[1] - 5), "P0", "label result")


def _edge_distance(view: View, r: dict) -> None:
    axis = r.get("axis")
    centre = (r.get("center") or {}).get(axis)
    for value in [p[axis] for p in r["points"]] + ([centre] if centre is not None else []):
        _axis_line(view, axis, value, "result-line" if value != centre else "result-centre")


def _centred_shape(view: View, r: dict, has_points: bool) -> None:
    c = view.uv(r["center"])
    if "diameter" in r:
        view.circle(c, float(r["diameter"]) / 2.0, "result-shape")
    elif "length" in r and "width" in r and isinstance(r["length"], float):
        view.rect(c, float(r["length"]), float(r["width"]), "result-shape")
    if "angle" in r and has_points:
        view.infinite_line(c, float(r["angle"]), "result-centre", HALF)
    view.circle(c, 1.5, "result-point")
    view.text((c[0] + 2, c[1] - 5), "P0", "label result")


def _plane_trace(view: View, r: dict) -> None:
    pts3 = [p for p in r.get("points") or [] if isinstance(p, dict)]
    if view.name == "side" and len(pts3) >= 2:
        # trace of the measured plane: a line through the outermost touches along the 1st axis
        ends = sorted((view.uv(p) for p in pts3), key=lambda q: q[0])
        view.line(_extend(ends[0], ends[-1], -0.1), _extend(ends[0], ends[-1], 1.1), "result-line")
    view.caption = f"α {fixed(r['alpha'], 4)}°  β {fixed(r['beta'], 4)}°"


def _extend(a, b, t: float) -> tuple[float, float]:
    return a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])

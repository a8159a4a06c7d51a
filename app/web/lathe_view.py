"""The lathe drawn as the manual's figures show it: X up, Z right (turning.md §0.1), MCS, mm.

One SVG of the true set-up (the machine view, what the operator sees through the door): the
chuck, the clamped part in section (eccentric by e_X at the spindle's angle; bores cut out),
the reference grooves and the tool probe (mirrored below the turning centre where they are
bodies of revolution), the turret reference F, the active tool (nose circle, tip) or the probe
ball, and, on the task screens, the planned path of the NC reference point. SVG y = −X.
"""

from __future__ import annotations

from html import escape

MARGIN = 15.0


def _f(v: float) -> str:
    return f"{float(v):.3f}"


def _rect(z0: float, z1: float, x0: float, x1: float, cls: str, extra: str = "") -> str:
    z0, z1 = min(z0, z1), max(z0, z1)
    x0, x1 = min(x0, x1), max(x0, x1)
    return (f'<rect class="{cls}" x="{_f(z0)}" y="{_f(-x1)}" width="{_f(z1 - z0)}" height="{_f(x1 - x0)}"'
            f'{extra}/>')


def _bounds(scene: dict, limits: dict, path: list | None, focus) -> tuple[float, float, float, float]:
    zs, xs = [], []
    chuck = scene.get("chuck_face_z")
    if "part" in focus:
        for item in scene.get("part") or []:
            zs += item["z"]
            xs += [item["axis_x"] + item["diameter"] / 2, item["axis_x"] - item["diameter"] / 2]
    if "groove" in focus:
        for groove in scene.get("grooves") or []:
            for _r0, r1, z0, z1 in groove["rings"]:
                zs += [z0, z1]
                xs += [r1, -r1]
    tp = scene.get("tool_probe")
    if tp and "tool_probe" in focus:
        zs += [tp["Z-"], tp["Z+"]]
        xs += [tp["X-"], tp["X+"]]
    probe = scene.get("probe") or {}
    if probe.get("tip"):                    # the turret reference F may lie far off: not in the bounds
        zs.append(probe["tip"][2])
        xs.append(probe["tip"][0])
    for p in path or []:
        zs.append(p[2])
        xs.append(p[0])
    if chuck is not None and "part" in focus:
        zs.append(chuck - 40.0)
    if not zs:
        zs, xs = list(limits.get("Z", (0, 100))), list(limits.get("X", (0, 100)))
    z0, z1 = min(zs) - MARGIN, max(zs) + MARGIN
    x0, x1 = min(min(xs), -max(abs(x) for x in xs) * 0.25) - MARGIN, max(xs) + MARGIN
    return z0, z1, x0, x1


ALL = ("part", "groove", "tool_probe")


def _solids(scene: dict, z0: float) -> list[str]:
    """The chuck, the part (cylinders, then bores), the reference grooves and the tool probe."""
    parts = []
    chuck = scene.get("chuck_face_z")
    part = scene.get("part") or []
    r_max = max([p["diameter"] / 2 + abs(p["axis_x"]) for p in part] or [20.0])
    if chuck is not None:
        parts.append(_rect(z0, chuck, -r_max - 25.0, r_max + 25.0, "chuck", ' data-kind="chuck"'))
    for kind, cls, data in (("cylinder", "block", "part"), ("bore", "hole", "bore")):
        for item in part:
            if item["type"] == kind:
                r, e = item["diameter"] / 2, item["axis_x"]
                parts.append(_rect(item["z"][0], item["z"][1], e - r, e + r, cls, f' data-kind="{data}"'))
    for groove in scene.get("grooves") or []:
        for r0, r1, gz0, gz1 in groove["rings"]:
            for sign in (1, -1):
                parts.append(_rect(gz0, gz1, sign * r0, sign * r1, "ring_outer",
                                   f' data-kind="groove" data-number="{groove["number"]}"'))
    tp = scene.get("tool_probe")
    if tp:
        parts.append(_rect(tp["Z+"], tp["Z-"], tp["X+"], tp["X-"], "tool_probe", ' data-kind="tool_probe"'))
    return parts


def _tool(probe: dict, stroke: float) -> list[str]:
    """The holder from F to the tip, F, the probe ball or the tool nose (and a tool's tip)."""
    parts = []
    f = probe.get("f")
    tip = probe.get("tip")
    if f and tip:
        parts.append(f'<line class="holder" x1="{_f(tip[2])}" y1="{_f(-tip[0])}" x2="{_f(f[2])}" '
                     f'y2="{_f(-f[0])}"/>')
        parts.append(f'<circle class="f-point" cx="{_f(f[2])}" cy="{_f(-f[0])}" r="{_f(stroke * 4)}" '
                     'data-kind="F"/>')
    if tip:
        r = max(float(probe.get("diameter") or 0.0) / 2.0, stroke * 2)
        centre = probe.get("nose") or tip
        kind = "probe" if probe.get("is_probe") else "tool"
        parts.append(f'<circle class="probe" cx="{_f(centre[2])}" cy="{_f(-centre[0])}" r="{_f(r)}" '
                     f'data-kind="{kind}"/>')
        if not probe.get("is_probe"):
            parts.append(f'<circle class="tip" cx="{_f(tip[2])}" cy="{_f(-tip[0])}" r="{_f(stroke * 2)}" '
                         'data-kind="tip"/>')
    return parts


def lathe_svg(scene: dict, limits: dict, *, path: list | None = None, svg_id: str = "view-lathe",
              caption: str = "Lathe (X up, Z right, MCS radius)", focus=ALL) -> str:
    """The SVG markup (a ``<figure>``); ``path`` = NC reference points [X, Y, Z] (MCS) to draw;
    ``focus`` = what the view must hold besides the tool and the path."""
    z0, z1, x0, x1 = _bounds(scene, limits, path, focus)
    stroke = max((z1 - z0), (x1 - x0)) / 400.0
    parts = [f'<figure class="view lathe-view"><figcaption>{escape(caption)}</figcaption>',
             f'<svg id="{svg_id}" viewBox="{_f(z0)} {_f(-x1)} {_f(z1 - z0)} {_f(x1 - x0)}" '
             f'preserveAspectRatio="xMidYMid meet" role="img" aria-label="lathe view" '
             f'style="--stroke:{_f(stroke)}" data-kind="lathe">',
             f'<rect class="table" x="{_f(z0)}" y="{_f(-x1)}" width="{_f(z1 - z0)}" height="{_f(x1 - x0)}"/>']
    parts += _solids(scene, z0)
    parts.append(f'<line class="axis-line" x1="{_f(z0)}" y1="0" x2="{_f(z1)}" y2="0" '
                 f'stroke-dasharray="{_f(stroke * 8)} {_f(stroke * 4)}"/>')
    if path:
        points = " ".join(f"{_f(p[2])},{_f(-p[0])}" for p in path)
        parts.append(f'<polyline class="path" points="{points}" fill="none"/>')
    parts += _tool(scene.get("probe") or {}, stroke)
    parts.append("</svg></figure>")
    return "".join(parts)

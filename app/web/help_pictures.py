"""Help pictures of the measuring functions, drawn like the manual's figures (manual §4.3, spec
jog-measuring.md §2.5-jog-measuring §2.9, jog-measuring §5, jog-measuring §7): the part, where to put the probe, the points P1..Pn in their
order and the direction each is probed in, and the point the function computes (P0).

A schematic, not the real set-up (that is task_svg): fixed sizes in a 240 × 150 box, y down. The
directions follow the typed params; each touch carries ``data-point`` and ``data-dir`` (e.g. "+Y")
so a test can read the picture. In-plane functions are a top view (1st axis right, 2nd up), the
infeed-axis functions a side view (1st axis right, infeed up).
"""

from __future__ import annotations

from html import escape

from markupsafe import Markup

from app.errors import InvalidInput, NotFoundError
from app.i18n import N_, gettext
from app.web import units
from app.workflow.tasks import task_spec
from engine.plan_workpiece import corner_direction
from engine.planes import Plane
from engine.tasks import Family

W, H = 240, 150
END = ' text-anchor="end"'


class Picture:
    def __init__(self, plane: Plane, side: bool = False):
        self.plane, self.side = plane, side
        self.items: list[str] = []
        self.touches = 0

    def add(self, svg: str) -> None:
        self.items.append(svg)

    def touch(self, n: int | str, x: float, y: float, dx: float, dy: float, axis: str, sign: str) -> None:
        """Point ``n`` at (x, y), probed along (dx, dy) (screen units): an arrow ending at the point."""
        label = n if isinstance(n, str) else f"P{n}"
        self.touches += 1
        self.add(f'<g class="help-touch" data-point="{label}" data-dir="{sign}{axis}">'
                 f'<line class="help-arrow" x1="{x - 22 * dx:.1f}" y1="{y - 22 * dy:.1f}" x2="{x - 3 * dx:.1f}" '
                 f'y2="{y - 3 * dy:.1f}" marker-end="url(#help-head)"/>'
                 f'<circle class="help-point" cx="{x:.1f}" cy="{y:.1f}" r="2.6"/>'
                 f'<text x="{x + 7 * dx + (4 if dy else 0):.1f}" y="{y + 7 * dy + (10 if dy > 0 else 0) + (-4 if dx else 0):.1f}"'
                 f'{END if dx < 0 else ""}>{escape(label)}</text></g>')

    def probe(self, x: float, y: float, label: str = "") -> None:
        self.add(f'<g class="help-probe"><circle cx="{x:.1f}" cy="{y:.1f}" r="6"/>'
                 + (f'<line x1="{x:.1f}" y1="{y - 6:.1f}" x2="{x:.1f}" y2="{y - 30:.1f}"/>' if self.side else "")
                 + (f'<text x="{x + 9:.1f}" y="{y + 4:.1f}">{escape(label)}</text>' if label else "") + "</g>")

    def p0(self, x: float, y: float, label: str = "P0") -> None:
        self.add(f'<g class="help-p0" data-point="P0"><line x1="{x - 7:.1f}" y1="{y:.1f}" x2="{x + 7:.1f}" y2="{y:.1f}"/>'
                 f'<line x1="{x:.1f}" y1="{y - 7:.1f}" x2="{x:.1f}" y2="{y + 7:.1f}"/>'
                 f'<text x="{x + 5:.1f}" y="{y + 14:.1f}">{escape(label)}</text></g>')

    def svg(self, task: str, caption: str) -> Markup:
        up = self.plane.infeed if self.side else self.plane.second
        axes = (f'<g class="help-axes"><line x1="12" y1="138" x2="34" y2="138" marker-end="url(#help-head)"/>'
                f'<line x1="12" y1="138" x2="12" y2="116" marker-end="url(#help-head)"/>'
                f'<text x="37" y="141">{self.plane.first}</text><text x="8" y="112">{up}</text></g>')
        defs = ('<defs><marker id="help-head" viewBox="0 0 8 8" refX="7" refY="4" markerWidth="7" markerHeight="7" '
                'markerUnits="userSpaceOnUse" orient="auto-start-reverse"><path d="M0,0 L8,4 L0,8 z" class="help-head"/></marker></defs>')
        body = "".join(self.items)
        return Markup(f'<figure class="help-picture" data-task="{escape(task)}" data-touches="{self.touches}">'
                      f'<svg class="help-svg" viewBox="0 0 {W} {H}" role="img" aria-label="{escape(gettext("help picture"))}">'
                      f'{defs}{body}{axes}</svg><figcaption>{escape(caption)}</figcaption></figure>')


def _dir(sign: str, horizontal: bool) -> tuple[float, float]:
    s = 1.0 if sign == "+" else -1.0
    return (s, 0.0) if horizontal else (0.0, -s)          # screen y is down


# --- the functions ------------------------------------------------------------------------------

def _edge(task: str, p: dict, plane: Plane) -> Picture:
    axis = str(p.get("axis") or plane.first)
    sign = str(p.get("direction") or "+")
    if axis == plane.infeed:                               # side view: the probe above the top face
        pic = Picture(plane, side=True)
        pic.add('<rect class="help-part" x="60" y="80" width="120" height="50"/>')
        pic.probe(120, 40, gettext("start"))
        pic.touch(1, 120, 80, 0.0, 1.0, axis, "-")
        pic.p0(150, 80, f"{axis}0")
        return pic
    pic = Picture(plane)
    horizontal = axis == plane.first
    if task == "edge.distance":                            # a web between the two edges
        _edge_web(pic, axis, sign, str(p.get("direction_p2") or "-"), horizontal)
    elif horizontal:
        _edge_face_across(pic, task, axis, sign)
    else:
        _edge_face_along(pic, task, axis, sign)
    return pic


def _edge_web(pic: Picture, axis: str, sign: str, sign2: str, horizontal: bool) -> None:
    dx, dy = _dir(sign, horizontal)
    dx2, dy2 = _dir(sign2, horizontal)
    if horizontal:
        pic.add('<rect class="help-part" x="95" y="25" width="50" height="100"/>')
        pic.touch(1, 95 if sign == "+" else 145, 75, dx, dy, axis, sign)
        pic.touch(2, 145 if sign2 == "-" else 95, 75, dx2, dy2, axis, sign2)
    else:
        pic.add('<rect class="help-part" x="50" y="50" width="140" height="50"/>')
        pic.touch(1, 120, 100 if sign == "+" else 50, dx, dy, axis, sign)
        pic.touch(2, 120, 50 if sign2 == "-" else 100, dx2, dy2, axis, sign2)
    pic.p0(120, 75)


# the face probed: the part lies on the far side of the travel direction

def _edge_face_across(pic: Picture, task: str, axis: str, sign: str) -> None:
    """An edge probed along the screen's horizontal (the plane's first axis)."""
    dx, dy = _dir(sign, True)
    face = 100 if sign == "+" else 140
    pic.add(f'<rect class="help-part" x="{face if sign == "+" else 40}" y="25" width="100" height="100"/>')
    ys = (55, 100) if task == "edge.align" else (75,)
    for n, y in enumerate(ys, 1):
        pic.touch(n, face, y, dx, dy, axis, sign)
    pic.probe(face - 30 * dx, ys[0], gettext("start"))
    if task == "edge.set":
        pic.p0(face, 120, f"{axis}0")


def _edge_face_along(pic: Picture, task: str, axis: str, sign: str) -> None:
    """An edge probed along the screen's vertical (the plane's second axis)."""
    dx, dy = _dir(sign, False)
    face = 95 if sign == "+" else 55
    pic.add(f'<rect class="help-part" x="40" y="{face - 70 if sign == "+" else face}" width="160" height="70"/>')
    xs = (80, 160) if task == "edge.align" else (120,)
    for n, x in enumerate(xs, 1):
        pic.touch(n, x, face, dx, dy, axis, sign)
    pic.probe(xs[0], face - 30 * dy, gettext("start"))
    if task == "edge.set":
        pic.p0(190, face, f"{axis}0")


def _corner(task: str, p: dict, plane: Plane) -> Picture:
    """Positions 1..4 = front-left, front-right, back-right, back-left (engine.plan_workpiece)."""
    pic = Picture(plane)
    kind = str(p.get("kind") or "outside")
    try:
        position = int(p.get("position") or 1)
    except (TypeError, ValueError):
        position = 1
    position = position if position in (1, 2, 3, 4) else 1
    left, front = position in (1, 4), position in (1, 2)
    cx, cy = (70 if left else 170), (115 if front else 35)        # the corner on the screen
    sx, sy = (1 if left else -1), (-1 if front else 1)            # from the corner into the part (screen)
    if kind == "outside":
        x0, x1 = sorted((cx, cx + 130 * sx))
        y0, y1 = sorted((cy, cy + 90 * sy))
        pic.add(f'<rect class="help-part" x="{x0}" y="{y0}" width="{x1 - x0}" height="{y1 - y0}"/>')
    else:                                                          # the walls around an inside corner
        pic.add(f'<path class="help-part" d="M{cx},{cy} h{130 * sx} v{-14 * sy} h{-(130 + 14) * sx} '
                f'v{(90 + 14) * sy} h{14 * sx} z"/>')
    count = 4 if task == "corner.any" else 3
    along = [(cx + 30 * sx, cy), (cx + 95 * sx, cy), (cx, cy + 30 * sy), (cx, cy + 70 * sy)]
    for n in range(1, count + 1):
        d = corner_direction(kind, position, n, plane)
        first, second = float(d @ plane.unit(plane.first)), float(d @ plane.unit(plane.second))
        axis = plane.first if abs(first) > 0.5 else plane.second
        sign = "+" if (first + second) > 0 else "-"
        x, y = along[n - 1]
        pic.touch(n, x, y, first, -second, axis, sign)
    pic.p0(cx, cy)
    return pic


def _round(task: str, plane: Plane) -> Picture:
    """Holes and spigots: one (4 touches, the probe in the middle or above) or 2-4 centres."""
    pic = Picture(plane)
    spigot = task_spec(task).family == Family.SPIGOT
    count = int(task.split(".")[1]) if task.split(".")[1].isdigit() else 1
    if count == 1:
        pic.add(f'<rect class="help-part" x="40" y="15" width="160" height="120"/>'
                f'<circle class="{"help-boss" if spigot else "help-hole"}" cx="120" cy="75" r="40"/>')
        # (axis, sign of the travel, touch point on the screen): a hole outwards, a spigot inwards
        touches = ((plane.first, "+", 160, 75), (plane.first, "-", 80, 75),
                   (plane.second, "+", 120, 35), (plane.second, "-", 120, 115))
        for axis, outward, x, y in touches:
            sign = outward if not spigot else ("-" if outward == "+" else "+")
            dx, dy = _dir(sign, axis == plane.first)
            pic.touch(f"{outward}{axis}", x, y, dx, dy, axis, sign)      # named by the side it is on
        pic.probe(120, 75)
        pic.p0(120, 75)
        return pic
    centres = [(70, 105), (170, 105), (170, 45), (70, 45)][:count]
    if count == 3:
        centres = [(70, 105), (170, 105), (120, 40)]
    pic.add('<rect class="help-part" x="30" y="15" width="180" height="120"/>')
    for n, (x, y) in enumerate(centres, 1):
        pic.add(f'<circle class="{"help-boss" if spigot else "help-hole"}" cx="{x}" cy="{y}" r="14"/>'
                f'<g class="help-centre" data-point="P{n}"><circle class="help-point" cx="{x}" cy="{y}" r="2.6"/>'
                f'<text x="{x + 5}" y="{y - 17}">P{n}</text></g>')
    pic.probe(*centres[0])
    if count == 2:
        pic.add(f'<line class="help-result" x1="{centres[0][0]}" y1="{centres[0][1]}" x2="{centres[1][0]}" '
                f'y2="{centres[1][1]}"/>')
    elif count == 4:
        pic.add('<line class="help-result" x1="70" y1="105" x2="170" y2="45"/>'
                '<line class="help-result" x1="170" y1="105" x2="70" y2="45"/>')
        pic.p0(120, 75)
    else:
        pic.add('<circle class="help-result" cx="120" cy="81.25" r="56.25" fill="none"/>')
        pic.p0(120, 81.25)
    return pic


def _rect(task: str, plane: Plane) -> Picture:
    pic = Picture(plane)
    spigot = task_spec(task).family == Family.SPIGOT
    pic.add('<rect class="help-part" x="30" y="15" width="180" height="120"/>')
    pic.add(f'<rect class="{"help-boss" if spigot else "help-hole"}" x="70" y="45" width="100" height="60"/>')
    sign = "-" if spigot else "+"
    other = "+" if spigot else "-"
    if spigot:
        pic.touch(f"+{plane.first}", 170, 75, -1, 0, plane.first, sign)      # named by the side, probed inwards
        pic.touch(f"-{plane.first}", 70, 75, 1, 0, plane.first, other)
        pic.touch(f"+{plane.second}", 120, 45, 0, 1, plane.second, sign)
        pic.touch(f"-{plane.second}", 120, 105, 0, -1, plane.second, other)
    else:
        pic.touch(f"{sign}{plane.first}", 170, 75, 1, 0, plane.first, sign)
        pic.touch(f"{other}{plane.first}", 70, 75, -1, 0, plane.first, other)
        pic.touch(f"{sign}{plane.second}", 120, 45, 0, -1, plane.second, sign)
        pic.touch(f"{other}{plane.second}", 120, 105, 0, 1, plane.second, other)
    pic.probe(120, 75, gettext("start, above") if spigot else gettext("start"))
    pic.p0(120, 75)
    return pic


def _plane_align(plane: Plane) -> Picture:
    pic = Picture(plane, side=True)
    pic.add('<path class="help-part" d="M40,100 L200,82 L200,130 L40,130 z"/>')
    for n, x in enumerate((60, 120, 180), 1):
        pic.touch(n, x, 100 - (x - 40) * 18 / 160, 0.0, 1.0, plane.infeed, "-")
    return pic


def _probe_length(plane: Plane) -> Picture:
    pic = Picture(plane, side=True)
    pic.add('<rect class="help-part" x="50" y="95" width="140" height="35"/>')
    pic.probe(120, 55, gettext("probe"))
    pic.touch(1, 120, 95, 0.0, 1.0, plane.infeed, "-")
    note = gettext("calibration height %(axis)s", axis=plane.infeed)
    pic.add(f'<text class="help-note" x="140" y="90">{escape(note)}</text>')
    return pic


def _probe_radius(plane: Plane) -> Picture:
    pic = Picture(plane)
    pic.add('<circle class="help-ring" cx="120" cy="75" r="60"/><circle class="help-hole" cx="120" cy="75" r="40"/>')
    for axis, dx, dy, x, y in ((plane.first, 1, 0, 160, 75), (plane.first, -1, 0, 80, 75),
                               (plane.second, 0, -1, 120, 35), (plane.second, 0, 1, 120, 115)):
        s = "+" if dx > 0 or dy < 0 else "-"
        pic.touch(f"{s}{axis}", x, y, dx, dy, axis, s)
    pic.probe(120, 75, gettext("ring centre"))
    return pic


def _tool(task: str, plane: Plane) -> Picture:
    """Tool probe (disc) seen from the side: the tool above it (length), beside it (diameter)."""
    pic = Picture(plane, side=True)
    pic.add('<rect class="help-tool-probe" x="95" y="95" width="50" height="10"/>'
            '<rect class="help-fixture" x="112" y="105" width="16" height="30"/>')
    if task == "tool.diameter":
        pic.add('<rect class="help-tool" x="60" y="30" width="20" height="70"/>'
                '<text class="help-note" x="50" y="24">' + escape(gettext("turning")) + '</text>')
        pic.touch(1, 95, 100, 1.0, 0.0, plane.first, "+")
    else:
        pic.add('<rect class="help-tool" x="110" y="20" width="20" height="55"/>')
        pic.touch(1, 120, 95, 0.0, 1.0, plane.infeed, "-")
        if task == "toolprobe.calibrate":
            pic.add('<text class="help-note" x="136" y="40">' + escape(gettext("calibration tool")) + '</text>')
    return pic


CAPTIONS = {
    "edge.set": N_("Put the probe in front of the edge, at measuring depth; NC Start probes P1 in the direction shown."),
    "edge.align": N_("In front of the edge: P1 first, then P2 further along the same edge; Calculate gives the angle."),
    "edge.distance": N_("P1 in front of the first edge, P2 in front of the second; the centre between them is set."),
    "corner.right": N_("At the corner, at measuring depth: P1 and P2 on the reference edge, P3 on the second edge."),
    "corner.any": N_("P1 and P2 on the reference edge, P3 and P4 on the second edge; P0 is where the edges meet."),
    "pocket.rect": N_("Probe roughly in the middle of the pocket, at measuring depth: four walls are probed."),
    "spigot.rect": N_("Probe above the middle of the spigot: it goes round and probes the four sides at depth DZ."),
    "plane.align": N_("Above the plane: P1, P2, P3 spread wide, each probed downwards; the plane's tilt is found."),
    "probe.length": N_("The probe above a surface of known height (the calibration height); NC Start probes down."),
    "probe.radius": N_("The probe in the calibration ring, roughly at its centre, at measuring depth."),
    "toolprobe.calibrate": N_("The calibration tool above the tool probe's disc; NC Start probes the disc."),
    "tool.length": N_("The tool above the tool probe's disc; NC Start probes down for the length."),
    "tool.diameter": N_("The tool beside the disc, turning; NC Start probes sideways for the radius."),
    "hole.1": N_("Probe roughly at the centre of the hole, at measuring depth: NC Start probes the four points shown."),
    "spigot.1": N_("Probe roughly at the centre of the spigot, above it: NC Start probes the four points shown."),
}
SEVERAL = {
    "hole": N_("Probe at the centre of hole 1 (P1), NC Start; then hole 2 and on in order: each is a complete hole."),
    "spigot": N_("Probe at the centre of spigot 1 (P1), NC Start; then spigot 2 and on in order: each is a complete "
                 "spigot."),
}


def _caption(task: str) -> str:
    """The picture's caption in the operator's language."""
    if task in CAPTIONS:
        return gettext(CAPTIONS[task])
    return gettext(SEVERAL["hole" if task.startswith("hole") else "spigot"])


def draw(task: str, params: dict | None, plane: Plane) -> Markup | None:
    """The help picture of ``task`` for the typed ``params`` (raw form values are fine), or None."""
    p = params or {}
    family = task.split(".")[0]
    if family == "edge":
        pic = _edge(task, p, plane)
    elif family == "corner":
        pic = _corner(task, p, plane)
    elif task in ("pocket.rect", "spigot.rect"):
        pic = _rect(task, plane)
    elif family in ("hole", "spigot"):
        pic = _round(task, plane)
    elif task == "plane.align":
        pic = _plane_align(plane)
    elif task == "probe.length":
        pic = _probe_length(plane)
    elif task == "probe.radius":
        pic = _probe_radius(plane)
    elif task in ("toolprobe.calibrate", "tool.length", "tool.diameter"):
        pic = _tool(task, plane)
    else:
        return None
    return pic.svg(task, _caption(task))


# --- the equipment a function uses (issue 17 item 5): shown beside its picture ----------------------

def _yes(flag) -> str:
    return gettext("yes") if flag else gettext("not yet")


def _diameter(mm: float, gud) -> str:
    """"Ø 4.000 mm" in the screen's unit and the language's decimal sign."""
    return f"Ø {units.format_length(mm, gud)} {units.unit(gud)}"


def _row(key: str, text: str) -> tuple[str, str, str]:
    """(key for tests and styles, the label in the operator's language, the text)."""
    return key, gettext(key), text


def equipment_rows(services, task: str) -> list[tuple[str, str, str]]:
    """(key, label, text) rows: the probe's calibration data, the calibration ring, the tool probe.
    Labels are catalogue texts (N_), lengths in the screen's unit."""
    gud = services.settings.get()
    rows: list[tuple[str, str, str]] = []
    family = task.split(".")[0]
    no_data = gettext("%(number)s: no data", number=gud.tool_probe_number if family in ("toolprobe", "tool")
                      else gud.probe_number)
    if family in ("toolprobe", "tool"):
        try:
            tp = services.tool_probes.get(int(gud.tool_probe_number))
        except (NotFoundError, InvalidInput, ValueError, TypeError):    # no record, or no number set
            return [_row(N_("Tool probe"), no_data)]
        rows.append(_row(N_("Tool probe"), gettext("%(number)s, disc %(diameter)s", number=tp["number"],
                                                   diameter=_diameter(float(tp.get("disc_diameter") or 0), gud))))
        rows.append(_row(N_("Calibrated"), gettext("length %(length)s, diameter %(diameter)s",
                                                   length=_yes(tp.get("calibrated_length")),
                                                   diameter=_yes(tp.get("calibrated_diameter")))))
        if tp.get("calibration_tool"):
            rows.append(_row(N_("Calibration tool"), f"T{tp['calibration_tool']}"))
        return rows
    try:
        probe = services.probes.get(int(gud.probe_number))
    except (NotFoundError, InvalidInput, ValueError, TypeError):
        return [_row(N_("Probe data"), no_data)]
    effective = float(probe.get("effective_diameter") or 0.0)
    ball = _diameter(float(probe.get("ball_diameter") or 0), gud)
    if effective > 0:
        text = gettext("%(number)s: ball %(ball)s, effective %(effective)s", number=probe["number"], ball=ball,
                       effective=_diameter(effective, gud))
    else:
        text = gettext("%(number)s: ball %(ball)s", number=probe["number"], ball=ball)
    rows.append(_row(N_("Probe data"), text))
    rows.append(_row(N_("Calibrated"), gettext("radius %(radius)s, length %(length)s",
                                               radius=_yes(probe.get("calibrated_radius")),
                                               length=_yes(probe.get("calibrated_length")))))
    if probe.get("cal_ring_diameter"):
        rows.append(_row(N_("Calibrated in ring"), _diameter(float(probe["cal_ring_diameter"]), gud)))
    if task == "probe.radius":
        ring = float(gud.cal_ring_diameter or 0.0)
        rows.append(_row(N_("Calibration ring"), _diameter(ring, gud) if ring > 0 else gettext("not set (type it in)")))
    if task == "probe.length":
        rows.append(_row(N_("Calibration height"),
                         f"{units.format_length(float(gud.cal_height or 0.0), gud)} {units.unit(gud)}"))
    return rows

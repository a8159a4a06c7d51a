"""The true scene as exact signed distances of convex primitives composed by CSG (design.md §5).

Composition: ``sdf = min over bodies of max(sdf_P, -sdf_N1, -sdf_N2, ...)``: a body is one
positive convex primitive minus convex cut-outs (block minus holes/pockets, ring minus bore);
spigots, bosses, spheres, gauges are further bodies (union). A prism part (design.md §9.8) is
the union of convex prisms: its polygon (normalised counter-clockwise) is cut into convex
pieces (ear clipping, then Hertel–Mehlhorn merging of the triangles while the union stays
convex), each piece one body with the part's cut-outs. The distance to a union is the minimum
of the distances, so the composed set {sdf <= r} (r > 0) is exact whatever the pieces; inside
the part the composed value is a bound (pieces meet at inner diagonals), used only for its sign.

Contact of a ball of radius r swept along c(s) = c0 + s·d happens where sdf(c(s)) <= r. For
a body that set is ``{sdf_P <= r} minus ∪{sdf_N < -r}``. Each primitive's signed distance
along a line is a convex function of s, so each of these sets is one interval whose ends are
root-found (golden-section bracket, then brentq to 1e-13 mm): nothing is stepped, grazing
and parallel moves cost the same as head-on ones.

Exactness (honest list):
- exact: every plane face at any angle (block faces of a rotated/tilted block, prism walls,
  hole and pocket bottoms, boss faces), cylinder walls from inside (holes, ring bore) and
  outside (spigots, ring, tool probe), spheres, the block's and the prism's own edges and
  corners (exact box SDF, exact extruded convex-polygon SDF: vertical edges at any corner
  angle, top and bottom rims), a non-convex prism's inside corners and concave junctions
  (hole bottom edge, spigot foot, sphere on the part: a union of exact sets is exact).
- a bound only: convex edges made by subtraction (the rim of a hole or pocket, the ring's
  bore rim). There the composed set is the sharp offset instead of the rounded one, so a
  ball reaching over a rim from above touches up to (√2 − 1)·r earlier than the true torus
  contact. Measuring tasks never probe rims; a jog over a rim stops a little early.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .axis_lines import as_line, table_transform
from .physics import SPINDLE_MOUNTS, rpy_matrix
from .polygon import convex_pieces
from .roots import brentq

ROOT_XTOL = 1e-13          # mm, brentq tolerance on the path parameter
_RTOL = 4 * float(np.finfo(float).eps)
_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0
_EXTEND = 2000.0           # mm: cut-outs reach this far above the top face (open to the air)


class Primitive:
    """A convex solid in its own frame (centre at the origin), placed by local2mcs = (R, t)."""

    def __init__(self, rotation: np.ndarray, centre) -> None:
        self.rotation = np.asarray(rotation, dtype=float)       # local -> MCS
        self.centre = np.asarray(centre, dtype=float)
        # the same as plain floats (row-major): the contact search asks one point at a time,
        # where numpy's cost per call is most of the work (issue 30 item 3)
        self._r = tuple(float(v) for v in self.rotation.ravel())
        self._c = (float(self.centre[0]), float(self.centre[1]), float(self.centre[2]))

    def to_local(self, p_in_mcs) -> np.ndarray:
        return self.rotation.T @ (np.asarray(p_in_mcs, dtype=float) - self.centre)

    def _local(self, x: float, y: float, z: float) -> tuple[float, float, float]:
        """``to_local`` of one point in plain floats: Rᵀ·(p − centre)."""
        r = self._r
        cx, cy, cz = self._c
        dx, dy, dz = x - cx, y - cy, z - cz
        return (r[0] * dx + r[3] * dy + r[6] * dz, r[1] * dx + r[4] * dy + r[7] * dz,
                r[2] * dx + r[5] * dy + r[8] * dz)

    def _local_dir(self, dx: float, dy: float, dz: float) -> tuple[float, float, float]:
        r = self._r
        return (r[0] * dx + r[3] * dy + r[6] * dz, r[1] * dx + r[4] * dy + r[7] * dz,
                r[2] * dx + r[5] * dy + r[8] * dz)

    def local_sdf(self, x: float, y: float, z: float) -> float:  # pragma: no cover - abstract
        raise NotImplementedError

    @property
    def bound(self) -> float:      # pragma: no cover - abstract
        """Radius about ``centre`` of a sphere holding the solid."""
        raise NotImplementedError

    def out_of_reach(self, c0, d, length: float, level: float) -> bool:
        """True when no point of the path c0 + s·d, s in [0, length], comes within ``level`` of
        the solid (the bounding sphere proves it): the exact search can be skipped."""
        return self._out_of_reach(_xyz(c0), _xyz(d), length, level)

    def _out_of_reach(self, c0: tuple[float, float, float], d: tuple[float, float, float], length: float,
                      level: float) -> bool:
        cx, cy, cz = self._c
        rx, ry, rz = cx - c0[0], cy - c0[1], cz - c0[2]
        s = min(max(rx * d[0] + ry * d[1] + rz * d[2], 0.0), length)
        gx, gy, gz = rx - s * d[0], ry - s * d[1], rz - s * d[2]
        return math.sqrt(gx * gx + gy * gy + gz * gz) > self.bound + max(level, 0.0) + 1e-9

    def sdf(self, p_in_mcs) -> float:
        return self.local_sdf(*self._local(*_xyz(p_in_mcs)))

    def along(self, c0, d):
        """g(s) = sdf(c0 + s·d) as a fast scalar closure (convex in s)."""
        return self._along(_xyz(c0), _xyz(d))

    def _along(self, c0: tuple[float, float, float], d: tuple[float, float, float]):
        x0, y0, z0 = self._local(*c0)
        dx, dy, dz = self._local_dir(*d)
        f = self.local_sdf
        return lambda s: f(x0 + s * dx, y0 + s * dy, z0 + s * dz)


def _xyz(p) -> tuple[float, float, float]:
    """A point or direction as three plain floats."""
    a = np.asarray(p, dtype=float).reshape(-1)
    return float(a[0]), float(a[1]), float(a[2])


class Box(Primitive):
    def __init__(self, rotation, centre, half_size) -> None:
        super().__init__(rotation, centre)
        self.hx, self.hy, self.hz = (float(v) for v in half_size)

    def local_sdf(self, x: float, y: float, z: float) -> float:
        # exact box SDF: outside distance + inside (negative) part
        qx, qy, qz = abs(x) - self.hx, abs(y) - self.hy, abs(z) - self.hz
        outside = math.sqrt(max(qx, 0.0) ** 2 + max(qy, 0.0) ** 2 + max(qz, 0.0) ** 2)
        return outside + min(max(qx, qy, qz), 0.0)

    @property
    def bound(self) -> float:
        return math.sqrt(self.hx ** 2 + self.hy ** 2 + self.hz ** 2)


class Cylinder(Primitive):
    """Capped cylinder along the local z axis."""

    def __init__(self, rotation, centre, radius: float, half_height: float) -> None:
        super().__init__(rotation, centre)
        self.radius = float(radius)
        self.hz = float(half_height)

    def local_sdf(self, x: float, y: float, z: float) -> float:
        dr = math.hypot(x, y) - self.radius
        dz = abs(z) - self.hz
        return min(max(dr, dz), 0.0) + math.hypot(max(dr, 0.0), max(dz, 0.0))

    @property
    def bound(self) -> float:
        return math.hypot(self.radius, self.hz)

    def _out_of_reach(self, c0: tuple[float, float, float], d: tuple[float, float, float], length: float,
                      level: float) -> bool:
        """The cylinder lies in the capsule of its axis segment and radius (cut-outs are long)."""
        r = self._r
        axis = (r[2], r[5], r[8])
        cx, cy, cz = self._c
        foot = (cx - self.hz * axis[0], cy - self.hz * axis[1], cz - self.hz * axis[2])
        gap = _segment_distance_xyz(c0, d, length, foot, axis, 2.0 * self.hz)
        return gap > self.radius + max(level, 0.0) + 1e-9


class ConvexPrism(Primitive):
    """A convex polygon (local x/y, counter-clockwise) extruded over local z in [−hz, hz].

    Exact SDF: the 2D convex polygon's signed distance w (outside: distance to the nearest
    edge segment; inside: −distance to the nearest edge line) extruded like a box:
    ``min(max(w, dz), 0) + |(max(w, 0), max(dz, 0))|``, dz = |z| − hz. Convex, 1-Lipschitz.
    """

    def __init__(self, rotation, centre, polygon, half_height: float) -> None:
        super().__init__(rotation, centre)
        pts = [(float(x), float(y)) for x, y in polygon]
        self.polygon = pts
        self.hz = float(half_height)
        edges = []
        for i, (ax, ay) in enumerate(pts):
            bx, by = pts[(i + 1) % len(pts)]
            ex, ey = bx - ax, by - ay
            length = math.hypot(ex, ey)
            edges.append((ax, ay, ex, ey, 1.0 / (length * length), ey / length, -ex / length))
        self._edges = tuple(edges)

    def distance_2d(self, x: float, y: float) -> float:
        """Signed distance of (x, y) to the polygon (negative inside)."""
        best_sq = math.inf
        plane = -math.inf
        for ax, ay, ex, ey, inv_sq, nx, ny in self._edges:
            px, py = x - ax, y - ay
            h = nx * px + ny * py                       # signed distance to the edge line (outward +)
            if h > plane:
                plane = h
            t = (px * ex + py * ey) * inv_sq
            t = 0.0 if t < 0.0 else (1.0 if t > 1.0 else t)
            qx, qy = px - t * ex, py - t * ey
            sq = qx * qx + qy * qy
            if sq < best_sq:
                best_sq = sq
        return plane if plane <= 0.0 else math.sqrt(best_sq)

    def local_sdf(self, x: float, y: float, z: float) -> float:
        w = self.distance_2d(x, y)
        dz = abs(z) - self.hz
        return min(max(w, dz), 0.0) + math.hypot(max(w, 0.0), max(dz, 0.0))

    @property
    def bound(self) -> float:
        return math.hypot(max(math.hypot(x, y) for x, y in self.polygon), self.hz)


class Ball(Primitive):
    """A sphere of ``radius`` about its centre (exact SDF)."""

    def __init__(self, centre, radius: float) -> None:
        super().__init__(np.eye(3), centre)
        self.radius = float(radius)

    def local_sdf(self, x: float, y: float, z: float) -> float:
        return math.sqrt(x * x + y * y + z * z) - self.radius

    @property
    def bound(self) -> float:
        return self.radius


@dataclass
class Body:
    kind: str                                     # "part", "ring_gauge", "tool_probe"
    solid: Primitive
    cutouts: list[Primitive] = field(default_factory=list)
    name: str = ""                                # what the operator reads ("spigot"); default: kind

    def sdf(self, p) -> float:
        return self._sdf(*_xyz(p))

    def _sdf(self, x: float, y: float, z: float) -> float:
        solid = self.solid
        value = solid.local_sdf(*solid._local(x, y, z))
        for c in self.cutouts:
            cut = -c.local_sdf(*c._local(x, y, z))
            if cut > value:
                value = cut
        return value


def _segment_distance(p0, u, length_u: float, q0, v, length_v: float) -> float:
    """Distance between the segments p0 + s·u (s in [0, length_u]) and q0 + t·v (t in [0,
    length_v]); u, v unit vectors (the closest points by clamping, Ericson §5.1.9)."""
    return _segment_distance_xyz(_xyz(p0), _xyz(u), length_u, _xyz(q0), _xyz(v), length_v)


def _segment_distance_xyz(p0, u, length_u: float, q0, v, length_v: float) -> float:
    """``_segment_distance`` in plain floats (the same formulas)."""
    rx, ry, rz = p0[0] - q0[0], p0[1] - q0[1], p0[2] - q0[2]
    b = u[0] * v[0] + u[1] * v[1] + u[2] * v[2]
    c = u[0] * rx + u[1] * ry + u[2] * rz
    f = v[0] * rx + v[1] * ry + v[2] * rz
    denom = 1.0 - b * b
    s = min(max((b * f - c) / denom, 0.0), length_u) if denom > 1e-12 else 0.0
    t = b * s + f
    if t < 0.0:
        t, s = 0.0, min(max(-c, 0.0), length_u)
    elif t > length_v:
        t, s = length_v, min(max(b * length_v - c, 0.0), length_u)
    gx = p0[0] + s * u[0] - (q0[0] + t * v[0])
    gy = p0[1] + s * u[1] - (q0[1] + t * v[1])
    gz = p0[2] + s * u[2] - (q0[2] + t * v[2])
    return math.sqrt(gx * gx + gy * gy + gz * gz)


def _sublevel_interval(g, level: float, length: float) -> tuple[float, float] | None:
    """{s in [0, length] : g(s) <= level} for a convex, 1-Lipschitz g: one interval or None."""
    lo, hi = 0.0, length
    g_lo, g_hi = g(lo), g(hi)
    inside = None
    if g_lo <= level:
        inside = lo
    elif g_hi <= level:
        inside = hi
    else:
        # golden section on the convex g; stop as soon as a point is inside or the Lipschitz
        # bound proves the minimum is above the level
        x1 = hi - _GOLDEN * (hi - lo)
        x2 = lo + _GOLDEN * (hi - lo)
        g1, g2 = g(x1), g(x2)
        for _ in range(200):
            if g1 <= level:
                inside = x1
                break
            if g2 <= level:
                inside = x2
                break
            if (g_lo + g_hi - (hi - lo)) / 2.0 > level or hi - lo < 1e-12 * max(1.0, length):
                return None
            if g1 < g2:
                hi, g_hi = x2, g2
                x2, g2 = x1, g1
                x1 = hi - _GOLDEN * (hi - lo)
                g1 = g(x1)
            else:
                lo, g_lo = x1, g1
                x1, g1 = x2, g2
                x2 = lo + _GOLDEN * (hi - lo)
                g2 = g(x2)
        if inside is None:
            return None

    def shifted(s: float) -> float:
        return g(s) - level

    start = 0.0 if g(0.0) <= level else brentq(shifted, 0.0, inside, xtol=ROOT_XTOL, rtol=_RTOL)
    end = length if g(length) <= level else brentq(shifted, inside, length, xtol=ROOT_XTOL,
                                                   rtol=_RTOL)
    return start, end


def _subtract(piece: tuple[float, float], cut: tuple[float, float], length: float):
    """Closed piece minus the open cut (cuts touching the path ends extend beyond them)."""
    a, b = piece
    ca = -math.inf if cut[0] <= 0.0 else cut[0]
    cb = math.inf if cut[1] >= length else cut[1]
    if cb <= a or ca >= b:
        return [piece]
    out = []
    if ca >= a:
        out.append((a, ca))
    if cb <= b:
        out.append((cb, b))
    return out


_UNKNOWN = object()
CONTACT_MEMO = 4096             # first_contact answers kept per scene


class Scene:
    """Union of bodies. All coordinates MCS, mm."""

    def __init__(self, bodies: list[Body] | None = None) -> None:
        self.bodies = list(bodies or [])
        # first_contact's answers by their exact inputs (issue 30): the probe measuring a point
        # again from where the last run ended travels the same paths until its first latch
        self._contacts: dict[tuple[float, ...], float | None] = {}

    def subset(self, kinds) -> Scene:
        return Scene([b for b in self.bodies if b.kind in kinds])

    def sdf(self, p_in_mcs) -> float:
        """Composed signed distance (exact on faces; a bound near subtraction rims)."""
        if not self.bodies:
            return math.inf
        x, y, z = _xyz(p_in_mcs)
        return min(b._sdf(x, y, z) for b in self.bodies)

    def contact_intervals(self, center0, direction, max_distance: float, radius: float):
        """Sorted, merged intervals of s in [0, max_distance] where the ball touches the solid."""
        c0 = _xyz(center0)
        d = _xyz(direction)
        pieces: list[tuple[float, float]] = []
        for body in self.bodies:
            if body.solid._out_of_reach(c0, d, max_distance, radius):
                continue
            main = _sublevel_interval(body.solid._along(c0, d), radius, max_distance)
            if main is None:
                continue
            body_pieces = [main]
            for cutout in body.cutouts:
                if cutout._out_of_reach(c0, d, max_distance, -radius):
                    continue
                cut = _sublevel_interval(cutout._along(c0, d), -radius, max_distance)
                if cut is None:
                    continue
                body_pieces = [q for p in body_pieces for q in _subtract(p, cut, max_distance)]
            pieces.extend(body_pieces)
        pieces.sort()
        merged: list[list[float]] = []
        for a, b in pieces:
            if merged and a <= merged[-1][1] + 1e-12:
                merged[-1][1] = max(merged[-1][1], b)
            else:
                merged.append([a, b])
        return [(a, b) for a, b in merged]

    def first_contact(self, center0, direction, max_distance: float, radius: float) -> float | None:
        """First s in [0, max_distance] where the ball centre c0 + s·d is at ``radius`` from the solid.

        A ball that starts in contact (a deflected probe) may move away or slide along the
        surface; moving deeper into the material is a contact at s = 0.
        """
        key = (*_xyz(center0), *_xyz(direction), float(max_distance), float(radius))
        known = self._contacts.get(key, _UNKNOWN)
        if known is not _UNKNOWN:
            return known        # type: ignore[return-value]  # the same path: the same answer
        found = self._first_contact(center0, direction, max_distance, radius)
        if len(self._contacts) >= CONTACT_MEMO:
            self._contacts.clear()
        self._contacts[key] = found
        return found

    def _first_contact(self, center0, direction, max_distance: float, radius: float) -> float | None:
        d = np.asarray(direction, dtype=float)
        norm = float(np.linalg.norm(d))
        if not norm > 0.0:
            raise ValueError("direction must be a non-zero vector")
        d = d / norm
        if max_distance <= 0.0 or not self.bodies:
            return None
        intervals = self.contact_intervals(center0, d, max_distance, radius)
        if not intervals:
            return None
        first_start, first_end = intervals[0]
        if first_start > 0.0:
            return first_start
        c0 = np.asarray(center0, dtype=float)
        step = 1e-7
        slope = (self.sdf(c0 + step * d) - self.sdf(c0)) / step
        if slope < -1e-6:
            return 0.0                       # pressing further into the material
        # leaving (or sliding along) the surface: the next contact is the next interval
        if len(intervals) > 1:
            return intervals[1][0]
        return None


def workpiece_pose(scenario, table_angle: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Part -> MCS (R, t) with the rotary table at ``table_angle`` (deg; pose = the part at 0).

    DIN 66217 table: +angle turns the part by −angle about the table's TRUE axis line (design.md
    §10.6, axis_lines.table_transform); nominally the vertical through ``machine.rotary_table.center``:
    R' = Rz(−c)·R, t' = Rz(−c)·(t − centre) + centre.
    """
    wp = scenario.workpiece
    rot = rpy_matrix(wp.pose.rot)
    trans = np.asarray(wp.pose.trans, dtype=float)
    table = scenario.machine.rotary_table
    if table is None or table_angle == 0.0:
        return rot, trans
    turn, shift = table_transform(as_line(table.true_lines()[table.axis]), table_angle)
    return turn @ rot, turn @ trans + shift


def _cut_from_top(depth: float, block_height: float) -> tuple[float, float]:
    """(mid z, half height) in part coordinates of a cut-out from ``depth`` below the top face up
    into the air; through the block when at least as deep as the block."""
    bottom = -_EXTEND if depth >= block_height else -depth
    return (_EXTEND + bottom) / 2.0, (_EXTEND - bottom) / 2.0


def spindle_mount(scenario) -> np.ndarray:
    """Probe frame -> MCS at SPOS 0 (physics.SPINDLE_MOUNTS): local z = the spindle axis."""
    return SPINDLE_MOUNTS[scenario.machine.spindle_axis]


def _base_solids(base, rot, place) -> list[Primitive]:
    """The part's body (block or prism) as convex primitives in MCS."""
    if base.type == "block":
        lx, ly, lz = base.size
        return [Box(rot, place([lx / 2, ly / 2, -lz / 2]), [lx / 2, ly / 2, lz / 2])]
    centre = place([0.0, 0.0, -base.height / 2])
    return [ConvexPrism(rot, centre, piece, base.height / 2) for piece in convex_pieces(base.polygon)]


def _base_height(base) -> float:
    return base.size[2] if base.type == "block" else base.height


def _vertical(mount) -> bool:
    return mount is None or np.array_equal(np.asarray(mount, dtype=float), np.eye(3))


def _axial_cylinder(mount: np.ndarray, face_centre, radius: float, length: float) -> Cylinder:
    """A cylinder whose axis is the spindle axis (``mount``·ẑ): its face at ``face_centre`` (the
    face towards the spindle), reaching ``length`` away from the spindle."""
    face = np.asarray(face_centre, dtype=float)
    if _vertical(mount):                                  # the vertical gauge, as in wave 1
        return Cylinder(np.eye(3), [face[0], face[1], face[2] - length / 2], radius, length / 2)
    return Cylinder(mount, face - mount[:, 2] * (length / 2), radius, length / 2)


def build_scene(scenario, table_angle: float = 0.0) -> Scene:
    """The scenario's true solids (design.md §4 field meanings) as a Scene in MCS.

    Gauges (ring, tool probe) stand along the spindle axis: their ``center`` is the centre of
    the face towards the spindle (the top face on a vertical spindle), their height reaches away
    from it. Spheres are bodies of their own (no cut-out cuts them); without a block or prism the
    workpiece is its spheres alone.
    """
    bodies: list[Body] = []
    wp = scenario.workpiece
    if wp is not None and (wp.base is not None or wp.spheres):
        rot, trans = workpiece_pose(scenario, table_angle)

        def place(p_part) -> np.ndarray:
            return rot @ np.asarray(p_part, dtype=float) + trans

        base = wp.base
        cutouts: list[Primitive] = []
        extras: list[Body] = []
        height = _base_height(base) if base is not None else 0.0
        for f in wp.features:
            if f.type == "hole":
                mid, half = _cut_from_top(f.depth, height)
                cutouts.append(Cylinder(rot, place([f.center[0], f.center[1], mid]), f.diameter / 2, half))
            elif f.type == "pocket":
                mid, half = _cut_from_top(f.depth, height)
                cutouts.append(Box(rot, place([f.center[0], f.center[1], mid]),
                                   [f.size[0] / 2, f.size[1] / 2, half]))
            elif f.type == "spigot":
                extras.append(Body("part", Cylinder(rot, place([f.center[0], f.center[1], f.height / 2]),
                                                    f.diameter / 2, f.height / 2), name="spigot"))
            elif f.type == "boss":
                extras.append(Body("part", Box(rot, place([f.center[0], f.center[1], f.height / 2]),
                                               [f.size[0] / 2, f.size[1] / 2, f.height / 2]), name="boss"))
            elif f.type == "sphere":
                extras.append(Body("part", Ball(place(f.center), f.diameter / 2), name="sphere"))
        if base is not None:
            bodies.extend(Body("part", solid, cutouts, name="workpiece") for solid in _base_solids(base, rot, place))
        bodies.extend(extras)
    mount = spindle_mount(scenario)
    ring = scenario.ring_gauge
    if ring is not None:
        outer = _axial_cylinder(mount, ring.center, ring.outer_diameter / 2, ring.height)
        bore = Cylinder(outer.rotation, outer.centre, ring.diameter / 2, _EXTEND)
        bodies.append(Body("ring_gauge", outer, [bore]))
    tp = scenario.tool_probe
    if tp is not None:
        bodies.append(Body("tool_probe", tool_probe_cylinder(tp, mount=mount)))
    return Scene(bodies)


def _base_outline(out: dict, base, place, axis: list[float]) -> None:
    """The block's corners or the prism's polygon (top and bottom) into ``out``."""
    if base is not None and base.type == "block":
        lx, ly, lz = base.size
        out["block"] = {"corners": [place(x, y, z) for z in (0.0, -lz) for x, y in
                                    ((0, 0), (lx, 0), (lx, ly), (0, ly))]}
    elif base is not None:
        polygon = base.ccw_polygon
        out["prism"] = {"kind": "prism", "top": [place(x, y, 0.0) for x, y in polygon],
                        "bottom": [place(x, y, -base.height) for x, y in polygon],
                        "axis": axis, "height": float(base.height)}


def _feature_outline(out: dict, f, place, axis: list[float]) -> None:
    """A hole/spigot (circle), pocket/boss (rect) or sphere into ``out``."""
    if f.type in ("hole", "spigot"):
        top = 0.0 if f.type == "hole" else f.height
        height = f.depth if f.type == "hole" else f.height
        out["circles"].append({"kind": f.type, "center": place(f.center[0], f.center[1], top),
                               "axis": axis, "diameter": f.diameter, "height": height})
    elif f.type in ("pocket", "boss"):
        top = 0.0 if f.type == "pocket" else f.height
        hx, hy = f.size[0] / 2, f.size[1] / 2
        cx, cy = f.center
        out["rects"].append({"kind": f.type, "corners": [
            place(cx + sx * hx, cy + sy * hy, top) for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))]})
    elif f.type == "sphere":
        out["spheres"].append({"kind": "sphere", "center": place(*f.center), "diameter": float(f.diameter)})


def outline(scenario, table_angle: float = 0.0) -> dict:
    """The true solids for the machine view (JSON-ready, MCS): block corners, circles, rects,
    the prism's polygon (``prism``: ``top``/``bottom`` vertices counter-clockwise seen from the
    part's +z, ``axis`` = the part's z axis, ``height``) and the spheres (``spheres``: ``center``,
    ``diameter``). Circles carry their cylinder ``axis`` (the part's z, or the spindle axis for
    the gauges)."""
    out: dict = {"block": None, "prism": None, "circles": [], "rects": [], "spheres": []}
    wp = scenario.workpiece
    if wp is not None and (wp.base is not None or wp.spheres):
        rot, trans = workpiece_pose(scenario, table_angle)

        def place(x: float, y: float, z: float) -> list[float]:
            return [float(v) for v in rot @ np.array([x, y, z]) + trans]

        axis = [float(v) for v in rot[:, 2]]          # the part's z axis
        _base_outline(out, wp.base, place, axis)
        for f in wp.features:
            _feature_outline(out, f, place, axis)
    up = [float(v) for v in spindle_mount(scenario)[:, 2]]
    if scenario.ring_gauge is not None:
        ring = scenario.ring_gauge
        for kind, dia in (("ring_bore", ring.diameter), ("ring_outer", ring.outer_diameter)):
            out["circles"].append({"kind": kind, "center": list(ring.center), "axis": up,
                                   "diameter": dia, "height": ring.height})
    if scenario.tool_probe is not None:
        tp = scenario.tool_probe
        out["circles"].append({"kind": "tool_probe", "center": list(tp.center), "axis": up,
                               "diameter": tp.disc_diameter, "height": tp.height})
    return out


def tool_probe_cylinder(tool_probe, grow_radius: float = 0.0, grow_down: float = 0.0, mount=None) -> Cylinder:
    """The tool probe cylinder, optionally grown (Minkowski sum with a cutter along its axis).

    Its axis is the spindle axis (``mount``·ẑ, default vertical); ``center`` is its face towards
    the spindle, ``grow_down`` extends it away from the spindle."""
    if _vertical(mount):
        cx, cy, cz = tool_probe.center
        bottom = cz - tool_probe.height - grow_down
        return Cylinder(np.eye(3), [cx, cy, (cz + bottom) / 2], tool_probe.disc_diameter / 2 + grow_radius,
                        (cz - bottom) / 2)
    return _axial_cylinder(np.asarray(mount, dtype=float), tool_probe.center,
                           tool_probe.disc_diameter / 2 + grow_radius, tool_probe.height + grow_down)


def _primitive_data(solid: Primitive, name: str) -> dict:
    """One primitive as plain data (engine.guard_model reads it): rotation (local -> MCS, rows),
    centre, and the shape: ``sphere``/``radius``, a circle ``radius`` or a ``polygon`` with its
    ``half_height`` along local z."""
    out: dict = {"name": name, "rotation": solid.rotation.tolist(), "centre": solid.centre.tolist()}
    if isinstance(solid, Ball):
        out.update(sphere=True, radius=solid.radius)
    elif isinstance(solid, Cylinder):
        out.update(radius=solid.radius, half_height=solid.hz)
    elif isinstance(solid, Box):
        out.update(polygon=[[-solid.hx, -solid.hy], [solid.hx, -solid.hy], [solid.hx, solid.hy],
                            [-solid.hx, solid.hy]], half_height=solid.hz)
    elif isinstance(solid, ConvexPrism):
        out.update(polygon=[list(p) for p in solid.polygon], half_height=solid.hz)
    else:                                            # pragma: no cover - every primitive is listed
        raise TypeError(f"unknown primitive {solid!r}")
    return out


def protection_data(scene: Scene) -> list[dict]:
    """The scene as the control's protection model (the start guard, issue 24 §1): bodies of a
    solid minus cut-outs, each named as the operator reads it."""
    return [{"solid": _primitive_data(body.solid, body.name or body.kind),
             "cutouts": [_primitive_data(c, "cut-out") for c in body.cutouts]} for body in scene.bodies]

"""The true scene as exact signed distances of convex primitives composed by CSG (design.md §5).

Composition: ``sdf = min over bodies of max(sdf_P, -sdf_N1, -sdf_N2, ...)``: a body is one
positive convex primitive minus convex cut-outs (block minus holes/pockets, ring minus bore);
spigots, bosses, gauges are further bodies (union).

Contact of a ball of radius r swept along c(s) = c0 + s·d happens where sdf(c(s)) <= r. For
a body that set is ``{sdf_P <= r} minus ∪{sdf_N < -r}``. Each primitive's signed distance
along a line is a convex function of s, so each of these sets is one interval whose ends are
root-found (golden-section bracket, then brentq to 1e-13 mm): nothing is stepped, grazing
and parallel moves cost the same as head-on ones.

Exactness (honest list):
- exact: every plane face at any angle (block faces of a rotated/tilted block, hole and
  pocket bottoms, boss faces), cylinder walls from inside (holes, ring bore) and outside
  (spigots, ring, tool probe), the block's own edges and corners (exact box SDF), concave
  junctions (hole bottom edge, spigot foot: union of exact sets is exact).
- a bound only: convex edges made by subtraction (the rim of a hole or pocket, the ring's
  bore rim). There the composed set is the sharp offset instead of the rounded one, so a
  ball reaching over a rim from above touches up to (√2 − 1)·r earlier than the true torus
  contact. Measuring tasks never probe rims; a jog over a rim stops a little early.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq

from .physics import rpy_matrix

ROOT_XTOL = 1e-13          # mm, brentq tolerance on the path parameter
_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0
_EXTEND = 2000.0           # mm: cut-outs reach this far above the top face (open to the air)


class Primitive:
    """A convex solid in its own frame (centre at the origin), placed by local2mcs = (R, t)."""

    def __init__(self, rotation: np.ndarray, centre) -> None:
        self.rotation = np.asarray(rotation, dtype=float)       # local -> MCS
        self.centre = np.asarray(centre, dtype=float)

    def to_local(self, p_in_mcs) -> np.ndarray:
        return self.rotation.T @ (np.asarray(p_in_mcs, dtype=float) - self.centre)

    def local_sdf(self, x: float, y: float, z: float) -> float:  # pragma: no cover - abstract
        raise NotImplementedError

    def sdf(self, p_in_mcs) -> float:
        q = self.to_local(p_in_mcs)
        return self.local_sdf(q[0], q[1], q[2])

    def along(self, c0, d):
        """g(s) = sdf(c0 + s·d) as a fast scalar closure (convex in s)."""
        q0 = self.to_local(c0)
        qd = self.rotation.T @ np.asarray(d, dtype=float)
        x0, y0, z0 = (float(v) for v in q0)
        dx, dy, dz = (float(v) for v in qd)
        f = self.local_sdf
        return lambda s: f(x0 + s * dx, y0 + s * dy, z0 + s * dz)


class Box(Primitive):
    def __init__(self, rotation, centre, half_size) -> None:
        super().__init__(rotation, centre)
        self.hx, self.hy, self.hz = (float(v) for v in half_size)

    def local_sdf(self, x: float, y: float, z: float) -> float:
        # exact box SDF: outside distance + inside (negative) part
        qx, qy, qz = abs(x) - self.hx, abs(y) - self.hy, abs(z) - self.hz
        outside = math.sqrt(max(qx, 0.0) ** 2 + max(qy, 0.0) ** 2 + max(qz, 0.0) ** 2)
        return outside + min(max(qx, qy, qz), 0.0)


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


@dataclass
class Body:
    kind: str                                     # "part", "ring_gauge", "tool_probe"
    solid: Primitive
    cutouts: list[Primitive] = field(default_factory=list)

    def sdf(self, p) -> float:
        return max([self.solid.sdf(p)] + [-c.sdf(p) for c in self.cutouts])


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

    start = 0.0 if g(0.0) <= level else brentq(shifted, 0.0, inside, xtol=ROOT_XTOL, rtol=4 * np.finfo(float).eps)
    end = length if g(length) <= level else brentq(shifted, inside, length, xtol=ROOT_XTOL,
                                                   rtol=4 * np.finfo(float).eps)
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


class Scene:
    """Union of bodies. All coordinates MCS, mm."""

    def __init__(self, bodies: list[Body] | None = None) -> None:
        self.bodies = list(bodies or [])

    def subset(self, kinds) -> Scene:
        return Scene([b for b in self.bodies if b.kind in kinds])

    def sdf(self, p_in_mcs) -> float:
        """Composed signed distance (exact on faces; a bound near subtraction rims)."""
        if not self.bodies:
            return math.inf
        return min(b.sdf(p_in_mcs) for b in self.bodies)

    def contact_intervals(self, center0, direction, max_distance: float, radius: float):
        """Sorted, merged intervals of s in [0, max_distance] where the ball touches the solid."""
        c0 = np.asarray(center0, dtype=float)
        d = np.asarray(direction, dtype=float)
        pieces: list[tuple[float, float]] = []
        for body in self.bodies:
            main = _sublevel_interval(body.solid.along(c0, d), radius, max_distance)
            if main is None:
                continue
            body_pieces = [main]
            for cutout in body.cutouts:
                cut = _sublevel_interval(cutout.along(c0, d), -radius, max_distance)
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

    DIN 66217 table: +angle turns the part by −angle about the vertical table axis through
    ``machine.rotary_table.center``: R' = Rz(−c)·R, t' = Rz(−c)·(t − centre) + centre.
    """
    wp = scenario.workpiece
    rot = rpy_matrix(wp.pose.rot)
    trans = np.asarray(wp.pose.trans, dtype=float)
    table = scenario.machine.rotary_table
    if table is None or table_angle == 0.0:
        return rot, trans
    turn = rpy_matrix((0.0, 0.0, -float(table_angle)))
    centre = np.array([table.center[0], table.center[1], 0.0])
    return turn @ rot, turn @ (trans - centre) + centre


def _cut_from_top(depth: float, block_height: float) -> tuple[float, float]:
    """(mid z, half height) in part coordinates of a cut-out from ``depth`` below the top face up
    into the air; through the block when at least as deep as the block."""
    bottom = -_EXTEND if depth >= block_height else -depth
    return (_EXTEND + bottom) / 2.0, (_EXTEND - bottom) / 2.0


def build_scene(scenario, table_angle: float = 0.0) -> Scene:
    """The scenario's true solids (design.md §4 field meanings) as a Scene in MCS."""
    bodies: list[Body] = []
    identity = np.eye(3)
    wp = scenario.workpiece
    if wp is not None and wp.block is not None:
        rot, trans = workpiece_pose(scenario, table_angle)

        def place(p_part) -> np.ndarray:
            return rot @ np.asarray(p_part, dtype=float) + trans

        lx, ly, lz = wp.block.size
        block = Box(rot, place([lx / 2, ly / 2, -lz / 2]), [lx / 2, ly / 2, lz / 2])
        cutouts: list[Primitive] = []
        extras: list[Body] = []
        for f in wp.features:
            if f.type == "hole":
                mid, half = _cut_from_top(f.depth, lz)
                cutouts.append(Cylinder(rot, place([f.center[0], f.center[1], mid]), f.diameter / 2, half))
            elif f.type == "pocket":
                mid, half = _cut_from_top(f.depth, lz)
                cutouts.append(Box(rot, place([f.center[0], f.center[1], mid]),
                                   [f.size[0] / 2, f.size[1] / 2, half]))
            elif f.type == "spigot":
                extras.append(Body("part", Cylinder(rot, place([f.center[0], f.center[1], f.height / 2]),
                                                    f.diameter / 2, f.height / 2)))
            elif f.type == "boss":
                extras.append(Body("part", Box(rot, place([f.center[0], f.center[1], f.height / 2]),
                                               [f.size[0] / 2, f.size[1] / 2, f.height / 2])))
        bodies.append(Body("part", block, cutouts))
        bodies.extend(extras)
    ring = scenario.ring_gauge
    if ring is not None:
        cx, cy, cz = ring.center
        outer = Cylinder(identity, [cx, cy, cz - ring.height / 2], ring.outer_diameter / 2, ring.height / 2)
        bore = Cylinder(identity, [cx, cy, cz - ring.height / 2], ring.diameter / 2, _EXTEND)
        bodies.append(Body("ring_gauge", outer, [bore]))
    tp = scenario.tool_probe
    if tp is not None:
        bodies.append(Body("tool_probe", tool_probe_cylinder(tp)))
    return Scene(bodies)


def outline(scenario, table_angle: float = 0.0) -> dict:
    """The true solids for the machine view (JSON-ready, MCS): block corners, circles, rects."""
    out: dict = {"block": None, "circles": [], "rects": []}
    wp = scenario.workpiece
    if wp is not None and wp.block is not None:
        rot, trans = workpiece_pose(scenario, table_angle)

        def place(x: float, y: float, z: float) -> list[float]:
            return [float(v) for v in rot @ np.array([x, y, z]) + trans]

        axis = [float(v) for v in rot[:, 2]]          # the part's z axis
        lx, ly, lz = wp.block.size
        out["block"] = {"corners": [place(x, y, z) for z in (0.0, -lz) for x, y in
                                    ((0, 0), (lx, 0), (lx, ly), (0, ly))]}
        for f in wp.features:
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
    up = [0.0, 0.0, 1.0]
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


def tool_probe_cylinder(tool_probe, grow_radius: float = 0.0, grow_down: float = 0.0) -> Cylinder:
    """The tool probe cylinder, optionally grown (Minkowski sum with a vertical cutter)."""
    cx, cy, cz = tool_probe.center
    bottom = cz - tool_probe.height - grow_down
    return Cylinder(np.eye(3), [cx, cy, (cz + bottom) / 2], tool_probe.disc_diameter / 2 + grow_radius,
                    (cz - bottom) / 2)

"""Simple polygons for prism parts (design.md §9.8): validation and convex pieces.

Pure 2D geometry (mm, part x/y), no numpy. ``check_simple_polygon`` refuses what is not a simple
polygon with a message naming the field; ``convex_pieces`` cuts a simple polygon (either
orientation) into convex counter-clockwise pieces whose union it is (scene.py builds one convex
prism per piece: the distance to a union is the minimum of the distances, so contact stays exact).
"""

from __future__ import annotations

import math

POLYGON_TOL = 1e-9        # mm: shorter edges, thinner areas and closer non-adjacent edges are refused
_COLLINEAR = 1e-12        # |sin| of the angle at a vertex below which it is a straight vertex
MAX_VERTICES = 100        # validation and decomposition are O(n²)/O(n³): 100 vertices take ~0.4 s


def _cross(o, a, b) -> float:
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def _segments_meet(p1, p2, q1, q2, tol: float) -> bool:
    """Do the closed segments p1p2 and q1q2 come closer than ``tol``?"""
    def seg_point(a, b, p) -> float:
        ab = (b[0] - a[0], b[1] - a[1])
        t = ((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1]) / (ab[0] ** 2 + ab[1] ** 2)
        t = min(max(t, 0.0), 1.0)
        return math.hypot(p[0] - a[0] - t * ab[0], p[1] - a[1] - t * ab[1])

    d1, d2 = _cross(q1, q2, p1), _cross(q1, q2, p2)
    d3, d4 = _cross(p1, p2, q1), _cross(p1, p2, q2)
    if ((d1 > 0 > d2) or (d1 < 0 < d2)) and ((d3 > 0 > d4) or (d3 < 0 < d4)):
        return True                                     # a proper crossing
    return min(seg_point(q1, q2, p1), seg_point(q1, q2, p2), seg_point(p1, p2, q1), seg_point(p1, p2, q2)) < tol


def polygon_area(polygon) -> float:
    """Signed area (shoelace): > 0 counter-clockwise seen from +z."""
    n = len(polygon)
    return 0.5 * sum(polygon[i][0] * polygon[(i + 1) % n][1] - polygon[(i + 1) % n][0] * polygon[i][1]
                     for i in range(n))


def check_simple_polygon(polygon, name: str = "polygon") -> None:
    """ValueError unless ``polygon`` is a simple polygon: 3..MAX_VERTICES vertices, no zero-length edge, no
    edge folding back onto its neighbour, non-adjacent edges apart, a non-zero area."""
    n = len(polygon)
    if n < 3:
        raise ValueError(f"{name}: a polygon needs at least 3 vertices, got {n}")
    if n > MAX_VERTICES:
        raise ValueError(f"{name}: at most {MAX_VERTICES} vertices, got {n}")
    for i in range(n):
        a, b = polygon[i], polygon[(i + 1) % n]
        if math.hypot(b[0] - a[0], b[1] - a[1]) < POLYGON_TOL:
            raise ValueError(f"{name}: vertices {i} and {(i + 1) % n} coincide (zero-length edge)")
    for i in range(n):
        a, b, c = polygon[i - 1], polygon[i], polygon[(i + 1) % n]
        ab = (b[0] - a[0], b[1] - a[1])
        bc = (c[0] - b[0], c[1] - b[1])
        if abs(_cross(a, b, c)) <= POLYGON_TOL * math.hypot(*ab) * math.hypot(*bc) and \
                ab[0] * bc[0] + ab[1] * bc[1] < 0.0:
            raise ValueError(f"{name}: the edges at vertex {i} fold back onto each other (self-intersecting)")
    for i in range(n):
        for j in range(i + 2, n):
            if i == 0 and j == n - 1:
                continue                                # adjacent through the closing edge
            if _segments_meet(polygon[i], polygon[(i + 1) % n], polygon[j], polygon[(j + 1) % n], POLYGON_TOL):
                raise ValueError(f"{name}: edges {i}-{(i + 1) % n} and {j}-{(j + 1) % n} intersect "
                                 f"(the polygon must be simple, not self-intersecting)")
    if abs(polygon_area(polygon)) < POLYGON_TOL:
        raise ValueError(f"{name}: the polygon has no area")
    convex_pieces(polygon)                               # decomposable (ValueError otherwise)


def _turn(o, a, b) -> float:
    """sin of the turn at ``a`` (o -> a -> b): > 0 left (convex for counter-clockwise)."""
    la = math.hypot(a[0] - o[0], a[1] - o[1])
    lb = math.hypot(b[0] - a[0], b[1] - a[1])
    return _cross(o, a, b) / (la * lb)


def _in_triangle(p, a, b, c) -> bool:
    """p inside or on the counter-clockwise triangle abc."""
    return _cross(a, b, p) >= 0.0 and _cross(b, c, p) >= 0.0 and _cross(c, a, p) >= 0.0


def _triangulate(pts) -> list[list[int]]:
    """Ear clipping of a simple counter-clockwise polygon: triangles as vertex index lists."""
    idx = list(range(len(pts)))
    tris: list[list[int]] = []
    while len(idx) > 3:
        for k in range(len(idx)):
            i0, i1, i2 = idx[k - 1], idx[k], idx[(k + 1) % len(idx)]
            turn = _turn(pts[i0], pts[i1], pts[i2])
            if abs(turn) <= _COLLINEAR:
                idx.pop(k)                               # a straight vertex: no triangle, same shape
                break
            if turn < 0.0:
                continue                                 # reflex: no ear
            if any(_in_triangle(pts[j], pts[i0], pts[i1], pts[i2]) for j in idx if j not in (i0, i1, i2)):
                continue
            tris.append([i0, i1, i2])
            idx.pop(k)
            break
        else:                                            # pragma: no cover - a simple polygon always has an ear
            raise ValueError("polygon: cannot be triangulated (is it simple?)")
    if len(idx) == 3 and abs(_turn(pts[idx[0]], pts[idx[1]], pts[idx[2]])) > _COLLINEAR:
        tris.append(idx)
    return tris


def _is_convex(pts, piece: list[int]) -> bool:
    n = len(piece)
    return all(_turn(pts[piece[k - 1]], pts[piece[k]], pts[piece[(k + 1) % n]]) >= -_COLLINEAR for k in range(n))


def _merged(p: list[int], q: list[int]) -> list[int] | None:
    """The union of two pieces sharing an edge (a, b) in p and (b, a) in q, or None."""
    for k in range(len(p)):
        a, b = p[k], p[(k + 1) % len(p)]
        for m in range(len(q)):
            if q[m] == b and q[(m + 1) % len(q)] == a:
                from_b = p[k + 1:] + p[:k + 1]           # b ... a around p
                from_a = q[m + 1:] + q[:m + 1]           # a ... b around q
                return from_b + from_a[1:-1]
    return None


def convex_pieces(polygon) -> list[list[tuple[float, float]]]:
    """Convex pieces (counter-clockwise vertex lists) whose union is the simple ``polygon``
    (any orientation): the polygon itself when convex, else ear-clipped triangles merged while
    their union stays convex (Hertel–Mehlhorn: at most 4× the optimum number of pieces)."""
    pts = [(float(x), float(y)) for x, y in polygon]
    if polygon_area(pts) < 0.0:
        pts.reverse()
    every = list(range(len(pts)))
    if _is_convex(pts, every):
        return [pts]
    pieces = _triangulate(pts)
    merged_any = True
    while merged_any:
        merged_any = False
        for i in range(len(pieces)):
            for j in range(i + 1, len(pieces)):
                union = _merged(pieces[i], pieces[j])
                if union is not None and _is_convex(pts, union):
                    pieces[i] = union
                    del pieces[j]
                    merged_any = True
                    break
            if merged_any:
                break
    return [[pts[k] for k in piece] for piece in pieces]



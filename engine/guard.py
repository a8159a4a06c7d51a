"""Start guard: the whole planned path of a point checked before its first motion (issue 24 §1,
design.md §10.1).

The guard drives a point program (``engine.plan.point_program``) against a *protection model*:
the solids the control knows (workpiece with its holes, pockets, spigots and bosses, spheres,
ring gauge, tool probe; ``engine.guard_model``) and the machine limits. Each positioning move
is a segment of the ball centre's path; it is ``collision`` where the ball (radius r) would
touch a solid on the way (a switch during positioning is alarm 61302, jog-measuring §2.4
step 2), ``limit`` where its end lies outside the axis limits (the NC refuses the block), else
``clear``. A probing move is where contact is wanted: the guard answers it with the first
contact of its own model along the stroke (the latch the program then continues from), or no
switch. Positions the model cannot judge (no model at all) are ``unknown``: the answer says so,
never a silent pass.

The probe's own reach (measuring-math §1.3): after the switch the axes run on by the braking
distance s_b = 1000·v·t + 1000·v²/(2a) + v[m/min]/Kv (v the measuring feed in effect in m/s, t
the signal delay, a the deceleration, Kv the position loop gain), or to the stroke's programmed
end if that comes first. The ball is then deflected by min(pre-travel + s_b, stroke − contact)
past the surface; beyond the probe's permissible deflection the stylus breaks (61302), so such a
probing move is ``overtravel`` (refused). The contact is the model's first contact, else the
nominal surface the plan expects, else the stroke's start (the worst case).

Geometry: signed distances of extrusions (a polygon or circle in its local xy, height along its
local z) and spheres, composed like constructive solid geometry: a body is a solid minus its
cut-outs (sdf = max(sdf_P, −sdf_N)), the model the union of bodies (min). The contact of a ball
moving along c0 + s·d is the first s with sdf(c(s)) ≤ r, found by sphere tracing (the composed
sdf is exact or a lower bound of the distance, so a step of sdf − r never passes a surface).
Pure numpy: no I/O, nothing of the simulator.
"""

from __future__ import annotations

import math
from collections.abc import Generator, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np
import numpy.typing as npt

from engine.types import FloatArray, Latch, MeasuringError, MoveStep, ProbeStep, Step

CONTACT_EPS = 1e-7          # mm: ball this close to a surface = contact
MAX_TRACE_STEPS = 20000
UNSTICK_STEP = 0.01         # mm: a move starting in contact (retract) leaves it in these steps


# --- solids ---------------------------------------------------------------------------------

def _polygon_sdf(points: FloatArray, polygon: FloatArray) -> FloatArray:
    """Signed 2-D distance of ``points`` (n, 2) to a closed polygon (m, 2): < 0 inside."""
    best = np.full(len(points), np.inf)
    inside = np.zeros(len(points), dtype=bool)
    m = len(polygon)
    for i in range(m):
        a, b = polygon[i], polygon[(i + 1) % m]
        e = b - a
        w = points - a
        t = np.clip((w @ e) / float(e @ e), 0.0, 1.0)
        dist = np.linalg.norm(w - t[:, None] * e, axis=1)
        best = np.minimum(best, dist)
        # even-odd rule: a horizontal ray to +x crosses this edge
        cond = (a[1] > points[:, 1]) != (b[1] > points[:, 1])
        with np.errstate(divide="ignore", invalid="ignore"):
            x_cross = a[0] + (points[:, 1] - a[1]) * e[0] / e[1]
        inside ^= cond & (points[:, 0] < x_cross)
    return np.where(inside, -best, best)


def _polygon_distance(px: float, py: float, edges: tuple[tuple[float, ...], ...]) -> float:
    """``_polygon_sdf`` of one point (edges as ``Solid._plain`` has them)."""
    best = math.inf
    inside = False
    for ax, ay, _bx, by, ex, ey, ee in edges:
        wx, wy = px - ax, py - ay
        t = min(max((wx * ex + wy * ey) / ee, 0.0), 1.0) if ee > 0.0 else 0.0
        best = min(best, math.hypot(wx - t * ex, wy - t * ey))
        if (ay > py) != (by > py) and px < ax + (py - ay) * ex / ey:     # even-odd rule
            inside = not inside
    return -best if inside else best


@dataclass(frozen=True)
class Solid:
    """An extrusion (``polygon`` (m, 2) or a circle of ``radius`` in local xy, ``half_height``
    along local z about the local origin) or, with ``sphere``, a ball of ``radius``; placed by
    local→MCS = (``rotation``, ``centre``). ``name`` is what the operator reads ("spigot")."""

    name: str
    centre: FloatArray
    rotation: FloatArray = field(default_factory=lambda: np.eye(3))
    radius: float = 0.0
    half_height: float = 0.0
    polygon: FloatArray | None = None
    sphere: bool = False

    @cached_property
    def _plain(self) -> tuple[tuple[float, ...], tuple[float, ...], tuple[tuple[float, ...], ...] | None, float]:
        """Centre, rotation (row-major), polygon edges (ax, ay, bx, by, ex, ey, |e|²) as floats, and
        the radius of a ball about the centre that holds the solid (``distance``'s bound)."""
        centre = tuple(float(v) for v in self.centre)
        rotation = tuple(float(v) for v in np.asarray(self.rotation, dtype=float).ravel())
        edges = None
        if self.polygon is not None:
            pts = [(float(x), float(y)) for x, y in np.asarray(self.polygon, dtype=float)]
            edges = tuple((a[0], a[1], b[0], b[1], b[0] - a[0], b[1] - a[1], (b[0] - a[0]) ** 2 + (b[1] - a[1]) ** 2)
                          for a, b in zip(pts, pts[1:] + pts[:1], strict=True))
            reach = max(math.hypot(x, y) for x, y in pts)
        else:
            reach = self.radius
        bound = self.radius if self.sphere else math.hypot(reach, self.half_height)
        return centre, rotation, edges, bound

    def lower_bound(self, x: float, y: float, z: float) -> float:
        """A value the signed distance at (x, y, z) is never below: |p − centre| − bound."""
        (cx, cy, cz), _, _, bound = self._plain
        return math.sqrt((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2) - bound

    def distance(self, x: float, y: float, z: float) -> float:
        """``sdf`` of one point in plain floats: the same formulas without numpy's cost per call
        (the sphere tracing asks one point at a time, issue 30 item 3)."""
        (cx, cy, cz), r, edges, _ = self._plain
        dx, dy, dz = x - cx, y - cy, z - cz
        qx = dx * r[0] + dy * r[3] + dz * r[6]          # q = (p − centre) · rotation
        qy = dx * r[1] + dy * r[4] + dz * r[7]
        qz = dx * r[2] + dy * r[5] + dz * r[8]
        if self.sphere:
            return math.sqrt(qx * qx + qy * qy + qz * qz) - self.radius
        d2 = _polygon_distance(qx, qy, edges) if edges is not None else math.hypot(qx, qy) - self.radius
        dzh = abs(qz) - self.half_height
        return min(max(d2, dzh), 0.0) + math.hypot(max(d2, 0.0), max(dzh, 0.0))

    def sdf(self, points: FloatArray) -> FloatArray:
        q = (np.atleast_2d(points) - self.centre) @ self.rotation      # rows: local coordinates
        if self.sphere:
            return np.asarray(np.linalg.norm(q, axis=1) - self.radius)
        if self.polygon is not None:
            d2 = _polygon_sdf(q[:, :2], self.polygon)
        else:
            d2 = np.linalg.norm(q[:, :2], axis=1) - self.radius
        dz = np.abs(q[:, 2]) - self.half_height
        outside = np.hypot(np.maximum(d2, 0.0), np.maximum(dz, 0.0))
        return np.asarray(np.minimum(np.maximum(d2, dz), 0.0) + outside)


@dataclass(frozen=True)
class Body:
    """A solid minus its cut-outs (a block with holes, a ring with its bore)."""

    solid: Solid
    cutouts: tuple[Solid, ...] = ()

    @property
    def name(self) -> str:
        return self.solid.name

    def sdf(self, points: FloatArray) -> FloatArray:
        value = self.solid.sdf(points)
        for cut in self.cutouts:
            value = np.maximum(value, -cut.sdf(points))
        return value

    def distance(self, x: float, y: float, z: float) -> float:
        """``sdf`` of one point; a cut-out too far away to matter (−sdf_N ≤ its bound − |p − c|
        ≤ the value so far) is not evaluated."""
        value = self.solid.distance(x, y, z)
        for cut in self.cutouts:
            if -cut.lower_bound(x, y, z) > value:
                value = max(value, -cut.distance(x, y, z))
        return value


@dataclass(frozen=True)
class ProtectionModel:
    """What the control knows of the work space (MCS): bodies and axis limits.

    ``known`` False: there is no model (a controller without one): every positioning move is
    ``unknown``. ``limits``: axis -> (low, high) of the tool reference point."""

    bodies: tuple[Body, ...] = ()
    limits: dict[str, tuple[float, float]] = field(default_factory=dict)
    known: bool = True
    # first_contact's answers for this model by their exact inputs (issue 30): a point measured
    # again from where its last run ended (the probe returns to its start) asks the same paths
    contacts: dict[tuple[float, ...], tuple[float, str] | None] = field(
        default_factory=dict, compare=False, repr=False)

    def sdf(self, point: npt.ArrayLike) -> tuple[float, str]:
        """(distance, name of the nearest body) of one point."""
        x, y, z = (float(v) for v in np.asarray(point, dtype=float).ravel()[:3])
        return self.distance(x, y, z)

    def distance(self, x: float, y: float, z: float) -> tuple[float, str]:
        """``sdf`` in plain floats; a body whose bound is no nearer than the best so far is skipped
        (it cannot be the nearest)."""
        best, name = math.inf, ""
        for body in self.bodies:
            if body.solid.lower_bound(x, y, z) >= best:
                continue
            v = body.distance(x, y, z)
            if v < best:
                best, name = v, body.name
        return best, name


def first_contact(model: ProtectionModel, c0: npt.ArrayLike, c1: npt.ArrayLike, radius: float
                  ) -> tuple[float, str] | None:
    """First s in [0, |c1 − c0|] where a ball of ``radius`` moving c0 → c1 touches the model,
    with the body's name; None when the way is free. A ball that starts in contact and moves away
    or slides along the surface is free until its next contact; pressing deeper is s = 0."""
    ax, ay, az = (float(v) for v in np.asarray(c0, dtype=float))
    bx, by, bz = (float(v) for v in np.asarray(c1, dtype=float))
    key = (ax, ay, az, bx, by, bz, float(radius))
    known = model.contacts.get(key, _UNKNOWN)
    if known is not _UNKNOWN:
        return known            # type: ignore[return-value]  # the same inputs: the same answer
    hit = _first_contact(model, ax, ay, az, bx, by, bz, float(radius))
    if len(model.contacts) >= CONTACT_MEMO:
        model.contacts.clear()
    model.contacts[key] = hit
    return hit


_UNKNOWN = object()
CONTACT_MEMO = 4096             # answers kept per model


def _first_contact(model: ProtectionModel, ax: float, ay: float, az: float, bx: float, by: float, bz: float,
                   radius: float) -> tuple[float, str] | None:
    length = math.sqrt((bx - ax) ** 2 + (by - ay) ** 2 + (bz - az) ** 2)
    if length <= 0.0 or not model.bodies:
        return None
    dx, dy, dz = (bx - ax) / length, (by - ay) / length, (bz - az) / length

    def at(s: float) -> tuple[float, str]:
        return model.distance(ax + s * dx, ay + s * dy, az + s * dz)

    g, name = at(0.0)
    s = 0.0
    if g - radius <= CONTACT_EPS:
        step = 1e-6
        ahead, _ = at(step)
        if ahead < g - 1e-6 * step:
            return 0.0, name
        while s < length and g - radius <= CONTACT_EPS:
            s = min(length, s + UNSTICK_STEP)
            g, name = at(s)
        if g - radius <= CONTACT_EPS:
            return None
    # the rest of the way at once: the distance changes no faster than the path (1-Lipschitz), so
    # with the gap at s and the gap at the end the ball stays > CONTACT_EPS clear when the two
    # exceed the way left by 2·CONTACT_EPS (a retract, a move through free space: no stepping)
    end_gap = at(length)[0] - radius
    for _ in range(MAX_TRACE_STEPS):          # g, name: the distance at s
        gap = g - radius
        if gap <= CONTACT_EPS:
            return s, name
        if gap + end_gap > (length - s) + 2.0 * CONTACT_EPS:
            return None
        s += gap
        if s > length:
            return None
        g, name = at(s)
    return s, name          # a grazing pass that never resolves: treated as a contact


# --- the probe's own reach (measuring-math §1.3) -----------------------------------------------

def braking_distance(feed_mm_min: float, latency_s: float, decel_m_s2: float, kv: float) -> float:
    """s_b [mm] = 1000·v·t + 1000·v²/(2·a) + Δs, Δs = v[m/min]/Kv (measuring-math §1.3): ``feed``
    in mm/min (v in m/s for the first two terms, m/min for the following error), t in s, a in
    m/s², Kv in (m/min)/mm."""
    v_m_s = float(feed_mm_min) / 60000.0
    v_m_min = float(feed_mm_min) / 1000.0
    return 1000.0 * v_m_s * float(latency_s) + 1000.0 * v_m_s * v_m_s / (2.0 * float(decel_m_s2)) + v_m_min / float(kv)


@dataclass(frozen=True)
class Braking:
    """What the control knows of its braking behind a switch and the probe's permissible
    deflection (mm); ``override`` the feed override (percent) the measuring feed runs at;
    ``pretravel`` (mm) what the ball moves past the contact before it switches."""

    latency_s: float
    decel: float
    kv: float
    max_deflection: float
    override: float = 100.0
    pretravel: float = 0.0

    def feed_in_effect(self, feed: float) -> float:
        return float(feed) * float(self.override) / 100.0

    def distance(self, feed: float) -> float:
        """s_b at the programmed ``feed`` (mm/min) under the override."""
        return braking_distance(self.feed_in_effect(feed), self.latency_s, self.decel, self.kv)

    def deflection(self, feed: float, past_contact: float) -> float:
        """How far the ball is pushed past the surface: pre-travel + s_b, at most the stroke's
        remaining length ``past_contact`` behind the contact (the axes stop at the block's end)."""
        return min(self.pretravel + self.distance(feed), max(0.0, float(past_contact)))


# --- the check ------------------------------------------------------------------------------

@dataclass(frozen=True)
class Placement:
    """Where the plan's coordinates lie in the model: ball centre (MCS) = rotation·p + ball_shift,
    axes (tool reference point, MCS) = rotation·p + axes_shift; ``ball_radius`` of the probe."""

    rotation: FloatArray
    ball_shift: FloatArray
    axes_shift: FloatArray
    ball_radius: float

    def ball(self, p: npt.ArrayLike) -> FloatArray:
        return np.asarray(self.rotation @ np.asarray(p, dtype=float) + self.ball_shift)

    def axes(self, p: npt.ArrayLike) -> FloatArray:
        return np.asarray(self.rotation @ np.asarray(p, dtype=float) + self.axes_shift)

    def back(self, ball_mcs: npt.ArrayLike) -> FloatArray:
        return np.asarray(self.rotation.T @ (np.asarray(ball_mcs, dtype=float) - self.ball_shift))


@dataclass(frozen=True)
class Reach:
    """A probing move's braking distance s_b, the deflection it gives and the permissible one (mm)."""

    braking: float
    deflection: float
    max_deflection: float

    @property
    def beyond(self) -> bool:
        return self.deflection > self.max_deflection + 1e-9


REFUSED = ("collision", "limit", "overtravel")


@dataclass(frozen=True)
class Segment:
    """One planned motion: ``kind`` "move"/"probe", plan coordinates, and the guard's verdict
    (``clear``, ``collision``, ``limit``, ``unknown``; a probing move ``contact``, ``no_switch``
    or ``overtravel``: its braking would push the probe beyond its permissible deflection);
    ``where`` the contact point (plan coordinates) and ``body`` what is hit; ``braking`` the
    braking distance s_b and ``deflection`` the deflection it gives (mm) of a probing move."""

    index: int
    label: str
    kind: str
    start: FloatArray
    end: FloatArray
    verdict: str
    body: str = ""
    where: FloatArray | None = None
    axis: str = ""
    feed: float | None = None
    reach: Reach | None = None

    @property
    def braking(self) -> float | None:
        return None if self.reach is None else self.reach.braking

    @property
    def deflection(self) -> float | None:
        return None if self.reach is None else self.reach.deflection

    @property
    def max_deflection(self) -> float | None:
        return None if self.reach is None else self.reach.max_deflection

    @property
    def refused(self) -> bool:
        return self.verdict in REFUSED


@dataclass(frozen=True)
class GuardReport:
    segments: tuple[Segment, ...]
    complete: bool           # the program ran to its end (False: refused, or it stopped itself)
    # the probing directions the program asked for, in its order (plan coordinates)
    probe_directions: tuple[FloatArray, ...] = ()

    @property
    def refusal(self) -> Segment | None:
        return next((s for s in self.segments if s.refused), None)

    @property
    def unknown(self) -> bool:
        return any(s.verdict == "unknown" for s in self.segments)


AXES = ("X", "Y", "Z")


def _limit_axis(model: ProtectionModel, axes: FloatArray) -> str:
    for i, axis in enumerate(AXES):
        bounds = model.limits.get(axis)
        if bounds is not None and not bounds[0] - 1e-9 <= float(axes[i]) <= bounds[1] + 1e-9:
            return axis
    return ""


def check_program(program: Generator[Step, Latch | None, object], start: npt.ArrayLike,
                  model: ProtectionModel, placement: Placement, braking: Braking | None = None) -> GuardReport:
    """Drive ``program`` from ``start`` (plan coordinates) against ``model``; stop at the first
    refused segment. Probing moves are answered with the model's first contact along the stroke
    (the latch = the NC reference there), so the path after a touch is the one the machine will
    take when the part is where the model says. With ``braking`` every probing move is also
    checked against the probe's permissible deflection (``probe_reach``)."""
    pos = np.asarray(start, dtype=float)
    segments: list[Segment] = []
    r = placement.ball_radius
    reply: Latch | None = None
    complete = False
    directions: list[FloatArray] = []
    try:
        while True:
            step = program.send(reply)
            reply = None
            if isinstance(step, MoveStep):
                target = np.asarray(step.target, dtype=float)
                seg = _move_segment(len(segments) + 1, step.label, pos, target, model, placement)
                segments.append(seg)
                if seg.refused:
                    break
                pos = target
            elif isinstance(step, ProbeStep):
                d = np.asarray(step.direction, dtype=float)
                directions.append(d)
                end = pos + float(step.distance) * d
                if not model.known:
                    hit_s: float | None = step.expected if step.expected is not None else step.distance / 2.0
                    body, verdict = "", "unknown"
                else:
                    hit = first_contact(model, placement.ball(pos), placement.ball(end), r)
                    hit_s, body = (hit if hit is not None else (None, ""))
                    verdict = "contact" if hit is not None else "no_switch"
                axis = _limit_axis(model, placement.axes(end))
                if axis and hit_s is None:
                    segments.append(Segment(len(segments) + 1, step.label, "probe", pos, end, "limit", axis=axis))
                    break
                where = None if hit_s is None else pos + float(hit_s) * d
                reach = probe_reach(step, hit_s if verdict == "contact" else None, braking)
                if reach is not None and reach.beyond:
                    verdict = "overtravel"
                seg = Segment(len(segments) + 1, step.label, "probe", pos, end, verdict, body, where,
                              feed=float(step.feed), reach=reach)
                segments.append(seg)
                if seg.refused:
                    break
                if where is not None:
                    pos = where
                    reply = Latch(triggered=True, rec=where.copy())
                else:
                    pos = end
                    reply = Latch(triggered=False)
    except StopIteration:
        complete = True
    except MeasuringError:
        pass                 # the program stops itself (no switch: 61301) before any harm
    return GuardReport(tuple(segments), complete, tuple(directions))


def probe_reach(step: ProbeStep, contact_s: float | None, braking: Braking | None) -> Reach | None:
    """The reach of a probing move; None without braking data. ``contact_s``: the travel to the
    first contact (None: the nominal surface the plan expects, else the stroke's start, the
    worst case)."""
    if braking is None:
        return None
    if contact_s is None:
        contact_s = step.expected if step.expected is not None else 0.0
    return Reach(braking.distance(step.feed), braking.deflection(step.feed, float(step.distance) - float(contact_s)),
                 float(braking.max_deflection))


def _move_segment(index: int, label: str, a: FloatArray, b: FloatArray, model: ProtectionModel,
                  placement: Placement) -> Segment:
    axis = _limit_axis(model, placement.axes(b))
    if axis:
        return Segment(index, label, "move", a, b, "limit", axis=axis)
    if not model.known:
        return Segment(index, label, "move", a, b, "unknown")
    hit = first_contact(model, placement.ball(a), placement.ball(b), placement.ball_radius)
    if hit is None:
        return Segment(index, label, "move", a, b, "clear")
    s, body = hit
    d = b - a
    where = a + (s / float(np.linalg.norm(d))) * d if np.linalg.norm(d) > 0 else a
    return Segment(index, label, "move", a, b, "collision", body, where)


def segments_to_api(segments: Sequence[Segment], axes: Sequence[str] = AXES, point: int | None = None
                    ) -> list[dict[str, Any]]:
    def xyz(v: FloatArray | None) -> dict[str, float] | None:
        return None if v is None else {a: float(x) for a, x in zip(axes, v, strict=True)}

    def reach(s: Segment) -> dict[str, Any]:
        if s.kind != "probe":
            return {}
        return {"feed": s.feed, "braking": s.braking, "deflection": s.deflection, "max_deflection": s.max_deflection}

    return [{"point": point, "step": s.index, "label": s.label, "kind": s.kind, "from": xyz(s.start),
             "to": xyz(s.end), "verdict": s.verdict, "body": s.body or None, "at": xyz(s.where),
             "axis": s.axis or None, **reach(s)} for s in segments]

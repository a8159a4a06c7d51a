"""Analytic test world for the plan tests: exact switching positions of a ball probe/tool.

Independent of the engine's evaluation: contacts are solved from the geometry (planes,
circles) in closed form; pre-travel per direction as design.md §5 (sum d_i² p(axis, sign)).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from engine.frames import rot_z
from engine.plan import run_program
from engine.types import Latch, MoveStep, ProbeStep, SpindleStep


@dataclass
class HalfSpace:
    """Material where n·x < k (n: outward unit normal). ``r``: own contact radius (tool tip: 0)."""

    normal: np.ndarray
    k: float
    r: float | None = None

    def contact(self, c0, d, r):
        r = r if self.r is None else self.r
        nd = float(self.normal @ d)
        if nd >= 0.0:
            return None
        t = (float(self.normal @ c0) - self.k - r) / (-nd)
        return t if t >= -1e-12 else None


def _cylinder_roots(centre, p, c0, d, radius):
    """Travel t (ascending) at which c0 + t·d lies at ``radius`` from the axis (centre, p);
    None when the travel is along the axis or misses the circle."""
    rel = c0 - centre
    rel = rel - float(rel @ p) * p
    dd = d - float(d @ p) * p
    a = float(dd @ dd)
    if a == 0.0:
        return None
    b = 2.0 * float(rel @ dd)
    c = float(rel @ rel) - radius ** 2
    disc = b * b - 4 * a * c
    if disc < 0:
        return None
    return (-b - np.sqrt(disc)) / (2 * a), (-b + np.sqrt(disc)) / (2 * a)


@dataclass
class Bore:
    """Inner cylinder (axis along ``p``) of radius R around ``centre``; the ball moves inside."""

    centre: np.ndarray
    radius: float
    p: np.ndarray

    def contact(self, c0, d, r):
        roots = _cylinder_roots(self.centre, self.p, c0, d, self.radius - r)
        return None if roots is None else roots[1]          # leaving the inner circle


@dataclass
class Spigot:
    """Outer cylinder (axis ``p``) of radius R, top at height ``top`` (ball centre below -> contact)."""

    centre: np.ndarray
    radius: float
    p: np.ndarray
    top: float

    def contact(self, c0, d, r):
        if float(c0 @ self.p) >= self.top:
            return None
        roots = _cylinder_roots(self.centre, self.p, c0, d, self.radius + r)
        if roots is None:
            return None
        t = roots[0]                                        # entering the outer circle
        return t if t >= -1e-12 else None


@dataclass
class World:
    shapes: list
    r: float = 2.0                                 # true ball radius (tool: tool radius in-plane)
    skew: np.ndarray = field(default_factory=lambda: np.zeros(3))   # ball − reference at spindle 0°
    pretravel: dict = field(default_factory=dict)  # "X+": δ ...
    miss: int = 0                                  # first ``miss`` probings do not switch
    spindle_angle: float = 0.0
    spindle_speed: float = 0.0
    probes: list = field(default_factory=list)
    moves: list = field(default_factory=list)

    def ball_offset(self) -> np.ndarray:
        return rot_z(self.spindle_angle) @ self.skew

    def delta(self, d) -> float:
        total = 0.0
        for i, axis in enumerate("XYZ"):
            if d[i] != 0.0:
                total += d[i] ** 2 * self.pretravel.get(axis + ("+" if d[i] > 0 else "-"), 0.0)
        return total

    def switch(self, rec0, d, distance):
        c0 = rec0 + self.ball_offset()
        ts = [t for s in self.shapes if (t := s.contact(c0, d, self.r)) is not None]
        if not ts:
            return None
        t = min(ts) + self.delta(d)
        return t if t <= distance else None


def drive(program, start, world: World):
    """Run a point program against the world; returns (stored point, steps)."""
    pos = np.asarray(start, dtype=float)

    def respond(step):
        nonlocal pos
        if isinstance(step, MoveStep):
            world.moves.append((pos.copy(), np.asarray(step.target, float).copy(), world.spindle_angle))
            pos = np.asarray(step.target, dtype=float)
        elif isinstance(step, SpindleStep):
            if step.angle is not None:
                world.spindle_angle = step.angle
            if step.speed is not None:
                world.spindle_speed = step.speed
        elif isinstance(step, ProbeStep):
            d = np.asarray(step.direction, float)
            t = world.switch(pos, d, step.distance)
            world.probes.append((pos.copy(), step))
            if world.miss > 0 or t is None:
                world.miss -= 1
                pos = pos + step.distance * d
                return Latch(triggered=False)
            pos = pos + t * d
            return Latch(triggered=True, rec=pos.copy(), latched_mcs=pos.copy())
        return None

    steps: list = []
    return run_program(program, respond, steps), steps

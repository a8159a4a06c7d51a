"""Rotary axes as lines (design.md §10.6): where a swivel head puts the tool, where a table puts the part.

Pure functions of the simulated machine (own helpers: the simulator never imports the engine).
An axis is a line at the zero position of every rotary axis, ``point`` + s·``direction``; turning
it by θ maps x -> p + R(d, θ)·(x − p) (a screw without pitch; product of exponentials, Lynch &
Park, "Modern Robotics" §4.1). A head's outer axis carries the inner one:
T_head(θ1, θ2) = T_second(θ2) ∘ T_first(θ1), applied to the vector from the tool reference point
(scenario.SwivelHead). With the ideal lines (through the reference point along X/Y/Z) this is the
wave-2 model R_head = R_second·R_first exactly.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

from .physics import head_angles_for as ideal_head_angles

Line = tuple[np.ndarray, np.ndarray]          # (point, unit direction)
_SOLVE_ITERATIONS = 30


def _cos_sin(deg: float) -> tuple[float, float]:
    """cos/sin of ``deg`` degrees, exact at multiples of 90° (the zero position stays exact)."""
    d = float(deg) % 360.0
    exact = {0.0: (1.0, 0.0), 90.0: (0.0, 1.0), 180.0: (-1.0, 0.0), 270.0: (0.0, -1.0)}
    if d in exact:
        return exact[d]
    rad = math.radians(float(deg))
    return math.cos(rad), math.sin(rad)


def rotation_about(direction, deg: float) -> np.ndarray:
    """Rodrigues: R = cosθ·I + sinθ·[d]× + (1 − cosθ)·d·dᵀ, right-handed about unit ``direction``."""
    d = np.asarray(direction, dtype=float)
    c, s = _cos_sin(deg)
    cross = np.array([[0.0, -d[2], d[1]], [d[2], 0.0, -d[0]], [-d[1], d[0], 0.0]])
    return c * np.eye(3) + s * cross + (1.0 - c) * np.outer(d, d)


def as_line(line) -> Line:
    """A scenario.AxisLine (or a ``{"point", "direction"}`` dict) as (point, unit direction)."""
    point = line["point"] if isinstance(line, Mapping) else line.point
    direction = line["direction"] if isinstance(line, Mapping) else line.direction
    d = np.asarray(direction, dtype=float)
    return np.asarray(point, dtype=float), d / np.linalg.norm(d)


def turn(line: Line, deg: float) -> tuple[np.ndarray, np.ndarray]:
    """(R, t) of x -> p + R·(x − p) = R·x + (I − R)·p for the axis ``line`` at ``deg``."""
    point, direction = line
    rotation = rotation_about(direction, deg)
    return rotation, point - rotation @ point


def head_transform(lines: Mapping[str, Line], head_axes: Sequence[str], angles: Sequence[float] | np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray]:
    """(R_head, shift): a vector v from the tool reference point goes to R_head·v + shift
    (T_second(θ2) ∘ T_first(θ1)); ``shift`` is where the spindle nose moves, 0 for ideal lines."""
    (first, second), (t1, t2) = head_axes, angles
    r1, s1 = turn(lines[first], float(t1))
    r2, s2 = turn(lines[second], float(t2))
    return r2 @ r1, r2 @ s1 + s2


def table_transform(line: Line, deg: float) -> tuple[np.ndarray, np.ndarray]:
    """(R, t) part placement of a rotary table at ``deg``: it turns the part by −deg (DIN 66217)."""
    return turn(line, -float(deg))


def head_angles_for(lines: Mapping[str, Line], head_axes: Sequence[str], n, current=(0.0, 0.0)
                    ) -> list[tuple[float, float]]:
    """All (θ1, θ2) with R_head·ẑ = n for these lines: the ideal head's closed-form solutions
    (physics.head_angles_for) refined by Gauss-Newton on R_head(θ)·ẑ − n (the lines' directions
    differ from X/Y/Z by µrad, so the ideal solution starts within reach). A candidate that does not
    converge to 1e-12 is dropped."""
    target = np.asarray(n, dtype=float) / np.linalg.norm(n)
    out = []
    for cand in ideal_head_angles(head_axes, target, current):
        theta = np.array(cand, dtype=float)
        for _ in range(_SOLVE_ITERATIONS):
            rot, _ = head_transform(lines, head_axes, theta)
            residual = rot[:, 2] - target
            if float(np.linalg.norm(residual)) < 1e-14:
                break
            jac = np.empty((3, 2))
            for k in range(2):
                step = np.zeros(2)
                step[k] = 1e-6
                jac[:, k] = (head_transform(lines, head_axes, theta + step)[0][:, 2]
                             - head_transform(lines, head_axes, theta - step)[0][:, 2]) / 2e-6
            delta, *_ = np.linalg.lstsq(jac, -residual, rcond=None)
            theta = theta + delta
        rot, _ = head_transform(lines, head_axes, theta)
        if float(np.linalg.norm(rot[:, 2] - target)) < 1e-12:
            out.append((float(theta[0]), float(theta[1])))
    return out

"""Probe physics of the simulator (measuring-math §1.3, §1.7; design.md §5).

Pure functions, no state. Own small rotation helper: the simulator must not import the
engine (it must not "know the answer" from the same code).
"""

from __future__ import annotations

import math

import numpy as np

Z_UNIT = np.array([0.0, 0.0, 1.0])


def rpy_matrix(rot_deg) -> np.ndarray:
    """R = Rz(c)·Ry(b)·Rx(a) for rot = (a about X, b about Y, c about Z) in degrees (design.md §3)."""
    a, b, c = (math.radians(float(v)) for v in rot_deg)
    ca, sa, cb, sb, cc, sc = math.cos(a), math.sin(a), math.cos(b), math.sin(b), math.cos(c), math.sin(c)
    rx = np.array([[1.0, 0.0, 0.0], [0.0, ca, -sa], [0.0, sa, ca]])
    ry = np.array([[cb, 0.0, sb], [0.0, 1.0, 0.0], [-sb, 0.0, cb]])
    rz = np.array([[cc, -sc, 0.0], [sc, cc, 0.0], [0.0, 0.0, 1.0]])
    return rz @ ry @ rx


def eccentricity_at(eccentricity_xy, spindle_angle_deg: float) -> np.ndarray:
    """e(φ) = Rot_Z(φ)·e_true: the skew turns with SPOS (measuring-math §1.7)."""
    phi = math.radians(spindle_angle_deg)
    ex, ey = float(eccentricity_xy[0]), float(eccentricity_xy[1])
    return np.array([ex * math.cos(phi) - ey * math.sin(phi), ex * math.sin(phi) + ey * math.cos(phi), 0.0])


def ball_centre(axes_xyz, true_length: float, eccentricity_xy, spindle_angle_deg: float,
                head=None) -> np.ndarray:
    """True ball centre = A + R_head·(e(φ) − L·ẑ) (design.md §4 scenario, A = tool reference point,
    R_head = identity without a swivel head, scenario.SwivelHead)."""
    offset = eccentricity_at(eccentricity_xy, spindle_angle_deg) - true_length * Z_UNIT
    if head is not None:
        offset = np.asarray(head, dtype=float) @ offset
    return np.asarray(axes_xyz, dtype=float) + offset


def _axis_rotation(axis: str, deg: float) -> np.ndarray:
    rot = {"A": (deg, 0.0, 0.0), "B": (0.0, deg, 0.0), "C": (0.0, 0.0, deg)}[axis]
    return rpy_matrix(rot)


def head_rotation(head_axes, angles_deg) -> np.ndarray:
    """R_head = R_second(θ_second)·R_first(θ_first) (scenario.SwivelHead; axes alphabetical)."""
    (first, second), (t1, t2) = head_axes, angles_deg
    return _axis_rotation(second, float(t2)) @ _axis_rotation(first, float(t1))


def head_angles_for(head_axes, n, current=(0.0, 0.0)) -> list[tuple[float, float]]:
    """All (θ_first, θ_second) in degrees with R_head·ẑ = n (unit), before limit/wrap choice.

    A/B: n = (cosA·sinB, −sinA, cosA·cosB); A/C: n = (sinA·sinC, −sinA·cosC, cosA);
    B/C: n = (sinB·cosC, sinB·sinC, cosB). Near the pole (inner angle 0) the outer angle
    is free: it stays where it is.
    """
    nx, ny, nz = (float(v) for v in np.asarray(n, dtype=float) / np.linalg.norm(n))
    out = []
    if tuple(head_axes) == ("A", "B"):
        a = -math.asin(max(-1.0, min(1.0, ny)))
        for a_i in (a, math.pi - a):
            ca = math.cos(a_i)
            if abs(ca) < 1e-12:
                out.append((math.degrees(a_i), float(current[1])))
            else:
                out.append((math.degrees(a_i), math.degrees(math.atan2(nx / ca, nz / ca))))
        return out
    inner = math.acos(max(-1.0, min(1.0, nz)))
    for t in (inner, -inner):
        s = math.sin(t)
        if abs(s) < 1e-9:
            out.append((math.degrees(t), float(current[1])))
        elif tuple(head_axes) == ("A", "C"):
            out.append((math.degrees(t), math.degrees(math.atan2(nx / s, -ny / s))))
        else:                                            # ("B", "C")
            out.append((math.degrees(t), math.degrees(math.atan2(ny / s, nx / s))))
    return out


def pretravel_along(direction, table: dict[str, float]) -> float:
    """p(d) = Σ d_i²·p(axis_i, sign d_i); Z+ falls back to Z− (design.md §5)."""
    d = np.asarray(direction, dtype=float)
    total = 0.0
    for i, axis in enumerate("XYZ"):
        if d[i] == 0.0:
            continue
        key = f"{axis}{'+' if d[i] > 0 else '-'}"
        value = table.get(key)
        if value is None and key == "Z+":
            value = table.get("Z-")
        total += d[i] * d[i] * float(value or 0.0)
    return total


def braking_distance(feed_mm_min: float, latency_s: float, decel_m_s2: float, kv: float) -> float:
    """s_b [mm] = 1000·v·t + 1000·v²/(2a) + v[m/min]/Kv (measuring-math §1.3, v in m/s)."""
    v_m_s = feed_mm_min / 60000.0
    v_m_min = feed_mm_min / 1000.0
    return 1000.0 * v_m_s * latency_s + 1000.0 * v_m_s * v_m_s / (2.0 * decel_m_s2) + v_m_min / kv


def latency_path(feed_mm_min: float, latency_s: float) -> float:
    """Path travelled between switch and latch: e_lat = v·t (measuring-math §1.5), mm."""
    return feed_mm_min / 60.0 * latency_s

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


def ball_centre(axes_xyz, true_length: float, eccentricity_xy, spindle_angle_deg: float) -> np.ndarray:
    """True ball centre = A + e(φ) − L·ẑ (design.md §4 scenario, A = tool reference point)."""
    return np.asarray(axes_xyz, dtype=float) + eccentricity_at(eccentricity_xy, spindle_angle_deg) \
        - true_length * Z_UNIT


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

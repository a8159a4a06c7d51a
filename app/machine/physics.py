"""Probe physics of the simulator (measuring-math §1.3, measuring-math §1.7; design.md §5).

Pure functions, no state. Own small rotation helper: the simulator must not import the
engine (it must not "know the answer" from the same code).
"""

from __future__ import annotations

import math

import numpy as np

Z_UNIT = np.array([0.0, 0.0, 1.0])

# Probe frame -> MCS at SPOS 0 for each spindle axis (scenario machine.spindle_axis): the probe's
# own (x, y, z) are the (a, o, p) of the plane whose infeed is the spindle axis (measuring-math
# measuring-math §0.1): Z -> (X, Y, Z) as G17, Y -> (Z, X, Y) as G18, X -> (Y, Z, X) as G19. Columns = the probe
# axes in MCS; all three are proper rotations (cyclic permutations), probe z = +spindle axis.
SPINDLE_MOUNTS = {
    "Z": np.eye(3),
    "Y": np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]),
    "X": np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
}
PRETRAVEL_FRAMES = ("probe", "machine")


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
                head=None, mount=None) -> np.ndarray:
    """True ball centre = A + R_head·M·(e(φ) − L·ẑ) (design.md §4 scenario, A = tool reference point,
    R_head = identity without a swivel head, scenario.SwivelHead; M = SPINDLE_MOUNTS[spindle_axis],
    identity for the vertical spindle)."""
    offset = eccentricity_at(eccentricity_xy, spindle_angle_deg) - true_length * Z_UNIT
    if mount is not None:
        offset = np.asarray(mount, dtype=float) @ offset
    if head is not None:
        offset = np.asarray(head, dtype=float) @ offset
    return np.asarray(axes_xyz, dtype=float) + offset


def _cos_sin_deg(deg: float) -> tuple[float, float]:
    """cos/sin of ``deg`` degrees, exact at the multiples of 90° (SPOS 0/90/180/270)."""
    deg = float(deg) % 360.0
    exact = {0.0: (1.0, 0.0), 90.0: (0.0, 1.0), 180.0: (-1.0, 0.0), 270.0: (0.0, -1.0)}
    if deg in exact:
        return exact[deg]
    rad = math.radians(deg)
    return math.cos(rad), math.sin(rad)


def probe_rotation(spindle_angle_deg: float, mount=None, head=None) -> np.ndarray:
    """Probe frame -> MCS: R = R_head·M·Rz(φ).

    The probe body turns with SPOS about its own z (the spindle axis, tip -> spindle) by +φ,
    counter-clockwise seen from the spindle (right-hand rule), exactly as the eccentricity
    e(φ) = Rz(φ)·e_true does; M (SPINDLE_MOUNTS) puts the probe on a horizontal spindle, R_head
    turns it with a swivel head. A direction d given in MCS reads Rᵀ·d in the probe's frame.
    """
    c, s = _cos_sin_deg(spindle_angle_deg)
    rotation = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    if mount is not None:
        rotation = np.asarray(mount, dtype=float) @ rotation
    if head is not None:
        rotation = np.asarray(head, dtype=float) @ rotation
    return rotation


def _axis_rotation(axis: str, deg: float) -> np.ndarray:
    rot = {"A": (deg, 0.0, 0.0), "B": (0.0, deg, 0.0), "C": (0.0, 0.0, deg)}[axis]
    return rpy_matrix(rot)


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


def lobing_along(direction_probe, harmonics) -> float:
    """Σ A·cos(n(θ − φ))·(d_x² + d_y²): the lobes of the probe body for a travel d in the probe's
    own frame, θ its angle in the probe's X/Y plane, weighted like the table's X/Y entries."""
    d = np.asarray(direction_probe, dtype=float)
    in_plane = float(d[0] * d[0] + d[1] * d[1])
    if not harmonics or in_plane == 0.0:
        return 0.0
    theta = np.arctan2(d[1], d[0])
    return in_plane * sum(h.amplitude * float(np.cos(h.order * (theta - np.radians(h.phase)))) for h in harmonics)


def pretravel_in_probe(direction_mcs, table: dict[str, float], probe2mcs, harmonics=()) -> float:
    """p(Rᵀ·d): the pre-travel table keyed by the probe's own axes (plus its lobing harmonics),
    d in MCS, R = probe_rotation."""
    d_probe = np.asarray(probe2mcs, dtype=float).T @ np.asarray(direction_mcs, dtype=float)
    return pretravel_along(d_probe, table) + lobing_along(d_probe, harmonics)


def braking_distance(feed_mm_min: float, latency_s: float, decel_m_s2: float, kv: float) -> float:
    """s_b [mm] = 1000·v·t + 1000·v²/(2a) + v[m/min]/Kv (measuring-math §1.3, v in m/s)."""
    v_m_s = feed_mm_min / 60000.0
    v_m_min = feed_mm_min / 1000.0
    return 1000.0 * v_m_s * latency_s + 1000.0 * v_m_s * v_m_s / (2.0 * decel_m_s2) + v_m_min / kv


def latency_path(feed_mm_min: float, latency_s: float) -> float:
    """Path travelled between switch and latch: e_lat = v·t (measuring-math §1.5), mm."""
    return feed_mm_min / 60.0 * latency_s

"""Test helpers: independent truth (scipy rotations, plain geometry), small scenarios."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from app.machine.scenario import load_scenario


def rotation(rot_deg) -> np.ndarray:
    """R = Rz(c)·Ry(b)·Rx(a): intrinsic Z-Y-X Euler angles (independent of the simulator's helper)."""
    a, b, c = rot_deg
    return Rotation.from_euler("ZYX", [c, b, a], degrees=True).as_matrix()


def plane_contact(c0, d, point_on_plane, outward_normal, radius) -> float:
    """s where a ball centre c0 + s·d reaches distance ``radius`` from the plane (from outside)."""
    n = np.asarray(outward_normal, float)
    return (radius - n @ (np.asarray(c0, float) - point_on_plane)) / (n @ np.asarray(d, float))


def circle_contact_inside(c0_xy, d_xy, centre_xy, reach) -> float:
    """Positive s where |c0 + s·d − centre| = reach (start inside the circle)."""
    p = np.asarray(c0_xy, float) - centre_xy
    d = np.asarray(d_xy, float)
    a, b, c = d @ d, 2 * p @ d, p @ p - reach**2
    return (-b + np.sqrt(b * b - 4 * a * c)) / (2 * a)


def circle_contact_outside(c0_xy, d_xy, centre_xy, reach) -> float:
    p = np.asarray(c0_xy, float) - centre_xy
    d = np.asarray(d_xy, float)
    a, b, c = d @ d, 2 * p @ d, p @ p - reach**2
    return (-b - np.sqrt(b * b - 4 * a * c)) / (2 * a)


def scenario(**overrides):
    """A plain test scenario: no pre-travel, eccentricity, latency or noise unless asked for."""
    data = {
        "seed": 3,
        "machine": {"limits": {"X": [-100, 1000], "Y": [-100, 800], "Z": [-500, 100]},
                    "latency_s": 0.0, "time_scale": 0.0},
        "probe": {"t": 9, "ball_diameter": 4.0, "length": 100.0, "max_deflection": 5.0},
        "workpiece": {"pose": {"trans": [200.0, 150.0, -150.0], "rot": [0.0, 0.0, 17.0]},
                      "features": [{"type": "block", "size": [200, 120, 60]},
                                   {"type": "hole", "center": [40, 30], "diameter": 20, "depth": 25},
                                   {"type": "spigot", "center": [150, 60], "diameter": 30, "height": 15}]},
        "ring_gauge": {"center": [700, 100, -200], "diameter": 25.0, "height": 20},
        "tool_probe": {"center": [800, 600, -200], "disc_diameter": 20.0, "height": 40},
        "tools": [{"t": 1, "length": 85.0, "radius": 5.0}],
        "start": {"X": 0.0, "Y": 0.0, "Z": 50.0},
    }
    for key, value in overrides.items():
        if isinstance(value, dict) and isinstance(data.get(key), dict):
            data[key] = {**data[key], **value}
        else:
            data[key] = value
    return load_scenario(data)

"""Time per evaluation of every engine task (run: python bench/bench_engine.py).

Builds ideal G17 touches of a block corner, a bore, a spigot, a pocket, hole patterns and a
tilted plane, then times engine.evaluate per task and the calibration / tool functions.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from engine.calibration import calibrate_length, calibrate_radius  # noqa: E402
from engine.plan_base import RingCalibrationPoint, RingPass  # noqa: E402
from engine.planes import PLANES  # noqa: E402
from engine.tasks import evaluate  # noqa: E402
from engine.toolmeasure import calibrate_tool_probe, spindle_speed_feeds, tool_length  # noqa: E402
from engine.types import CirclePoint, EdgePoint, ProbeRecord, RectPoint, Touch  # noqa: E402

G17 = PLANES["G17"]
R = 2.0
PROBE = ProbeRecord(ball_diameter=4.0)


def edge(centre, d):
    c, d = np.array(centre, float), np.array(d, float)
    return EdgePoint(Touch(ball_centre=c, direction=d, surface=c + R * d))


def circle(m, radius, hole=True):
    touches = []
    for d in ((1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0)):
        d = np.array(d, float)
        c = np.array([m[0], m[1], -5.0]) + (radius - R if hole else -(radius + R)) * d
        touches.append(Touch(ball_centre=c, direction=d, surface=c + R * d))
    return CirclePoint(center=np.zeros(3), diameter=0.0, touches=tuple(touches))


def rect(m, length, width, pocket=True):
    touches = []
    for d, half in (((1, 0, 0), length / 2), ((-1, 0, 0), length / 2), ((0, 1, 0), width / 2),
                    ((0, -1, 0), width / 2)):
        d = np.array(d, float)
        s = np.array([m[0], m[1], -5.0]) + (half if pocket else -half) * d
        touches.append(Touch(ball_centre=s - R * d, direction=d, surface=s))
    return RectPoint(center=np.zeros(3), length=0.0, width=0.0, touches=tuple(touches))


CASES = {
    "edge.set": ({"axis": "X"}, [edge((8, 5, -5), (1, 0, 0))]),
    "edge.align": ({"axis": "Y", "reference_axis": "X"},
                   [edge((10, -2, -5), (0, 1, 0)), edge((60, -1.9, -5), (0, 1, 0))]),
    "edge.distance": ({"axis": "X"}, [edge((-2, 5, -5), (1, 0, 0)), edge((52, 5, -5), (-1, 0, 0))]),
    "corner.right": ({"kind": "outside", "position": 1},
                     [edge((10, -2, -5), (0, 1, 0)), edge((60, -2, -5), (0, 1, 0)),
                      edge((-2, 10, -5), (1, 0, 0))]),
    "corner.any": ({"kind": "outside", "position": 1},
                   [edge((10, -2, -5), (0, 1, 0)), edge((60, -2, -5), (0, 1, 0)),
                    edge((-2, 10, -5), (1, 0, 0)), edge((-2.5, 40, -5), (1, 0, 0))]),
    "pocket.rect": ({}, [rect((50, 40), 30, 20)]),
    "spigot.rect": ({}, [rect((50, 40), 30, 20, pocket=False)]),
    "hole.1": ({}, [circle((40, 30), 10)]),
    "spigot.1": ({}, [circle((40, 30), 10, hole=False)]),
    "hole.2": ({}, [circle((40, 30), 10), circle((140, 32), 10)]),
    "spigot.2": ({}, [circle((40, 30), 10, False), circle((140, 32), 10, False)]),
    "hole.3": ({"angle_correction": "rotation"},
               [circle((40, 30), 5), circle((100, 90), 5), circle((160, 30), 5)]),
    "spigot.3": ({}, [circle((40, 30), 5, False), circle((100, 90), 5, False),
                      circle((160, 30), 5, False)]),
    "hole.4": ({}, [circle((0, 0), 5), circle((100, 0), 5), circle((100, 80), 5), circle((0, 80), 5)]),
    "spigot.4": ({}, [circle((0, 0), 5, False), circle((100, 0), 5, False), circle((100, 80), 5, False),
                      circle((0, 80), 5, False)]),
    "plane.align": ({}, [edge((0, 0, 2.0), (0, 0, -1)), edge((50, 0, 2.5), (0, 0, -1)),
                         edge((0, 40, 1.7), (0, 0, -1))]),
}


def per_call(fn, repeat: int = 300) -> float:
    fn()
    t0 = time.perf_counter()
    for _ in range(repeat):
        fn()
    return (time.perf_counter() - t0) / repeat


def main() -> None:
    print(f"{'task':16s} {'µs/evaluate':>12s}")
    for task, (params, points) in CASES.items():
        us = per_call(lambda t=task, p=params, pts=points: evaluate(t, p, pts, G17, PROBE)) * 1e6
        print(f"{task:16s} {us:12.1f}")
    ring = RingPass(0.0, {"X+": np.array([10.0, 0, 0]), "X-": np.array([-10.0, 0, 0]),
                          "Y+": np.array([0, 10.0, 0]), "Y-": np.array([0, -10.0, 0])})
    ring_point = RingCalibrationPoint(25.0, ring, (RingPass(180.0, ring.rec), ring))
    extra = {
        "probe.length": lambda: calibrate_length(23.1, 20.0, PROBE, 100.0, G17),
        "probe.radius": lambda: calibrate_radius(ring_point, PROBE, G17),
        "toolprobe.calib": lambda: calibrate_tool_probe({"Z-": 100.0, "X-": 55.0, "X+": 25.0}, 20.0, 5.0, G17),
        "tool.length": lambda: tool_length(150.3, {"Z-": 80.0}, G17),
        "tool.speed_feed": lambda: spindle_speed_feeds(12.0),
    }
    for name, fn in extra.items():
        print(f"{name:16s} {per_call(fn) * 1e6:12.1f}")


if __name__ == "__main__":
    main()

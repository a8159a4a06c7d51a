"""The app tests' scenario: deliberately simple (axis-parallel block, no noise, no pre-travel, no
eccentricity, no latency, time_scale 0) so expected positions can be written down by hand."""

from __future__ import annotations

import copy

PROBE_LENGTH = 100.0
CUTTER_LENGTH = 85.0
BLOCK_TOP_Z = -120.0       # MCS of the block's top face
TEST_SCENARIO = {
    "seed": 1,
    "machine": {"limits": {"X": [-10, 800], "Y": [-10, 500], "Z": [-400, 10]}, "rapid": 10000,
                "jog_feed": 1000, "latency_s": 0.0, "time_scale": 0},
    "probe": {"t": 9, "ball_diameter": 4.0, "length": PROBE_LENGTH, "max_deflection": 5.0},
    "workpiece": {"pose": {"trans": [250.0, 150.0, BLOCK_TOP_Z], "rot": [0.0, 0.0, 0.0]},
                  "features": [{"type": "block", "size": [200, 120, 60]},
                               {"type": "hole", "center": [40, 30], "diameter": 20, "depth": 25}]},
    "ring_gauge": {"center": [600, 100, -160], "diameter": 25.0, "height": 20},
    "tool_probe": {"center": [700, 400, -140], "disc_diameter": 20.0, "height": 40},
    "tools": [{"t": 1, "type": 120, "length": CUTTER_LENGTH, "radius": 5.0}],
    "start": {"X": 100.0, "Y": 100.0, "Z": 0.0},
}


def test_scenario() -> dict:
    """A fresh copy of the scenario, to modify in a test."""
    return copy.deepcopy(TEST_SCENARIO)


test_scenario.__test__ = False   # a helper, not a test

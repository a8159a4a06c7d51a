"""Simulator scenes for the NC tests: an axis-parallel block whose faces are placed so that the
probing positions can be written down by hand (ball radius, pre-travel, latency, braking)."""

from __future__ import annotations

from nc_runtimes import SimRuntime

from app.machine.scenario import load_scenario
from app.machine.sim import SimulatedMachine
from engine.frames import Frame

BALL_R = 2.0
PROBE_LENGTH = 100.0
PRE = {"X+": 0.004, "X-": 0.005, "Y+": 0.003, "Y-": 0.006, "Z-": 0.002}
G54 = (200.0, 100.0, -150.0)             # settable frame G54: translation only
LEFT_FACE = 252.116                      # MCS X of the block's left face (x = 0 of the part)
BACK_FACE = 127.956                      # MCS Y of the block's back face (y = 120 of the part)
TOP = -150.0                             # MCS Z of the block's top face (WCS Z 0 in G54)
SIZE = (200.0, 120.0, 60.0)


def braking(feed_mm_min: float, latency_s: float, decel: float = 1.0, kv: float = 1.0) -> float:
    """Overtravel after the switch, measuring-math §1.3 (written out here, not the simulator's)."""
    v = feed_mm_min / 60000.0                          # m/s
    return 1000.0 * v * latency_s + 1000.0 * v * v / (2.0 * decel) + (feed_mm_min / 1000.0) / kv


def scene(*, latency_s: float = 0.0, noise_sigma: float = 0.0, seed: int = 5, pretravel=None):
    data = {
        "seed": seed,
        "machine": {"limits": {"X": [-50, 900], "Y": [-50, 600], "Z": [-400, 200]}, "rapid": 10000,
                    "latency_s": latency_s, "decel": 1.0, "kv": 1.0, "time_scale": 0},
        "probe": {"t": 9, "ball_diameter": 2 * BALL_R, "length": PROBE_LENGTH, "max_deflection": 5.0,
                  "pretravel": PRE if pretravel is None else pretravel, "noise_sigma": noise_sigma},
        "workpiece": {"pose": {"trans": [LEFT_FACE, BACK_FACE - SIZE[1], TOP], "rot": [0.0, 0.0, 0.0]},
                      "features": [{"type": "block", "size": list(SIZE)}]},
        "tools": [{"t": 1, "length": 85.0, "radius": 5.0}],
        "start": {"X": 0.0, "Y": 0.0, "Z": 150.0},
    }
    machine = SimulatedMachine(load_scenario(data))
    runtime = SimRuntime(machine, offsets={"G54": Frame(coarse=G54)})
    return machine, runtime

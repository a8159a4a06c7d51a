"""Set-up error against the noise bound (issue [probe-physics], docs/noise-bound.md).

Calibrate (ring: radius, surface: length) + right-angled outside corner + set edge Z into G54 on
the design.md §4 example probe (eccentricity, direction-dependent pre-travel, 4 ms latency,
0.3 µm noise, wrong nominal length) for many seeds; prints the mean |error| per axis and of
the rotation against the best-estimator bound (engine.calibration.setup_noise_bound), the worst
seed and how many seeds miss 2 µm / 10 µrad.

Run: python bench/bench_setup_noise.py [seeds] [pretravel_frame probe|machine] [rot_z]
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests" / "flows"))

from flowkit import Flow, cal_scenario, make_client  # noqa: E402

from engine.calibration import setup_noise_bound  # noqa: E402

SIGMA = 0.0003


def run(seeds: int, frame: str, rot_z: float) -> dict:
    errors, rotations = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for seed in range(seeds):
            sc = cal_scenario(seed=seed, probe__pretravel_frame=frame,
                              workpiece__pose={"trans": [250.0, 150.0, -120.0], "rot": [0.0, 0.0, rot_z]})
            with make_client(Path(tmp) / f"s{seed}", sc) as client:
                flow = Flow(client, sc)
                client.put("/api/settings", json={"pretravel_frame": frame})
                flow.calibrate_radius()
                flow.calibrate_length()
                flow.corner_and_z_setup()
                _t, angle, dt = flow.offset_error("G54")
            errors.append(dt)
            rotations.append(angle)
    errors, rotations = np.array(errors), np.array(rotations)
    return {"mean_abs": np.mean(np.abs(errors), axis=0), "rotation_mean_abs": float(np.mean(rotations)),
            "worst": float(np.max(np.linalg.norm(errors, axis=1))), "worst_rotation": float(np.max(rotations)),
            "over_2um": int(np.sum(np.linalg.norm(errors, axis=1) > 0.002)),
            "over_10urad": int(np.sum(rotations > 10e-6)), "n": len(errors)}


def main(seeds: int = 30, frame: str = "probe", rot_z: float = 12.5) -> int:
    bound = setup_noise_bound(SIGMA, rotation_deg=rot_z, standoff=12.0)
    got = run(seeds, frame, rot_z)
    print(f"{got['n']} seeds, pre-travel frame {frame}, part turned {rot_z:g}°, noise {SIGMA * 1e3:g} µm")
    print(f"{'':12s} {'mean |error|':>14s} {'bound':>10s} {'ratio':>7s}")
    worst_ratio = 0.0
    for i, axis in enumerate("XYZ"):
        mean, b = 1e3 * got["mean_abs"][i], 1e3 * bound["mean_abs"][axis]
        worst_ratio = max(worst_ratio, mean / b)
        print(f"{axis:12s} {mean:11.3f} µm {b:7.3f} µm {mean / b:7.2f}")
    rot, rb = 1e6 * got["rotation_mean_abs"], 1e6 * bound["rotation_mean_abs"]
    print(f"{'rotation':12s} {rot:9.3f} µrad {rb:5.3f} µrad {rot / rb:7.2f}")
    print(f"worst seed {1e3 * got['worst']:.3f} µm / {1e6 * got['worst_rotation']:.2f} µrad; "
          f"over 2 µm: {got['over_2um']}, over 10 µrad: {got['over_10urad']}")
    ok = got["over_2um"] == 0 and got["over_10urad"] == 0 and worst_ratio <= 1.35
    print("OK" if ok else "ABOVE the bar (every seed within 2 µm / 10 µrad, mean per axis within 1.35× the bound)")
    return 0 if ok else 1


if __name__ == "__main__":
    args = sys.argv[1:]
    sys.exit(main(int(args[0]) if args else 30, args[1] if len(args) > 1 else "probe",
                  float(args[2]) if len(args) > 2 else 12.5))

"""The centre error of an N-point circle fit against N (design.md §10.2, issue 28 item 3).

hole.1 with ``params.points`` = N on a Ø12 bore, noise σ = 2 µm per touch, many seeds: prints the
RMS distance of the fitted centre from the true one and σ·√(2/N), the least-squares bound for N
evenly spaced touches (each touch informs the centre along its direction only).

Run: python bench/bench_circle_points.py [seeds]
"""

from __future__ import annotations

import math
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests" / "flows"))

from flowkit import make_client  # noqa: E402
from truthkit import HOLE_D, HOLES, Operator, scenario  # noqa: E402

SIGMA = 0.002


def centre_rms(n: int, seeds: int, tmp: Path) -> float:
    errors = []
    for seed in range(seeds):
        data = scenario(rot=(0.0, 0.0, 4.0))
        data["probe"]["noise_sigma"], data["seed"] = SIGMA, seed
        with make_client(tmp / f"n{n}s{seed}", data) as client:
            op = Operator(client, data)
            op.load()
            pose = data["workpiece"]["pose"]
            op.put_offset("G54", rot=pose["rot"], trans=pose["trans"])
            op.activate("G54")
            op.ball_to_part(HOLES[0][0], HOLES[0][1], -8.0)
            session = op.create("hole.1", {"diameter": HOLE_D, "points": n}, "measure_only")
            c = op.start(session["id"])["result"]["center"]
            errors.append(math.hypot(c["X"] - HOLES[0][0], c["Y"] - HOLES[0][1]))
    return float(np.sqrt(np.mean(np.square(errors))))


def main() -> None:
    seeds = int(sys.argv[1]) if len(sys.argv) > 1 else 20
    print(f"hole.1 Ø{HOLE_D}, noise σ = {SIGMA * 1000:.1f} µm per touch, {seeds} seeds")
    print("   N   RMS centre error   σ·√(2/N)")
    with tempfile.TemporaryDirectory() as tmp:
        for n in (3, 4, 6, 8, 12, 16, 24, 36):
            rms = centre_rms(n, seeds, Path(tmp))
            print(f"{n:4d}   {rms * 1000:10.3f} µm    {SIGMA * math.sqrt(2.0 / n) * 1000:8.3f} µm")


if __name__ == "__main__":
    main()

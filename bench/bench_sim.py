"""How long one probing move of the simulator takes at time_scale 0: python bench/bench_sim.py"""

import time

from app.machine.scenario import demo_scenario
from app.machine.sim import SimulatedMachine
from app.services.scenarios import with_time_scale


def main(repeats: int = 200) -> None:
    machine = SimulatedMachine(with_time_scale(demo_scenario(), 0.0))
    start = machine.status().mcs
    t0 = time.perf_counter()
    for _ in range(repeats):
        result = machine.probe([0.0, 0.0, -1.0], 50.0, 300.0)
        assert result.triggered
        machine.goto(start)
    elapsed = (time.perf_counter() - t0) / repeats
    print(f"probe + retract at time_scale 0: {elapsed * 1e3:.3f} ms per pair ({repeats} pairs)")


if __name__ == "__main__":
    main()

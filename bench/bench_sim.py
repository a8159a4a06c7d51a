"""How long one probing move of the simulator takes at time_scale 0: python bench/bench_sim.py"""

import time

from app.machine.scenario import demo_scenario
from app.machine.sim import SimulatedMachine


def main(repeats: int = 200) -> None:
    scenario = demo_scenario().model_copy(update={"machine": demo_scenario().machine.model_copy(
        update={"time_scale": 0.0})})
    machine = SimulatedMachine(scenario)
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

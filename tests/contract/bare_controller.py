"""A controller that offers the ``Machine`` Protocol and nothing else (no SwivelHead, no
SimulatorControl): the HMI must run on it. It plays the simulator behind that bare surface."""

from __future__ import annotations

from app.machine.protocol import ActiveFrame, Alarm, MachineStatus, MoveResult, ProbeResult
from app.machine.scenario import Scenario
from app.machine.sim import SimulatedMachine


class BareController:
    def __init__(self, scenario: Scenario) -> None:
        self.__sim = SimulatedMachine(scenario)     # name-mangled: nothing of it leaks out

    @property
    def controller(self) -> str:
        return "bare"

    @property
    def axes(self) -> tuple[str, ...]:
        return self.__sim.axes

    def status(self) -> MachineStatus:
        return self.__sim.status()

    def jog(self, axis: str, distance: float, feed: float | None = None) -> MoveResult:
        return self.__sim.jog(axis, distance, feed)

    def jog_continuous(self, axis: str, direction: int, feed: float | None = None) -> None:
        self.__sim.jog_continuous(axis, direction, feed)

    def stop(self) -> None:
        self.__sim.stop()

    def goto(self, target_mcs: dict[str, float], feed: float | None = None) -> MoveResult:
        return self.__sim.goto(target_mcs, feed)

    def probe(self, direction, distance: float, feed: float) -> ProbeResult:
        return self.__sim.probe(direction, distance, feed)

    def reset(self) -> None:
        self.__sim.reset()

    def change_tool(self, tool: int | None, offset_length: float) -> None:
        self.__sim.change_tool(tool, offset_length)

    def set_tool_offset(self, offset_length: float) -> None:
        self.__sim.set_tool_offset(offset_length)

    def write_tool(self, t: int, data: dict) -> None:
        self.__sim.write_tool(t, data)

    def spindle_position(self, angle: float) -> None:
        self.__sim.spindle_position(angle)

    def spindle_rotate(self, speed_rpm: float) -> None:
        self.__sim.spindle_rotate(speed_rpm)

    def set_override(self, percent: float) -> None:
        self.__sim.set_override(percent)

    def write_offset(self, name: str, frame: dict) -> None:
        self.__sim.write_offset(name, frame)

    def activate_frame(self, frame: ActiveFrame) -> None:
        self.__sim.activate_frame(frame)

    def post_alarm(self, alarm: Alarm) -> None:
        self.__sim.post_alarm(alarm)

    def close(self) -> None:
        self.__sim.close()

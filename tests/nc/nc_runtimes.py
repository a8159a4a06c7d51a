"""Two NcRuntime implementations for the tests: a recording fake, and an adapter around the
simulated machine (``app.machine.sim.SimulatedMachine``) as the product would build one."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np

from app.machine.protocol import ActiveFrame, MachineAlarm
from app.machine.sim import SimulatedMachine
from app.nc.errors import NcRuntimeError
from app.nc.runtime import MeasureResult
from engine import alarms
from engine.frames import Frame, FrameChain

XYZ = ("X", "Y", "Z")

# switch(start_mcs, end_mcs) -> fraction of the path at which the probe switches, or None
Switch = Callable[[Mapping[str, float], Mapping[str, float]], float | None]


def plane_switch(axis: str, value: float) -> Switch:
    """The probe switches where axis ``axis`` (MCS) passes ``value``."""
    def switch(start, end):
        a, b = float(start[axis]), float(end[axis])
        if a == b or not min(a, b) <= value <= max(a, b):
            return None
        return (value - a) / (b - a)
    return switch


class FakeRuntime:
    """Records every command; positions jump to the target; measuring moves switch per ``switch``."""

    def __init__(self, *, axes: Sequence[str] = XYZ, position: Mapping[str, float] | None = None,
                 offsets: Mapping[str, Frame] | None = None, basic: Sequence[Frame] = (),
                 tools: Mapping[int, Mapping[int, float]] | None = None, tool: int | None = None,
                 edge: int = 0, active: str = "G500", switch: Switch | None = None):
        self._axes = tuple(axes)
        self.pos = {a: 0.0 for a in self._axes}
        self.pos.update(position or {})
        self.offsets = dict(offsets or {})
        self.basic = tuple(basic)
        self.tools = {int(t): dict(d) for t, d in (tools or {}).items()}
        self.tool, self.edge = tool, edge
        self.active = active
        self.switch = switch
        self.log: list[tuple] = []
        self.fail: dict[str, NcRuntimeError] = {}      # op name -> error raised by the next such call

    def _maybe_fail(self, op: str) -> None:
        err = self.fail.pop(op, None)
        if err is not None:
            raise err

    @property
    def axes(self):
        return self._axes

    def position(self):
        return dict(self.pos)

    @property
    def moves(self) -> list[tuple]:
        return [e for e in self.log if e[0] in ("move", "measure")]

    def move(self, target_mcs, feed):
        self._maybe_fail("move")
        target = {a: float(v) for a, v in target_mcs.items()}
        self.log.append(("move", target, feed))
        self.pos.update(target)

    def measure(self, target_mcs, feed, stop_on_trigger):
        self._maybe_fail("measure")
        start = dict(self.pos)
        end = dict(start)
        end.update({a: float(v) for a, v in target_mcs.items()})
        self.log.append(("measure", dict(end), feed, stop_on_trigger))
        f = self.switch(start, end) if self.switch else None
        if f is None:
            self.pos = end
            return MeasureResult(False, None)
        latched = {a: start[a] + f * (end[a] - start[a]) for a in self._axes}
        self.pos = dict(latched) if stop_on_trigger else end
        return MeasureResult(True, latched)

    def offset_chain(self, name):
        if name == "G500":
            return FrameChain(basic=self.basic)
        if name not in self.offsets:
            raise NcRuntimeError(f"zero offset {name} does not exist", alarms.ZO_NUMBER)
        return FrameChain(basic=self.basic, settable=self.offsets[name])

    def active_offset(self):
        return self.active

    def activate_offset(self, name):
        self._maybe_fail("activate_offset")
        self.offset_chain(name)
        self.log.append(("activate", name))
        self.active = name

    def tool_state(self):
        return self.tool, self.edge

    def tool_length(self, tool, edge):
        if tool is None or edge == 0:
            return 0.0
        if tool not in self.tools:
            raise NcRuntimeError(f"T{tool} is not in the tool list", alarms.NO_TOOL_FOR_IDENTIFIER)
        if edge not in self.tools[tool]:
            raise NcRuntimeError(f"T{tool} has no cutting edge D{edge}", alarms.NC_D_NUMBER)
        return float(self.tools[tool][edge])

    def change_tool(self, tool, edge):
        self._maybe_fail("change_tool")
        self.tool_length(tool, edge)
        self.log.append(("tool", tool, edge))
        self.tool, self.edge = tool, edge

    def select_edge(self, edge):
        self.tool_length(self.tool, edge)
        self.log.append(("edge", edge))
        self.edge = edge

    def spindle(self, direction, speed):
        self.log.append(("spindle", direction, speed))

    def spindle_position(self, angle):
        self.log.append(("spos", angle))


class SimRuntime:
    """NcRuntime on the simulator: the NC's offsets and tool table live here (as the product's
    machine service keeps them); motion and probing are the simulator's."""

    def __init__(self, machine: SimulatedMachine, *, offsets: Mapping[str, Frame] | None = None,
                 basic: Sequence[Frame] = (), tool_lengths: Mapping[int, float] | None = None):
        self.machine = machine
        self.offsets = dict(offsets or {})
        self.basic = tuple(basic)
        sc = machine.scenario
        lengths = {sc.probe.t: sc.probe.nominal_length}
        lengths.update({t.t: t.nominal_length for t in sc.tools})
        lengths.update(tool_lengths or {})
        self.lengths = lengths
        status = machine.status()
        self._tool = status.tool
        self._edge = 1 if status.tool is not None else 0
        self._active = status.active_offset

    @staticmethod
    def _error(alarm) -> NcRuntimeError:
        definition = alarms.by_number(alarm.code) or alarms.NC_INTERNAL
        if alarm.code == alarms.PROBE_BROKEN.number and not alarm.resettable:
            definition = alarms.PROBE_BROKEN
        return NcRuntimeError(alarm.text, definition)

    @property
    def axes(self):
        return self.machine.axes

    def position(self):
        return dict(self.machine.status().mcs)

    def move(self, target_mcs, feed):
        try:
            result = self.machine.goto(dict(target_mcs), feed)
        except MachineAlarm as e:
            raise self._error(e.alarm) from None
        if not result.completed:
            raise self._error(result.alarm) if result.alarm else NcRuntimeError("motion stopped",
                                                                                alarms.RESET_ABORT)

    def measure(self, target_mcs, feed, stop_on_trigger):
        start = self.machine.status().mcs
        d = np.array([float(target_mcs.get(a, start[a])) - start[a] for a in XYZ])
        distance = float(np.linalg.norm(d))
        if distance == 0.0:
            raise NcRuntimeError("measuring move without path", alarms.NO_MEASURING_PATH)
        try:
            result = self.machine.probe(d / distance, distance, feed)
        except MachineAlarm as e:
            raise self._error(e.alarm) from None
        if result.triggered and not stop_on_trigger:
            # MEAW: go on to the end point. The simulator cannot push a deflected stylus on: a
            # remaining path is a collision there (a real probe would be deflected further).
            self.move(target_mcs, feed)
        return MeasureResult(result.triggered, dict(result.latched_mcs) if result.triggered else None)

    def offset_chain(self, name):
        if name == "G500":
            return FrameChain(basic=self.basic)
        if name not in self.offsets:
            raise NcRuntimeError(f"zero offset {name} does not exist", alarms.ZO_NUMBER)
        return FrameChain(basic=self.basic, settable=self.offsets[name])

    def active_offset(self):
        return self._active

    def activate_offset(self, name):
        chain = self.offset_chain(name)
        self.machine.activate_frame(ActiveFrame(name=name, wcs2bcs=chain.wcs2bcs.as_matrix()))
        self._active = name

    def tool_state(self):
        return self._tool, self._edge

    def tool_length(self, tool, edge):
        if tool is None or edge == 0:
            return 0.0
        if tool not in self.lengths:
            raise NcRuntimeError(f"T{tool} is not in the tool list", alarms.NO_TOOL_FOR_IDENTIFIER)
        if edge != 1:
            raise NcRuntimeError(f"T{tool} has only D1", alarms.NC_D_NUMBER)
        return float(self.lengths[tool])

    def change_tool(self, tool, edge):
        length = self.tool_length(tool, edge)
        try:
            self.machine.change_tool(tool, length)
        except MachineAlarm as e:
            raise self._error(e.alarm) from None
        self._tool, self._edge = tool, edge

    def select_edge(self, edge):
        self.machine.set_tool_offset(self.tool_length(self._tool, edge))
        self._edge = edge

    def spindle(self, direction, speed):
        self.machine.spindle_rotate(speed if direction else 0.0)

    def spindle_position(self, angle):
        self.machine.spindle_position(angle)

"""The machine as the HMI drives it: frame chain, activation, WCS<->MCS, motion, tool change, scenario.

Owns the one ``Machine`` (the simulator, later a real controller). WCS positions are those of
the tool tip: ``tip = axes - L * infeed_unit`` with L the NC's offset length (tool length +
wear) along the infeed axis of the measuring plane, and ``tip_mcs = wcs2bcs(p_wcs)`` (BCS = MCS).
The active settable offset and the tool in the spindle are persisted in the db state.
With a swivel head turned out of +Z the length goes along the machine's actual tool axis
(``status().tool_axis``, TRAORI-like), so that WCS tip positions stay right
(``app.workflow.executor.length_axis``, which owns the tip <-> axes conversion).
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable, Mapping
from contextlib import contextmanager

import numpy as np

from app.errors import AlarmError, BusyError, InvalidInput, NotFoundError
from app.machine.protocol import ActiveFrame, Alarm, Machine, MachineAlarm, MachineBusy, MoveResult
from app.machine.scenario import Scenario
from app.workflow.executor import StepExecutor
from db import Database
from engine.frames import GEOMETRY_AXES, Frame, FrameChain
from engine.planes import plane as plane_by_name

from .settings import SettingsService

CHANNEL = "CHAN1"
G500 = "G500"
SETFRAME = "BASIC_REF"             # the system frame outside the basic frames
PROBE_TOOL_TYPE = 710            # 3D probe, multidirectional (spec §10: 710/1xy)
MAX_TRAVEL = 10_000.0            # mm; a bigger single move is a typo
MAX_FEED = 50_000.0              # mm/min
STATE_ACTIVE_OFFSET = "active_offset"
STATE_TOOL = "tool"


def _finite(value, field: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise InvalidInput(f"{field}: must be a finite number", field=field)
    return float(value)


def basic_frame_names(names) -> tuple[str, ...]:
    """BASIC_0, BASIC_1, … in chain order (BASIC_REF is the SETFRAME, outside all of them)."""
    return tuple(sorted((n for n in names if n.startswith("BASIC_") and n != SETFRAME),
                        key=lambda n: int(n.split("_")[1])))


def frame_chain(offsets: Mapping[str, Frame], active: str) -> FrameChain:
    """WCS->BCS = BASIC_REF ∘ BASIC_0 ∘ BASIC_1 ∘ … ∘ ``active`` (identity under G500)."""
    return FrameChain(setframe=offsets.get(SETFRAME, Frame.identity()),
                      basic=tuple(offsets[n] for n in basic_frame_names(offsets)),
                      settable=Frame.identity() if active == G500 else offsets[active])


def alarm_dict(alarm: Alarm) -> dict:
    return {"code": alarm.code, "text": alarm.text}


class MachineService:
    """Thin, thread-safe orchestration around a ``Machine``; every method returns plain data."""

    def __init__(self, db: Database, machine: Machine, scenario: Scenario, settings: SettingsService,
                 machine_factory: Callable[[Scenario], Machine] | None = None):
        self._db = db
        self._machine = machine
        self._scenario = scenario
        self._settings = settings
        self._lock = threading.RLock()       # guards chain/tool bookkeeping, not the motion itself
        self._chain = FrameChain()
        self._active_offset = G500
        self.panel = PanelState()
        with db.unit(readonly=True) as unit:
            active = unit.get_state(STATE_ACTIVE_OFFSET, G500)
            tool = unit.get_state(STATE_TOOL, None)
        self._seed_data(reset=False)
        self.activate(active if self._is_settable(active) else G500)
        self._restore_tool(tool)

    # --- read-only views ----------------------------------------------------------------
    @property
    def machine(self) -> Machine:
        return self._machine

    @property
    def scenario(self) -> Scenario:
        return self._scenario

    @property
    def axes(self) -> tuple[str, ...]:
        return tuple(self._machine.axes)

    @property
    def rotary_axes(self) -> tuple[str, ...]:
        return tuple(a for a in self.axes if a not in GEOMETRY_AXES)

    @property
    def active_offset(self) -> str:
        return self._active_offset

    @property
    def chain(self) -> FrameChain:
        return self._chain

    def plane(self):
        return plane_by_name(self._settings.get().plane)

    def status(self) -> dict:
        """The ``GET /api/machine`` body (design.md §4) plus channel, tool length, program state."""
        st = self._machine.status()
        alarms = [alarm_dict(a) for a in st.alarms]
        program_state = "active" if st.busy else ("interrupted" if alarms else "reset")
        return {
            "mode": st.mode,
            "channel": CHANNEL,
            "mcs": {a: float(v) for a, v in st.mcs.items()},
            "wcs": self.wcs_from_mcs(st.mcs, st.tool_length),
            "active_offset": self._active_offset,
            "plane": self._settings.get().plane,
            "tool": st.tool,
            "tool_length": float(st.tool_length),
            "feed_override": float(st.feed_override),
            "spindle_angle": float(st.spindle_angle),
            "alarms": alarms,
            "busy": bool(st.busy),
            "program_state": program_state,
            "tool_axis": [float(v) for v in getattr(st, "tool_axis", (0.0, 0.0, 1.0))],
            "swivel": self.has_swivel(),
        }

    # --- swivel head (CYCLE800-like re-alignment, spec §6.2) --------------------------------
    def has_swivel(self) -> bool:
        return bool(getattr(self._machine, "has_swivel", lambda: False)())

    def retract_tool_axis(self, distance: float | None = None) -> dict:
        """Retract up along the tool axis (to the limits by default) before a swivel (spec §11 Q9)."""
        if distance is not None:
            distance = _finite(distance, "distance")
        return self._run(lambda: self._machine.retract_tool_axis(distance))

    def swivel_to_wcs(self) -> dict:
        """Swivel the head so that the tool axis is parallel to the active WCS's infeed axis."""
        if not self.has_swivel():
            raise InvalidInput("this machine has no swivel kinematics", field="realign")
        rotation = self._chain.wcs2bcs.as_matrix()[:3, :3]
        infeed = np.asarray(self.plane().infeed_unit, dtype=float)
        return self._run(lambda: self._machine.swivel_to_wcs(rotation, infeed))

    # --- coordinates ----------------------------------------------------------------------
    def _tip(self, tool_length: float | None) -> StepExecutor:
        """Tool tip <-> axis positions in the active chain (the executor owns the conversion)."""
        if tool_length is None:
            tool_length = self._machine.status().tool_length
        return StepExecutor(self._machine, self._chain.wcs2bcs, tool_length, self.plane().infeed_unit)

    def wcs_from_mcs(self, mcs: Mapping[str, float], tool_length: float | None = None) -> dict[str, float]:
        p_wcs = self._tip(tool_length).tip_in_wcs([float(mcs[a]) for a in GEOMETRY_AXES])
        out = {a: float(v) for a, v in zip(GEOMETRY_AXES, p_wcs, strict=True)}
        for axis in self.rotary_axes:
            if axis in mcs:
                out[axis] = float(mcs[axis]) - self._chain.wcs2bcs.rotary_offset(axis)
        return out

    def mcs_from_wcs(self, wcs: Mapping[str, float], tool_length: float | None = None) -> dict[str, float]:
        """Full WCS point (X, Y, Z; rotary optional) -> axis positions of the tool reference point."""
        axes_xyz = self._tip(tool_length).axes_for_tip([float(wcs[a]) for a in GEOMETRY_AXES], "WCS")
        out = {a: float(v) for a, v in zip(GEOMETRY_AXES, axes_xyz, strict=True)}
        for axis in self.rotary_axes:
            if axis in wcs:
                out[axis] = float(wcs[axis]) + self._chain.wcs2bcs.rotary_offset(axis)
        return out

    # --- motion -----------------------------------------------------------------------------
    def _check_axis(self, axis, field: str = "axis") -> str:
        if not isinstance(axis, str) or axis.upper() not in self.axes:
            raise InvalidInput(f"{field}: unknown axis {axis!r}; axes are {', '.join(self.axes)}", field=field)
        return axis.upper()

    def _check_feed(self, feed, field: str = "feed") -> float | None:
        if feed is None:
            return None
        feed = _finite(feed, field)
        if not 0 < feed <= MAX_FEED:
            raise InvalidInput(f"{field}: must be > 0 and <= {MAX_FEED:g} mm/min", field=field)
        return feed

    def _ensure_idle(self) -> None:
        if self._machine.status().busy:
            raise BusyError("a motion is running")

    def _finish(self, result: MoveResult) -> dict:
        if result.alarm is not None:
            raise AlarmError(result.alarm.code, result.alarm.text)
        return self.status()

    @staticmethod
    @contextmanager
    def _machine_errors():
        """The machine's busy/alarm exceptions as the API's errors."""
        try:
            yield
        except MachineBusy as exc:
            raise BusyError(str(exc) or "a motion is running") from None
        except MachineAlarm as exc:
            raise AlarmError(exc.alarm.code, exc.alarm.text) from None

    def _run(self, motion: Callable[[], MoveResult]) -> dict:
        self._ensure_idle()
        with self._machine_errors():
            result = motion()
        return self._finish(result)

    def jog(self, axis: str, distance: float, feed: float | None = None) -> dict:
        axis = self._check_axis(axis)
        distance = _finite(distance, "distance")
        if abs(distance) > MAX_TRAVEL:
            raise InvalidInput(f"distance: at most {MAX_TRAVEL:g} per jog", field="distance")
        feed = self._check_feed(feed)
        return self._run(lambda: self._machine.jog(axis, distance, feed))

    def jog_continuous(self, axis: str, direction: int, feed: float | None = None) -> dict:
        axis = self._check_axis(axis)
        if direction not in (-1, 1):
            raise InvalidInput("direction: must be -1 or +1", field="direction")
        feed = self._check_feed(feed)
        self._ensure_idle()
        with self._machine_errors():
            self._machine.jog_continuous(axis, direction, feed)
        return self.status()

    def stop(self) -> dict:
        self._machine.stop()
        return self.status()

    def goto_target(self, target: Mapping[str, float | None], coords: str = "WCS") -> dict[str, float]:
        """Validated MCS target of a goto; axes not given keep their current position in ``coords``."""
        if coords not in ("WCS", "MCS"):
            raise InvalidInput("coords: must be WCS or MCS", field="coords")
        given = {}
        for axis, value in target.items():
            if value is None:
                continue
            axis = self._check_axis(axis, field=str(axis))
            given[axis] = _finite(value, axis)
        st = self._machine.status()
        if coords == "MCS":
            return {**{a: float(v) for a, v in st.mcs.items()}, **given}
        current_wcs = self.wcs_from_mcs(st.mcs, st.tool_length)
        return self.mcs_from_wcs({**current_wcs, **given}, st.tool_length)

    def goto(self, target: Mapping[str, float | None], coords: str = "WCS", feed: float | None = None) -> dict:
        mcs_target = self.goto_target(target, coords)
        feed = self._check_feed(feed)
        return self._run(lambda: self._machine.goto(mcs_target, feed))

    def probe(self, direction, distance: float, feed: float, coords: str = "MCS") -> dict:
        """One raw measuring move (MEAS): ``{"triggered", "mcs", "wcs", "end_mcs", "feed", "override"}``."""
        if coords not in ("WCS", "MCS"):
            raise InvalidInput("coords: must be WCS or MCS", field="coords")
        if not isinstance(direction, list | tuple) or len(direction) != 3:
            raise InvalidInput("direction: must be [dx, dy, dz]", field="direction")
        d = np.array([_finite(v, f"direction.{i}") for i, v in enumerate(direction)])
        norm = float(np.linalg.norm(d))
        if norm < 1e-9:
            raise InvalidInput("direction: must not be the zero vector", field="direction")
        d = d / norm
        if coords == "WCS":
            d = self._chain.wcs2bcs.dir_child2parent(d)
        distance = _finite(distance, "distance")
        if not 0 < distance <= MAX_TRAVEL:
            raise InvalidInput(f"distance: must be > 0 and <= {MAX_TRAVEL:g}", field="distance")
        feed = self._check_feed(_finite(feed, "feed"))
        self._ensure_idle()
        with self._machine_errors():
            result = self._machine.probe(d, distance, feed)
        latched = None if result.latched_mcs is None else {a: float(v) for a, v in result.latched_mcs.items()}
        return {
            "triggered": bool(result.triggered),
            "mcs": latched,
            "wcs": None if latched is None else self.wcs_from_mcs(latched),
            "end_mcs": {a: float(v) for a, v in result.end_mcs.items()},
            "feed": float(result.feed),
            "override": float(result.override),
        }

    def reset(self) -> dict:
        self._machine.reset()
        return self.status()

    def set_override(self, percent: float) -> dict:
        percent = _finite(percent, "feed")
        if not 0 <= percent <= 120:
            raise InvalidInput("feed: override must be 0..120 %", field="feed")
        self._machine.set_override(percent)
        return self.status()

    # --- tools ------------------------------------------------------------------------------
    def resolve_tool(self, tool) -> int | None:
        """Tool number from a number, "T9"/"9", or a tool name; 0/None = empty spindle."""
        if tool is None or (isinstance(tool, int) and not isinstance(tool, bool) and tool == 0):
            return None
        if isinstance(tool, bool):
            raise InvalidInput("tool: must be a tool number or name", field="tool")
        if isinstance(tool, float) and tool.is_integer():
            tool = int(tool)
        if isinstance(tool, str):
            text = tool.strip()
            digits = text[1:] if text[:1] in ("T", "t") else text
            if digits.isdigit():
                tool = int(digits)
            else:
                with self._db.unit(readonly=True) as unit:
                    match = [t for t in unit.list_tools() if t.get("name") == text]
                if not match:
                    raise NotFoundError(f"no tool named {text!r}", field="tool", code="unknown_tool")
                return match[0]["t"]
        if not isinstance(tool, int) or tool < 0:
            raise InvalidInput("tool: must be a tool number or name", field="tool")
        return tool or None

    @staticmethod
    def offset_length(tool_data: Mapping) -> float:
        """The NC's L1: geometry length + wear length."""
        return float(tool_data["length"]) + float(tool_data.get("wear", {}).get("length", 0.0))

    def change_tool(self, tool) -> dict:
        t = self.resolve_tool(tool)
        length = 0.0
        if t is not None:
            with self._db.unit(readonly=True) as unit:
                data = unit.get_tool(t)
            if data is None:
                raise NotFoundError(f"T{t} is not in the tool table", field="tool", code="unknown_tool")
            length = self.offset_length(data)
        self._ensure_idle()
        try:
            with self._machine_errors():
                self._machine.change_tool(t, length)
        except ValueError as exc:      # the tool table knows it, the machine's magazine does not
            raise InvalidInput(f"tool: {exc}", field="tool") from None
        with self._db.unit() as unit:
            unit.set_state(STATE_TOOL, t)
        return self.status()

    def refresh_tool_offset(self) -> None:
        """Re-read the active tool's data (after a tool table edit) and hand L1 to the NC."""
        t = self._machine.status().tool
        if t is None:
            return
        with self._db.unit(readonly=True) as unit:
            data = unit.get_tool(t)
        if data is not None:
            self._machine.set_tool_offset(self.offset_length(data))

    # --- frames -----------------------------------------------------------------------------
    def _is_settable(self, name) -> bool:
        if name == G500:
            return True
        with self._db.unit(readonly=True) as unit:
            names = unit.offset_names()
        return isinstance(name, str) and name in names and not name.startswith("BASIC")

    def build_chain(self, active: str) -> FrameChain:
        with self._db.unit(readonly=True) as unit:
            offsets = {n: Frame.from_api(f) for n, f in unit.list_offsets().items()}
        return frame_chain(offsets, active)

    def activate(self, name: str) -> dict:
        if not isinstance(name, str) or not self._is_settable(name.upper()):
            raise InvalidInput(f"offset: {name!r} is not a settable zero offset (G500, G54..)", field="offset")
        name = name.upper()
        with self._lock:
            chain = self.build_chain(name)
            wcs2bcs = chain.wcs2bcs
            self._machine.activate_frame(ActiveFrame(name=name, wcs2bcs=wcs2bcs.as_matrix(),
                                                     rotary_offsets=dict(wcs2bcs.rotary)))
            changed = name != self._active_offset
            self._chain, self._active_offset = chain, name
            if changed:          # re-activating the same WO (after a correction) needs no write
                with self._db.unit() as unit:
                    unit.set_state(STATE_ACTIVE_OFFSET, name)
        return self.status()

    def refresh_frame(self) -> None:
        """Re-compose the active chain after an offset was written (BASIC_*, or the active WO)."""
        self.activate(self._active_offset)

    # --- scenario -----------------------------------------------------------------------------
    def load_scenario(self, scenario: Scenario, reset_data: bool = False) -> dict:
        """Reset the machine to ``scenario``; stored data stays unless ``reset_data``."""
        with self._lock:
            self._machine.load(scenario)
            self._scenario = scenario
            self._seed_data(reset=reset_data)
            self.activate(G500 if reset_data else self._active_offset)
            with self._db.unit(readonly=True) as unit:
                tool = unit.get_state(STATE_TOOL, None)
            self._restore_tool(tool)
        return self.status()

    def _restore_tool(self, tool) -> None:
        """Put the stored tool back into the spindle; the probe when none is stored or it is gone."""
        try:
            self.change_tool(tool if tool is not None else self._scenario.probe.t)
        except NotFoundError:
            self.change_tool(self._scenario.probe.t)

    def _seed_data(self, reset: bool) -> None:
        """Tool table from the scenario's nominal values (probe included) when empty or on reset;
        on reset also identity offsets, uncalibrated probe records and default settings."""
        sc = self._scenario
        with self._db.unit() as unit:
            tools = unit.list_tools()
            if reset:
                for tool in tools:
                    unit.delete_tool(tool["t"])
                for name in unit.offset_names():
                    unit.put_offset(name, {"trans": {}, "fine": {}, "rot": {}}, source="scenario",
                                    detail={"reason": "reset_data"})
                for record in unit.list_probes():
                    unit.put_probe(record["number"], {})
                for record in unit.list_tool_probes():
                    unit.put_tool_probe(record["number"], {})
            if reset or not tools:
                unit.put_tool(sc.probe.t, {"name": "3D probe", "type": PROBE_TOOL_TYPE,
                                           "length": sc.probe.nominal_length,
                                           "radius": sc.probe.nominal_ball_diameter / 2.0,
                                           "wear": {"length": 0.0, "radius": 0.0}})
                for tool in sc.tools:
                    unit.put_tool(tool.t, {"type": tool.type, "length": tool.nominal_length,
                                           "radius": tool.nominal_radius,
                                           "wear": {"length": 0.0, "radius": 0.0}})
            if reset:
                unit.set_state(STATE_TOOL, None)
            if sc.tool_probe is not None:   # its disc diameter is commissioning data, like nominal tool data
                n = 1 if reset else int(self._settings.get().tool_probe_number)
                record = unit.get_tool_probe(n) or {}
                if not record.get("disc_diameter"):
                    unit.put_tool_probe(n, {**record, "disc_diameter": float(sc.tool_probe.disc_diameter)})
        if reset:
            self._settings.reset_to_defaults()

    def scene_geometry(self) -> dict:
        return self._machine.scene_geometry()


class PanelState:
    """Machine control panel selections of the screen (axis, increment, displayed coordinates)."""

    INCREMENTS = {"1": 0.001, "10": 0.01, "100": 0.1, "1000": 1.0, "cont": None}

    def __init__(self):
        self.axis = "X"
        self.increment = "1000"
        self.coords = "WCS"

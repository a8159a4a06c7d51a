"""The machine as the HMI drives it: frame chain, activation, WCS<->MCS, motion, tool change, scenario.

Owns the one ``Machine`` (the simulator or a real controller, app.machine.registry) and calls
only what the ``Machine`` Protocol offers; the optional interfaces (``SwivelHead``,
``SimulatorControl``) are asked for with ``isinstance`` first: a scenario load or the machine
view on a controller without them is a 409 ``not_simulated``. Every named offset and tool the
HMI stores is written to the machine too (``write_offset``/``write_tool``: at start-up, after a
scenario load and after each write), so that the NC holds what the HMI stored. WCS positions are those of
the tool tip: ``tip = axes - L * infeed_unit`` with L the NC's offset length (tool length +
wear) along the infeed axis of the measuring plane, and ``tip_mcs = wcs2bcs(p_wcs)`` (BCS = MCS).
The active settable offset and the tool in the spindle are persisted in the db state.

On a lathe (a machine whose ``kind`` is "lathe", turning.md §10.2) the tip is
``P = F − (L1·x̂ + L2·ẑ)`` with the NC's lengths of the active tool (``engine.coords.LatheToolTip``),
WCS X is shown and read as a diameter with diameter programming (DIAMON), the plane is G18,
and ``GET /api/machine`` adds ``"kind": "lathe"``. Loading a scenario of the other kind
builds the other machine (``rebuild``, the registry's factory under the same name) and resets
the stored data: tool table, offsets and records of a milling machine mean nothing on a lathe.
With a swivel head turned out of +Z the length goes along the machine's actual tool axis
(``status().tool_axis``, TRAORI-like), so that WCS tip positions stay right
(``engine.coords``, which owns the tip <-> axes conversion).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import logging
import threading
import time
from collections.abc import Callable, Mapping
from contextlib import contextmanager
from functools import partial
from typing import overload

import numpy as np

from app import checks
from app.errors import AlarmError, BusyError, ConflictError, InvalidInput, NotFoundError
from app.machine.lathe_scenario import LatheScenario
from app.machine.protocol import (
    ActiveFrame,
    Alarm,
    FrameCapacity,
    Lathe,
    Machine,
    MachineAlarm,
    MachineBusy,
    MachineStatus,
    MoveResult,
    OwnConfiguration,
    ProbeState,
    SimulatorControl,
    SwivelHead,
)
from app.machine.scenario import Scenario
from app.records import PROBE_TOOL_TYPE
from db import Database, StorageUnavailable
from engine.alarms import all_alarms
from engine.alarms import by_number as alarm_by_number
from engine.coords import GEOMETRY_AXES, LatheToolTip, ToolTip, head_shift_of, length_axis
from engine.frames import G500, SETFRAME, Frame, FrameChain, basic_frame_names, chain_of, is_basic
from engine.planes import plane as plane_by_name

from . import lathe_data
from .data_reset import STATE_TOOL, clear_stored_data
from .live import ChangeSignal
from .settings import SettingsService

log = logging.getLogger(__name__)

CHANNEL = "CHAN1"
MAX_TRAVEL = 10_000.0            # mm; a bigger single move is a typo
MAX_FEED = 50_000.0              # mm/min
STATE_ACTIVE_OFFSET = "active_offset"


def alarm_dict(alarm: Alarm) -> dict:
    """An alarm with the manual's remedy (seed 001 turning §11, "说明，消除"), "" where the catalogue has none."""
    definition = alarm_by_number(alarm.code)
    broken = definition is not None and definition.resettable != alarm.resettable
    if broken:      # 61302 twice: the broken stylus is the one Reset cannot clear
        definition = next((a for a in all_alarms() if a.number == alarm.code and a.resettable == alarm.resettable),
                          definition)
    return {"code": alarm.code, "text": alarm.text, "remedy": definition.remedy if definition else ""}


class StatusSnapshot:
    """One state version of ``MachineService.status()``: the body and its JSON bytes (encoded once,
    on first use, as FastAPI's JSONResponse encodes). ``key``/``machine``/``chain``: what it was made of."""

    def __init__(self, key: tuple, machine: Machine, chain: FrameChain, body: dict, version: int):
        self.key, self.machine, self.chain, self.body, self.version = key, machine, chain, body, version
        self._json: bytes | None = None

    @property
    def json(self) -> bytes:
        if self._json is None:
            self._json = json.dumps(self.body, ensure_ascii=False, allow_nan=False, indent=None,
                                    separators=(",", ":")).encode("utf-8")
        return self._json


class MachineService:
    """Thin, thread-safe orchestration around a ``Machine``; every method returns plain data."""

    def __init__(self, db: Database, machine: Machine, scenario: Scenario | LatheScenario, settings: SettingsService,
                 rebuild: Callable[[Scenario | LatheScenario], Machine] | None = None):
        self._db = db
        self._rebuild = rebuild              # builds the machine of a scenario of the other kind
        self._machine = machine
        self._capabilities: tuple[Machine | None, dict[type, bool]] = (None, {})
        self._scenario = scenario
        self._settings = settings
        self._lock = threading.RLock()       # guards chain/tool bookkeeping, not the motion itself
        self._chain = FrameChain()
        self._active_offset = G500
        self._hold = HoldToRun(machine)
        self._frames: tuple[int, dict[str, Frame]] | None = None
        self._discard_listeners: list[Callable[[str], None]] = []
        # probe health (design.md §10.4): alarms as they appear, scenario loads
        self._alarm_listeners: list[Callable[[Alarm, dict], None]] = []
        self._alarms_seen: frozenset[tuple[int, str, bool]] = frozenset()
        self._scenario_listeners: list[Callable[[], None]] = []
        # one channel (issue 24 §3-4): what a Reset ends, what the mode group refuses, NC Stop's hold
        self._reset_listeners: list[tuple[Callable[[], None], Callable[[], None]]] = []
        self._interlocks: list[Callable[[str], None]] = []
        self._held_override: float | None = None
        self.mode_source: Callable[[], str | None] | None = None   # the NC channel's mode (MDA/AUTO)
        # what runs and locks the rest ({"mode", "program"}: a program, a JOG measurement) or None
        self.lock_source: Callable[[], dict | None] | None = None
        self._snapshot: StatusSnapshot | None = None
        self.changes = ChangeSignal()        # a change without motion (a probe deflected by hand): the live feed
        with db.unit(readonly=True) as unit:
            active = unit.get_state(STATE_ACTIVE_OFFSET, G500)
            tool = unit.get_state(STATE_TOOL, None)
        self._at_start(self._seed_data, False)
        self._at_start(self._take_nc_tools)
        self._push_nc_data()
        self._at_start(self._activate_stored, active)
        self._at_start(self._restore_tool, tool)

    def _activate_stored(self, active: str) -> None:
        try:
            self.activate(active if self._is_settable(active) else G500)
        except AlarmError:                     # a stored frame the NC cannot hold: no offset, alarm shown
            with contextlib.suppress(AlarmError):
                self.activate(G500)

    def _at_start(self, step: Callable[..., object], *args: object) -> None:
        """A start-up step; on a database that cannot be written (design.md §10.8) what it would
        store is left out and the HMI starts read only."""
        try:
            step(*args)
        except StorageUnavailable as exc:
            if not self._db.read_only:
                raise
            log.warning("start-up step left out (read-only database): %s", exc)

    # --- read-only views ----------------------------------------------------------------
    @property
    def machine(self) -> Machine:
        return self._machine

    @property
    def scenario(self) -> Scenario | LatheScenario:
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

    # --- what the machine is (its capabilities, protocol.py; asked here once each) ----------------
    def _is(self, protocol: type) -> bool:
        """``isinstance(machine, protocol)``, asked once per machine object: a runtime-checkable
        protocol's check looks up every member, and every poll's snapshot asks (issue 30 item 2)."""
        machine = self._machine
        known = self._capabilities
        if known[0] is not machine:
            known = self._capabilities = (machine, {})
        answer = known[1].get(protocol)
        if answer is None:
            answer = known[1][protocol] = isinstance(machine, protocol)
        return answer

    @property
    def is_lathe(self) -> bool:
        """The machine is a lathe (turning.md §10.2): X radius, DIAMON, the lathe tasks."""
        return self._is(Lathe)

    @property
    def diameter_programming(self) -> bool:
        machine = self._machine
        return self._is(Lathe) and bool(machine.diameter_programming)  # type: ignore[attr-defined]

    @property
    def spos_capable(self) -> bool:
        """SPOS possible: every milling spindle here; a lathe's main spindle as commissioned."""
        machine = self._machine
        return not isinstance(machine, Lathe) or bool(machine.spos_capable)

    # --- the machine's commissioning data (the scenario's machine section, design.md §4) ----------
    def limits(self) -> dict:
        """The software limits per axis (MCS)."""
        return self._scenario.limits()

    @property
    def rapid_feed(self) -> float:
        """The rapid traverse (mm/min)."""
        return float(self._scenario.machine.rapid)

    @property
    def has_tool_probe(self) -> bool:
        return self._scenario.tool_probe is not None

    def plane(self):
        return plane_by_name("G18" if self.is_lathe else self._settings.get().plane)

    def status(self) -> dict:
        """The ``GET /api/machine`` body (design.md §4) plus channel, tool length, program state.
        Shared by every caller until the state changes (``snapshot``): read it, never change it."""
        return self.snapshot().body

    def snapshot(self) -> StatusSnapshot:
        """The state as one value per state version: built again only when something it is made
        of changed (the machine's status, mode, lock, offset, chain, plane, feed hold), so that
        polls and the live feed cost no frame arithmetic and no encoding at rest (issue 30)."""
        st = self._machine.status()
        self._see_alarms(st)
        settings = self._settings.get()
        plane, units = settings.plane, settings.units
        mode = (self.mode_source() if self.mode_source else None) or st.mode
        lock = self.lock_source() if self.lock_source else None
        machine, chain = self._machine, self._chain
        key = (st, mode, lock, self._active_offset, plane, units, self._held_override is not None, self.has_swivel(),
               self.diameter_programming, self._scenario)
        last = self._snapshot
        if last is not None and last.machine is machine and last.chain is chain and last.key == key:
            return last
        snapshot = StatusSnapshot(key, machine, chain, self._status_body(st, plane, units, mode, lock),
                                  (last.version + 1) if last is not None else 1)
        self._snapshot = snapshot
        return snapshot

    def _status_body(self, st: MachineStatus, plane: str, units: str, mode: str, lock: dict | None) -> dict:
        alarms = [alarm_dict(a) for a in st.alarms]
        program_state = "active" if st.busy else ("interrupted" if alarms else "reset")
        return {
            "mode": mode,
            "channel": CHANNEL,
            "mcs": {a: float(v) for a, v in st.mcs.items()},
            "wcs": self.wcs_from_mcs(st.mcs, st.tool_length, st),
            "active_offset": self._active_offset,
            "plane": plane,
            "units": units,                 # the screens' units (design.md §9.9): the live feed carries a change
            "tool": st.tool,
            "tool_length": float(st.tool_length),
            "feed_override": float(st.feed_override),
            "spindle_angle": float(st.spindle_angle),
            "alarms": alarms,
            "busy": bool(st.busy),
            "feed_hold": self._held_override is not None,
            "lock": lock,
            "program_state": program_state,
            "tool_axis": [float(v) for v in getattr(st, "tool_axis", (0.0, 0.0, 1.0))],
            "head_shift": [float(v) for v in head_shift_of(getattr(st, "head_shift", None))],
            "swivel": self.has_swivel(),
            "controller": self._machine.controller,
            # design.md §10.7: the controller's E-stop and drives, and the machine's own INI (LinuxCNC)
            "estop": bool(getattr(st, "estop", False)),
            "machine_on": bool(getattr(st, "machine_on", True)),
            "linuxcnc_ini": self._linuxcnc_ini(),
            **self._probe_status(st),
            **(self._lathe_status(st) if self.is_lathe else {}),
        }

    def on_alarm(self, listener: Callable[[Alarm, dict], None]) -> None:
        """``listener(alarm, probes)`` once for each alarm that appears (``probes``: ``{"probe",
        "tool_probe", "tool"}`` when it was seen). Seen on every status read and before a Reset or
        a scenario load clears the alarms, so no alarm goes unseen (design.md §10.4)."""
        self._alarm_listeners.append(listener)

    def on_scenario(self, listener: Callable[[], None]) -> None:
        """``listener()`` after a scenario load (another probe may be in the machine now)."""
        self._scenario_listeners.append(listener)

    def _see_alarms(self, st: MachineStatus | None = None) -> None:
        if not self._alarm_listeners:
            return
        st = st or self._machine.status()
        now = frozenset((a.code, a.text, a.resettable) for a in st.alarms)
        with self._lock:
            new = now - self._alarms_seen
            self._alarms_seen = now
        if not new:
            return
        probes = {**self._probe_status(st), "tool": st.tool}
        for alarm in sorted(st.alarms, key=lambda a: a.resettable):      # the graver (a broken probe) first
            if (alarm.code, alarm.text, alarm.resettable) in new:
                for listener in self._alarm_listeners:
                    listener(alarm, probes)

    def probe_identity(self, which: str = "workpiece") -> str | None:
        """A fingerprint of the scenario's probe (the tool probe: ``which="tool"``): what a real
        control knows as the probe's serial number; None when there is no such probe."""
        part = self._scenario.probe if which == "workpiece" else getattr(self._scenario, "tool_probe", None)
        if part is None:
            return None
        text = json.dumps(part.model_dump(mode="json", exclude={"radio"}), sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()[:16]

    def probe_status(self) -> dict:
        """``{"probe", "tool_probe"}`` of ``status()``, read alone (the probe test samples it)."""
        return self._probe_status(self._machine.status())

    def _linuxcnc_ini(self) -> str | None:
        machine = self._machine
        own = machine.own_ini if isinstance(machine, OwnConfiguration) else None
        return str(own) if own is not None else None

    def _probe_status(self, st: MachineStatus) -> dict:
        """``probe`` and ``tool_probe`` (design.md §10.4); a controller that cannot tell its
        probe's state shows only whether the probe is the tool in the spindle."""
        probe = st.probe or ProbeState(in_spindle=st.tool is not None and st.tool == self._scenario.probe.t,
                                       deflected=None)
        tool_probe = None
        if st.tool_probe is not None:
            tool_probe = {k: v for k, v in st.tool_probe.to_api().items() if k != "in_spindle"}
        return {"probe": probe.to_api(), "tool_probe": tool_probe}

    def set_probe(self, which: str, deflect=None, battery=None, armed=None) -> dict:
        """The operator's hand on a probe of the simulator (``POST /api/sim/probe``, design.md §10.4)."""
        simulator = self._simulator("a hand on the probe")
        try:
            simulator.set_probe(which, deflect, battery, armed)
        except ValueError as exc:
            field = str(exc).partition(":")[0]
            raise InvalidInput(str(exc), field=field if field in ("probe", "deflect", "battery", "armed")
                               else None) from None
        self.changes.notify()
        return self.status()

    def _lathe_status(self, st) -> dict:
        l1, l2 = getattr(st, "tool_lengths", (0.0, 0.0))
        return {"kind": "lathe", "plane": "G18", "diameter_programming": self.diameter_programming,
                "x_unit": "diameter" if self.diameter_programming else "radius",
                "tool_lengths": {"L1": float(l1), "L2": float(l2)}}

    # --- swivel head (CYCLE800-like re-alignment, jog-measuring §6.2) --------------------------------
    def _swivel_head(self) -> SwivelHead | None:
        return self._machine if self._is(SwivelHead) else None  # type: ignore[return-value]

    def has_swivel(self) -> bool:
        head = self._swivel_head()
        return head is not None and bool(head.has_swivel())

    def head_axes(self) -> tuple[str, ...]:
        """The swivel head's axes (A/B/C), in their order; () without a swivel head."""
        head = self._swivel_head()
        return tuple(head.head_axes()) if head is not None and head.has_swivel() else ()

    def retract_tool_axis(self, distance: float | None = None) -> dict:
        """Retract up along the tool axis (to the limits by default) before a swivel (jog-measuring §11 Q9)."""
        if distance is not None:
            distance = checks.number(distance, "distance")
        head = self._swivel_head()
        if head is None:
            raise InvalidInput("this machine has no swivel kinematics", field="retract")
        return self._run(lambda: head.retract_tool_axis(distance))

    def swivel_to_wcs(self) -> dict:
        """Swivel the head so that the tool axis is parallel to the active WCS's infeed axis."""
        head = self._swivel_head()
        if head is None or not self.has_swivel():
            raise InvalidInput("this machine has no swivel kinematics", field="realign")
        rotation = self._chain.wcs2bcs.as_matrix()[:3, :3]
        infeed = np.asarray(self.plane().infeed_unit, dtype=float)
        return self._run(lambda: head.swivel_to_wcs(rotation, infeed))

    # --- coordinates ----------------------------------------------------------------------
    def _tip(self, tool_length: float | None, st: MachineStatus | None = None) -> ToolTip | LatheToolTip:
        """Tool tip <-> axis positions in the active chain (``engine.coords``)."""
        if st is None:
            st = self._machine.status()
        if self.is_lathe:
            l1, l2 = getattr(st, "tool_lengths", (0.0, 0.0))
            return LatheToolTip(self._chain.wcs2bcs, float(l1), float(l2))
        if tool_length is None:
            tool_length = st.tool_length
        axis = length_axis(getattr(st, "tool_axis", None), self.plane().infeed_unit)
        return ToolTip(self._chain.wcs2bcs, float(tool_length), axis, head_shift_of(getattr(st, "head_shift", None)))

    def wcs_from_mcs(self, mcs: Mapping[str, float], tool_length: float | None = None,
                     st: MachineStatus | None = None) -> dict[str, float]:
        p_wcs = self._tip(tool_length, st).tip_in_wcs([float(mcs.get(a, 0.0)) for a in GEOMETRY_AXES])
        out = {a: float(v) for a, v in zip(GEOMETRY_AXES, p_wcs, strict=True)}
        if self.diameter_programming:
            out["X"] *= 2.0                      # DIAMON: WCS X as a diameter (turning.md §0.3)
        for axis in self.rotary_axes:
            if axis in mcs:
                out[axis] = float(mcs[axis]) - self._chain.wcs2bcs.rotary_offset(axis)
        return out

    def mcs_from_wcs(self, wcs: Mapping[str, float], tool_length: float | None = None) -> dict[str, float]:
        """Full WCS point (X, Y, Z; rotary optional) -> axis positions of the tool reference point."""
        if self.diameter_programming:
            wcs = {**wcs, "X": float(wcs["X"]) / 2.0}
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

    @overload
    def _check_feed(self, feed: None, field: str = ...) -> None: ...
    @overload
    def _check_feed(self, feed: float, field: str = ...) -> float: ...
    def _check_feed(self, feed, field: str = "feed") -> float | None:
        if feed is None:
            return None
        feed = checks.number(feed, field)
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
        self.interlock("jog")
        self._ensure_idle()
        with self._machine_errors():
            result = motion()
        return self._finish(result)

    def jog(self, axis: str, distance: float, feed: float | None = None) -> dict:
        axis = self._check_axis(axis)
        distance = checks.number(distance, "distance")
        if abs(distance) > MAX_TRAVEL:
            raise InvalidInput(f"distance: at most {MAX_TRAVEL:g} per jog", field="distance")
        feed = self._check_feed(feed)
        return self._run(lambda: self._machine.jog(axis, distance, feed))

    def jog_continuous(self, axis: str, direction: int, feed: float | None = None, tab: str | None = None,
                       press: int | None = None) -> dict:
        """Hold-to-run (design.md §9.1): starts the jog, or renews the running one of the same
        axis and direction, for at most ``HOLD_S``; without a renewal the axis stops.

        ``tab``/``press`` (issue 24 §6): the browser tab and its key press; a renewal of a press
        already released (queued behind the release) or of a tab whose live feed dropped is ignored."""
        axis = self._check_axis(axis)
        if direction not in (-1, 1):
            raise InvalidInput("direction: must be -1 or +1", field="direction")
        feed = self._check_feed(feed)
        if not self._hold.renew(axis, direction, tab, press) and not self._hold.stale(tab, press):
            self.interlock("jog")
            self._ensure_idle()
            with self._machine_errors():
                self._hold.start(axis, direction, feed, tab, press)
        return self.status()

    def stop(self) -> dict:
        self._hold.release()
        self._machine.stop()
        return self.status()

    def release_jog(self) -> None:
        """Another motion takes over the axes: the hold-to-run watchdog lets go of them."""
        self._hold.release()

    def stop_jog(self, tab: str | None = None, press: int | None = None) -> dict:
        """The operator let go of a jog key: stop the continuous jog if one is held, nothing else
        (a late key-up must not stop the measurement NC Start has started since). With ``tab`` and
        ``press`` only that tab's jog stops, and later renewals of that press are ignored."""
        if self._hold.release(tab, press):
            self._machine.stop()
        return self.status()

    def tab_gone(self, tab: str) -> None:
        """The live feed of ``tab`` dropped (the browser died or left): its held jog stops now."""
        if self._hold.tab_gone(tab):
            self._machine.stop()

    def tab_back(self, tab: str) -> None:
        self._hold.tab_back(tab)

    def close(self) -> None:
        self._hold.close()
        self._machine.close()

    def goto_target(self, target: Mapping[str, float | None], coords: str = "WCS") -> dict[str, float]:
        """Validated MCS target of a goto; axes not given keep their current position in ``coords``."""
        if coords not in ("WCS", "MCS"):
            raise InvalidInput("coords: must be WCS or MCS", field="coords")
        given = {}
        for axis, value in target.items():
            if value is None:
                continue
            axis = self._check_axis(axis, field=str(axis))
            given[axis] = checks.number(value, axis)
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
        d = np.array([checks.number(v, f"direction.{i}") for i, v in enumerate(direction)])
        norm = float(np.linalg.norm(d))
        if norm < 1e-9:
            raise InvalidInput("direction: must not be the zero vector", field="direction")
        d = d / norm
        if coords == "WCS":
            d = self._chain.wcs2bcs.dir_child2parent(d)
        distance = checks.number(distance, "distance")
        if not 0 < distance <= MAX_TRAVEL:
            raise InvalidInput(f"distance: must be > 0 and <= {MAX_TRAVEL:g}", field="distance")
        feed = self._check_feed(checks.number(feed, "feed"))
        self.interlock("probe")
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

    # --- one channel: Reset, the mode group, feed hold (issue 24 §3-4) ---------------------------
    def on_reset(self, stop: Callable[[], None], wait: Callable[[], None]) -> None:
        """A runner of motion (the NC channel, a JOG measurement) ends at a Reset: ``stop()`` tells
        it (no new motion), ``wait()`` returns when it has ended."""
        self._reset_listeners.append((stop, wait))

    def add_interlock(self, check: Callable[[str], None]) -> None:
        """``check(action)`` raises ``ModeError`` when ``action`` ("jog", "probe", "spindle",
        "tool_change", "scenario", "measure", "nc_run") is refused while something runs."""
        self._interlocks.append(check)

    def interlock(self, action: str) -> None:
        for check in self._interlocks:
            check(action)

    def reset(self) -> dict:
        """The channel's one Reset (panel key, ``/api/machine/reset``, ``/api/nc/reset``): the
        runners are told to stop, the motion stops, the runners end (program reset to its
        defaults, measurement aborted), feed hold ends, the resettable alarms are cleared."""
        self._hold.release()
        self._see_alarms()                      # a collision is seen before Reset clears it
        for stop, _wait in self._reset_listeners:
            stop()
        self._machine.reset()
        for _stop, wait in self._reset_listeners:
            wait()
        self.feed_hold(False)
        self._machine.reset()                   # a motion begun meanwhile, the alarms of the abort
        return self.status()

    def feed_hold(self, on: bool) -> None:
        """NC Stop holds the axes where they are (override 0 %); NC Start lets them go on at the
        override they had."""
        with self._lock:
            if on and self._held_override is None:
                self._held_override = float(self._machine.status().feed_override)
                self._machine.set_override(0.0)
            elif not on and self._held_override is not None:
                self._machine.set_override(self._held_override)
                self._held_override = None

    @property
    def feed_held(self) -> bool:
        return self._held_override is not None

    def spindle_position(self, angle: float) -> dict:
        """SPOS (deg, 0..360): on a lathe the clamped workpiece turns with the main spindle."""
        angle = checks.number(angle, "angle")
        if not 0.0 <= angle <= 360.0:
            raise InvalidInput("angle: SPOS 0..360 degrees", field="angle")
        self.interlock("spindle")
        self._ensure_idle()
        with self._machine_errors():
            self._machine.spindle_position(angle)
        return self.status()

    def set_override(self, percent: float) -> dict:
        percent = checks.number(percent, "feed")
        if not 0 <= percent <= 120:
            raise InvalidInput("feed: override must be 0..120 %", field="feed")
        with self._lock:
            if self._held_override is not None:       # held: the new override acts at NC Start
                self._held_override = float(percent)
            else:
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
        """Tool change. The database records the new tool first and is put back if the machine
        refuses: machine and database never disagree about the spindle (design.md §9.1)."""
        t = self.resolve_tool(tool)
        length = 0.0
        with self._db.unit(readonly=True) as unit:
            data = unit.get_tool(t) if t is not None else None
            previous = unit.get_state(STATE_TOOL, None)
        if t is not None:
            if data is None:
                raise NotFoundError(f"T{t} is not in the tool table", field="tool", code="unknown_tool")
            length = self.offset_length(data)
        self.interlock("tool_change")
        self._ensure_idle()
        with self._db.unit() as unit:
            unit.set_state(STATE_TOOL, t)
        try:
            with self._machine_errors():
                self._machine.change_tool(t, length)
        except BaseException as exc:
            with self._db.unit() as unit:
                unit.set_state(STATE_TOOL, previous)
            if isinstance(exc, ValueError):      # the tool table knows it, the machine's magazine does not
                raise InvalidInput(f"tool: {exc}", field="tool") from None
            raise
        self._discard(f"T{t} was loaded into the spindle" if t is not None else "The spindle was emptied")
        return self.status()

    # --- what stored measuring points depend on -------------------------------------------------
    def on_discard(self, listener: Callable[[str], None]) -> None:
        """``listener(reason)`` when stored measuring points lose their meaning (tool change,
        scenario load; design.md §9.1)."""
        self._discard_listeners.append(listener)

    def _discard(self, reason: str) -> None:
        for listener in self._discard_listeners:
            listener(reason)

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
        return isinstance(name, str) and name in self._db.offset_names() and not is_basic(name)

    def stored_frames(self) -> dict[str, Frame]:
        """Every stored frame, read once per database generation (``Database.generation``)."""
        generation = self._db.generation
        if self._frames is None or self._frames[0] != generation:
            with self._db.unit(readonly=True) as unit:
                self._frames = (generation, {n: Frame.from_api(f) for n, f in unit.list_offsets().items()})
        return dict(self._frames[1])

    def frames_written(self, generation: int, name: str, frame: Mapping) -> None:
        """A commit (``generation`` -> +1) that wrote only frame ``name``: the cache takes it."""
        if self._frames is not None and self._frames[0] == generation and self._db.generation == generation + 1:
            self._frames = (generation + 1, {**self._frames[1], name: Frame.from_api(frame)})

    def build_chain(self, active: str) -> FrameChain:
        return chain_of(self.stored_frames(), active)

    def activate(self, name: str) -> dict:
        self.make_active(name)
        return self.status()

    def make_active(self, name: str) -> None:
        """``activate`` without building the state to answer (a measurement's commit needs none)."""
        if not isinstance(name, str) or not self._is_settable(name.upper()):
            raise InvalidInput(f"offset: {name!r} is not a settable zero offset (G500, G54..)", field="offset")
        name = name.upper()
        with self._lock:
            self._check_chain_holds(name)
            chain = self.build_chain(name)
            wcs2bcs = chain.wcs2bcs
            self._machine.activate_frame(ActiveFrame(name=name, wcs2bcs=wcs2bcs.as_matrix(),
                                                     rotary_offsets=dict(wcs2bcs.rotary)))
            changed = name != self._active_offset
            self._chain, self._active_offset = chain, name
            if changed:          # re-activating the same WO (after a correction) needs no write
                with self._db.unit() as unit:
                    unit.set_state(STATE_ACTIVE_OFFSET, name)

    def _check_chain_holds(self, name: str) -> None:
        """Every frame of the chain ``name`` would make active (the basic frames and ``name``) is one
        the NC holds (design.md §10.7, issue 34 §5): LinuxCNC holds no rotation about X or Y and no
        basic frame, so such an activation is refused with the NC's alarm (409, 61321), nothing
        shown as active that the NC does not move by."""
        if not isinstance(self._machine, FrameCapacity):
            return
        with self._db.unit(readonly=True) as unit:
            stored = unit.list_offsets()
        names = [n for n in (SETFRAME, *basic_frame_names(stored)) if n in stored]
        for frame_name in [*names, *([name] if name != G500 and name in stored else [])]:
            self.check_holds(frame_name, stored[frame_name])

    def refresh_frame(self) -> None:
        """Re-compose the active chain after an offset was written (BASIC_*, or the active WO)."""
        self.make_active(self._active_offset)

    # --- scenario -----------------------------------------------------------------------------
    def _simulator(self, what: str) -> SimulatorControl:
        """The machine's simulator interface; a real controller has none (409 ``not_simulated``)."""
        if not isinstance(self._machine, SimulatorControl):
            raise ConflictError(f"{what} needs the simulator; the controller is {self._machine.controller!r}",
                                code="not_simulated")
        return self._machine

    def load_scenario(self, scenario: Scenario | LatheScenario, reset_data: bool = False) -> dict:
        """Reset the machine to ``scenario``; stored data stays unless ``reset_data``."""
        simulator = self._simulator("a scenario load")
        self.interlock("scenario")
        self._ensure_idle()
        self._hold.release()
        self._see_alarms()
        with self._lock:
            if getattr(scenario, "kind", "mill") != getattr(self._scenario, "kind", "mill"):
                self._switch_machine(scenario)
                reset_data = True            # the other machine's tools, offsets and records mean nothing here
            else:
                simulator.load(scenario)
            self._scenario = scenario
            self._seed_data(reset=reset_data)
            self._push_nc_data()
            self.make_active(G500 if reset_data else self._active_offset)
            with self._db.unit(readonly=True) as unit:
                tool = unit.get_state(STATE_TOOL, None)
            self._restore_tool(tool)
        self._discard("A scenario was loaded")
        for listener in self._scenario_listeners:
            listener()
        return self.status()

    def _switch_machine(self, scenario: Scenario | LatheScenario) -> None:
        """A scenario of the other kind (lathe <-> milling machine): build that machine."""
        if self._rebuild is None:
            raise InvalidInput(f"this HMI drives a {getattr(self._scenario, 'kind', 'mill')} machine; "
                               f"start it with the {scenario.kind} scenario", code="invalid_scenario")
        try:
            machine = self._rebuild(scenario)
        except ValueError as exc:
            raise InvalidInput(str(exc), code="invalid_scenario") from None
        old, self._machine = self._machine, machine
        self._hold.close()
        self._hold = HoldToRun(machine)
        old.close()

    def _restore_tool(self, tool) -> None:
        """Put the stored tool back into the spindle; the probe when none is stored or it is gone.
        A controller that refuses (a tool its own table lacks) keeps its spindle; its alarm shows."""
        try:
            try:
                self.change_tool(tool if tool is not None else self._scenario.probe.t)
            except NotFoundError:
                self.change_tool(self._scenario.probe.t)
        except AlarmError:
            pass                                   # posted by the machine (status().alarms)

    def _take_nc_tools(self) -> None:
        """A controller that owns its tool table (LinuxCNC with the machine's own INI,
        ``nc_tool_table()``) gives its lengths and radii to the stored tools at the start; a tool
        whose geometry + wear it holds already keeps the HMI's split."""
        machine = self._machine
        held = machine.nc_tool_table() if isinstance(machine, OwnConfiguration) else {}
        if not held:
            return
        with self._db.unit() as unit:
            for t, nc in held.items():
                stored = unit.get_tool(t)
                wear = (stored or {}).get("wear") or {}
                if stored is not None \
                        and abs(float(stored["length"]) + float(wear.get("length", 0.0)) - nc["length"]) < 1e-9 \
                        and abs(float(stored["radius"]) + float(wear.get("radius", 0.0)) - nc["radius"]) < 1e-9:
                    continue
                kind = stored["type"] if stored is not None else (PROBE_TOOL_TYPE if t == self._scenario.probe.t
                                                                  else 120)
                unit.put_tool(t, {"type": kind, "length": nc["length"], "radius": nc["radius"],
                                  "wear": {"length": 0.0, "radius": 0.0}}, source="controller",
                              detail={"reason": "the controller's tool table"})

    def _seed_data(self, reset: bool) -> None:
        """Tool table from the scenario's nominal values (probe included) when empty or on reset;
        on reset also identity offsets, uncalibrated probe records and default settings."""
        sc = self._scenario
        if isinstance(sc, LatheScenario):
            lathe_data.seed(self._db, sc, reset, int(self._settings.get().tool_probe_number))
            if reset:
                self._settings.reset_to_defaults()
            return
        with self._db.unit() as unit:
            tools = unit.list_tools()
            if reset:
                clear_stored_data(unit)         # the spindle empty too
            if reset or not tools:
                unit.put_tool(sc.probe.t, {"name": "3D probe", "type": PROBE_TOOL_TYPE,
                                           "length": sc.probe.nominal_length,
                                           "radius": sc.probe.nominal_ball_diameter / 2.0,
                                           "wear": {"length": 0.0, "radius": 0.0}})
                for nominal in sc.tools:
                    unit.put_tool(nominal.t, {"type": nominal.type, "length": nominal.nominal_length,
                                              "radius": nominal.nominal_radius,
                                              "wear": {"length": 0.0, "radius": 0.0}})
            if sc.tool_probe is not None:   # its disc diameter is commissioning data, like nominal tool data
                n = 1 if reset else int(self._settings.get().tool_probe_number)
                record = unit.get_tool_probe(n) or {}
                if not record.get("disc_diameter"):
                    unit.put_tool_probe(n, {**record, "disc_diameter": float(sc.tool_probe.disc_diameter)})
        if reset:
            self._settings.reset_to_defaults()

    def machine_part(self, scatter_sigma) -> dict:
        """The next part of the series (design.md §9.3): the stored points of the old one go."""
        if isinstance(scatter_sigma, bool) or not isinstance(scatter_sigma, int | float) \
                or not 0.0 <= scatter_sigma <= 1.0:
            raise InvalidInput("scatter_sigma: a number of mm 0..1", field="scatter_sigma")
        simulator = self._simulator("the next part")
        self._ensure_idle()
        with self._machine_errors():
            part = simulator.machine_part(float(scatter_sigma))
        self._discard(f"Part {part} was clamped")
        return {"part": part, **self.status()}

    def scene_geometry(self) -> dict:
        return self._simulator("the machine view").scene_geometry()

    # --- the NC's copy of offsets and tools ----------------------------------------------------
    def _push_nc_data(self) -> None:
        """Every stored offset and tool to the machine (start-up, scenario load). A value the
        controller cannot hold does not stop the HMI: its alarm is shown until Reset."""
        with self._db.unit(readonly=True) as unit:
            offsets = unit.list_offsets()
            tools = unit.list_tools()
        writes = [partial(self._machine.write_offset, name, self._nc_frame(frame)) for name, frame in offsets.items()]
        writes += [partial(self._machine.write_tool, tool["t"], self._nc_tool(tool)) for tool in tools]
        for write in writes:
            try:
                write()
            except MachineAlarm as exc:
                self._machine.post_alarm(exc.alarm)

    def _nc_frame(self, frame: Mapping) -> dict:
        """A stored frame with the components of the machine's axes (``{"trans", "fine", "rot"}``)."""
        axes = set(self.axes)
        return {part: {a: float(v) for a, v in (frame.get(part) or {}).items() if a in axes}
                for part in ("trans", "fine", "rot")}

    @staticmethod
    def _nc_tool(data: Mapping) -> dict:
        """Stored tool data as the Protocol names it: geometry and wear (a lathe tool's SL, L1, L2
        and their wear too)."""
        wear = data.get("wear") or {}
        nc_wear = {"length": float(wear.get("length", 0.0)), "radius": float(wear.get("radius", 0.0))}
        out: dict[str, object] = {"type": int(data["type"]), "length": float(data["length"]),
                                  "radius": float(data["radius"]), "wear": nc_wear}
        if data.get("l1") is not None or data.get("l2") is not None:
            out.update(sl=int(data.get("sl") or 0), l1=float(data.get("l1") or 0.0), l2=float(data.get("l2") or 0.0))
            nc_wear.update(l1=float(wear.get("l1") or 0.0), l2=float(wear.get("l2") or 0.0))
        return out

    def check_holds(self, name: str, frame: Mapping) -> None:
        """Before the db write: a frame this NC cannot hold as ``name`` (LinuxCNC: a tilted G54, a
        basic frame) is refused here, a 409 alarm, so the HMI never stores what the NC lacks."""
        machine = self._machine
        if not isinstance(machine, FrameCapacity):
            return
        refused = machine.holds(name, self._nc_frame(frame))
        if refused is not None:
            self._machine.post_alarm(refused)          # as the NC would show a refused write
            raise AlarmError(refused.code, refused.text)

    def write_offset(self, name: str, frame: Mapping) -> None:
        """The stored frame ``name`` to the NC (after the db write); a refusal is a 409 alarm."""
        with self._machine_errors():
            self._machine.write_offset(name, self._nc_frame(frame))

    def write_tool(self, t: int, data: Mapping) -> None:
        """The stored tool data of T ``t`` to the NC (after the db write); a refusal is a 409 alarm."""
        with self._machine_errors():
            self._machine.write_tool(int(t), self._nc_tool(data))


class HoldToRun:
    """The dead-man of a continuous jog: it runs while renewed, at most ``HOLD_S`` after the last
    renewal; a watchdog thread stops the axis otherwise (a lost tab, network or server)."""

    HOLD_S = 0.5
    PERIOD_S = 0.05
    MAX_TABS = 4096

    def __init__(self, machine: Machine):
        self._machine = machine
        self._lock = threading.Lock()
        self._jog: tuple[str, int] | None = None
        self._holder: tuple[str | None, int | None] = (None, None)     # (tab, press) holding the jog
        self._released: dict[str, int] = {}        # tab -> its highest released key press
        self._gone: set[str] = set()               # tabs whose live feed dropped
        self._deadline = 0.0
        self._closed = threading.Event()
        self._thread: threading.Thread | None = None

    def _stale(self, tab: str | None, press: int | None) -> bool:
        if tab is None:
            return False
        return tab in self._gone or (press is not None and press <= self._released.get(tab, 0))

    def stale(self, tab: str | None, press: int | None) -> bool:
        """A request of a released press or of a tab that is gone: it must not move anything."""
        with self._lock:
            return self._stale(tab, press)

    def start(self, axis: str, direction: int, feed: float | None, tab: str | None = None,
              press: int | None = None) -> None:
        with self._lock:
            if self._stale(tab, press):          # the release overtook this start
                return
            self._machine.jog_continuous(axis, direction, feed)
            self._jog, self._deadline = (axis, direction), time.monotonic() + self.HOLD_S
            self._holder = (tab, press)
            if self._thread is None:
                self._thread = threading.Thread(target=self._watch, name="hold-to-run", daemon=True)
                self._thread.start()

    def renew(self, axis: str, direction: int, tab: str | None = None, press: int | None = None) -> bool:
        """Renew the running jog of ``axis``/``direction`` (of this tab's press when given);
        False when there is none."""
        with self._lock:
            if self._jog != (axis, direction) or not self._machine.status().busy:
                return False
            if tab is not None and (self._holder != (tab, press) or self._stale(tab, press)):
                return False
            self._deadline = time.monotonic() + self.HOLD_S
            return True

    def release(self, tab: str | None = None, press: int | None = None) -> bool:
        """Forget the held jog; True when one was held. With ``tab`` (and ``press``): the release
        of that key press: later requests of it are stale, another tab's jog is not touched."""
        with self._lock:
            if tab is not None and press is not None:
                self._released[tab] = max(press, self._released.get(tab, 0))
                if len(self._released) > self.MAX_TABS:
                    self._released.pop(next(iter(self._released)))
            if tab is not None and self._holder[0] not in (None, tab):
                return False
            held, self._jog = self._jog is not None, None
            return held

    def tab_gone(self, tab: str) -> bool:
        """The tab's live feed dropped: True when it held the jog (now forgotten)."""
        with self._lock:
            self._gone.add(tab)
            self._released.pop(tab, None)
            if len(self._gone) > self.MAX_TABS:       # page loads make new tabs: forget the oldest
                self._gone = set(list(self._gone)[-self.MAX_TABS // 2:])
            if self._jog is None or self._holder[0] != tab:
                return False
            self._jog = None
            return True

    def tab_back(self, tab: str) -> None:
        with self._lock:
            self._gone.discard(tab)

    def close(self) -> None:
        self._closed.set()
        self.release()

    def _watch(self) -> None:
        while not self._closed.wait(self.PERIOD_S):
            with self._lock:
                if self._jog is None:
                    continue
                if not self._machine.status().busy:      # ran onto a limit or was stopped
                    self._jog = None
                    continue
                if time.monotonic() < self._deadline:
                    continue
                self._jog = None
            self._machine.stop()

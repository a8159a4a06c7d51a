"""LinuxCNC behind the ``Machine`` Protocol (design.md §9.6), through its python module.

LinuxCNC runs headless with the project's configuration (config.py, process.py); this class
commands it over NML (``linuxcnc.command``/``stat``/``error_channel``) and arms the probe
comparator (hal/jogprobe.comp) over HAL before every motion. The scenario's scene is the
truth the probe input is fed from: before each motion the contact along its straight path is
found exactly (the simulator's ``Contact``: ball vs. scene, pre-travel p(d)), and the
comparator switches at that path length. LinuxCNC itself moves the axes, stops them on the
probe input and reports its own faults; nothing of the simulator's motion, braking or latch
model is used.

Decisions (where the spec leaves room):
- Positions are LinuxCNC's machine coordinates of the spindle nose (joint positions, trivial
  kinematics). Positioning is ``G53 G0/G1`` (machine coordinates, whatever G5x, rotation and
  tool offset are active). ``G38.3`` cannot take G53, so its end point is converted into the
  active program coordinates from ``stat`` (g5x, XY rotation, G92, tool offset), exactly.
- LinuxCNC's tool length offset follows the HMI's: ``G43.1 Z<L1>`` with the offset length of
  ``change_tool``/``set_tool_offset``, so that LinuxCNC's own DRO shows the tool tip in its
  G5x like the HMI's WCS; machine-coordinate motion does not depend on it.
- The probe result is the comparator's latch (the switching instant interpolated inside the
  servo period, plus the scenario's signal latency ``machine.latency_s``, like a hardware
  encoder latch), not where the axes stopped and not ``stat.probed_position`` (which lands 1-2
  servo periods late: measured 5-8 µm at 300, 20-23 µm at 1000, 98 µm at 3000 mm/min). Both are kept in
  ``last_probe``. Probe repeatability: the switching point scatters by the scenario's
  ``probe.noise_sigma`` (seeded), pre-travel as the scenario says.
- A probe switch during G0/G1 or a jog is LinuxCNC's own fault ("Probe tripped during
  non-probe move" / "... jog") -> PROBE_COLLISION. Overtravel behind the first contact beyond
  ``probe.max_deflection`` (LinuxCNC's real braking at its acceleration) breaks the probe
  (PROBE_BROKEN, not resettable, until a tool change) like the simulator's rule. A cutter
  that meets the part trips the same input at the contact (a crash) -> PROBE_COLLISION.
- Limits: a target beyond the scenario's limits (= LinuxCNC's soft limits) is refused before
  moving with SOFTWARE_LIMIT; LinuxCNC's own limit errors map to it as well.
- Reset = ``abort`` (LinuxCNC also stops the spindle) + clearing the resettable alarms.
  ``stop()`` ends a continuous jog (a teleop jog, ``JOG_STOP``) at once; it aborts an MDI motion.
- Frames: G54..G59.3 are LinuxCNC's G5x (P1..P9): ``G10 L2 P<n> X Y Z R<rot Z>`` with
  trans + fine. LinuxCNC cannot hold a rotation about X or Y, nor frames that it has no place
  for (basic frames, BASIC_REF, G505..): such a write is refused with ZO_NUMBER before
  anything changes, unless the frame is the identity (nothing to hold, nothing lost). The
  active settable frame is also selected in LinuxCNC (``G54`` ..); G500 leaves LinuxCNC's
  selection as it is (LinuxCNC has no "no offset" system).
- Tool data: the tool table (Z = length + wear, D = 2·(radius + wear), the split in the
  comment), reloaded on every write. Spindle: M3/M4/M5; SPOS = ``M19 R<angle>``.
- Other LinuxCNC errors are CONTROLLER_ERROR with LinuxCNC's message.
- Only X, Y, Z: a scenario with rotary axes or a swivel head is refused at start.
"""

from __future__ import annotations

import logging
import math
import os
import re
import threading
import time
from pathlib import Path

import numpy as np

from engine import alarms

from ..alarm_book import AlarmBook
from ..checks import finite, positive
from ..contact import Contact, Event
from ..kinematics import Kinematics
from ..nc_data import NcData
from ..protocol import (
    ActiveFrame,
    Alarm,
    MachineAlarm,
    MachineBusy,
    MachineStatus,
    MoveResult,
    ProbeResult,
)
from ..scenario import GEOMETRY_AXES, Scenario
from ..scene import protection_data
from . import process as process_module
from .config import COMPONENT, TOOL_TABLE, scenario_tools, tool_table_text, write_config
from .modules import LinuxCncMissing, import_linuxcnc
from .own import OwnIni
from .own_probe import OwnProbing
from .process import LinuxCncProcess, LinuxCncStartError

log = logging.getLogger(__name__)

G5X = {"G54": 1, "G55": 2, "G56": 3, "G57": 4, "G58": 5, "G59": 6, "G59.1": 7, "G59.2": 8, "G59.3": 9}
NO_SWITCH = 1e30
TAKEN_S = 15.0         # how long LinuxCNC's task may take to take up an MDI block
BEGIN_S = 3.0          # how long a block that moves may take to be seen moving
POLL_S = 0.002
MIN_TRAVEL = 0.01       # mm: a shorter block may round to no motion at all in LinuxCNC's words
CONNECT_TIMEOUT_S = 10.0
HOMING_S = 60.0
PROBE_TYPE = 710


def data_folder(db_path: Path | str | None = None) -> Path:
    """Where the configuration goes: ``HMI_LINUXCNC_DIR``, else ``linuxcnc/`` next to the db
    (``--db``; a database URL: next to the default one)."""
    given = os.environ.get("HMI_LINUXCNC_DIR")
    if given:
        return Path(given)
    db = str(db_path) if db_path is not None else os.environ.get("HMI_DB_PATH", "data/hmi.db")
    if "://" in db:
        db = "data/hmi.db"
    return Path(db).resolve().parent / "linuxcnc"


def _num(value: float) -> str:
    """A G-code number: fixed point (G-code has no exponent), 10 decimals."""
    text = f"{value:.10f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


class LinuxCncMachine:
    """A 3-axis mill on LinuxCNC: the generated configuration with the touch probe fed from the
    scenario's scene, or (``ini``) the machine's own configuration and probe (own.py, own_probe.py)."""

    def __init__(self, scenario: Scenario, folder: Path | None = None, ini: Path | str | None = None,
                 db_path: Path | str | None = None) -> None:
        self._own: OwnIni | None = OwnIni(Path(ini)) if ini is not None else None
        if self._own is not None:
            scenario = self._own.scenario(scenario)
        if tuple(scenario.axes) != GEOMETRY_AXES or scenario.machine.kinematics is not None:
            raise LinuxCncStartError("the LinuxCNC configuration has the axes X, Y, Z only; the scenario has "
                                     f"{', '.join(scenario.axes)}" + (" and a swivel head" if scenario.machine.kinematics
                                                                     else ""))
        try:
            self._lc, self._hal = import_linuxcnc()
        except LinuxCncMissing as exc:
            raise LinuxCncStartError(str(exc)) from None
        self._scenario = scenario
        self._kin = Kinematics(scenario)
        self._contact = Contact(scenario, self._kin)
        self._rng = np.random.default_rng(scenario.seed)
        self._lock = threading.RLock()            # the adapter's state
        self._nml = threading.RLock()             # the command and error channels
        self._local = threading.local()           # one linuxcnc.stat per thread
        self._idle = threading.Condition(self._lock)
        self._busy = False
        self._abort = threading.Event()
        self._stop = threading.Event()
        self._jog: tuple[int, threading.Thread] | None = None
        self._alarms = AlarmBook(self._lock)      # shown alarms (alarm_book.py, shared with the simulators)
        self._messages: list[tuple[int, str]] = []
        self._nc = NcData(GEOMETRY_AXES)
        self._tools = scenario_tools(scenario)
        self._tool: int | None = scenario.probe.t
        self._offset_length = scenario.probe.nominal_length
        self._frame = ActiveFrame()
        self._override = 100.0
        self._spindle_angle = 0.0
        self._seq = 0
        self._closed = False
        self.last_probe: dict | None = None
        self._probing = OwnProbing(self) if self._own is not None else None
        self.attached = False
        t0 = time.monotonic()
        folder = Path(folder) if folder is not None else data_folder(db_path)
        if self._own is None:
            self._process = LinuxCncProcess(folder, lambda where: write_config(scenario, where))
        else:
            own = self._own
            self._process = LinuxCncProcess(folder, lambda _where: own.headless_copy(), component=False)
            self.attached = self._running_with(own)
        if not self.attached:
            self._process.start()
        try:
            self._connect()
        except BaseException:
            self._process.stop()
            raise
        self.startup_s = time.monotonic() - t0

    def _running_with(self, own: OwnIni) -> bool:
        """A LinuxCNC already runs the machine's INI (its own display, or a headless copy): attach.
        A stale instance this HMI started (its HMI gone) is not attached to: the start replaces it."""
        running_processes = process_module.running()
        if not process_module.LOCK_FILE.exists() or not running_processes \
                or process_module.stale_instance(running_processes) is not None:
            return False
        try:
            s = self._lc.stat()
            s.poll()
        except self._lc.error:
            return False
        running = Path(str(s.ini_filename or ""))
        if not running.name:
            return False
        if running.parent.resolve() != own.path.parent or running.name not in (own.path.name, own.headless_copy().name):
            raise LinuxCncStartError(f"a LinuxCNC with another configuration is running ({running}); stop it first")
        return True

    @property
    def own_ini(self) -> Path | None:
        """The machine's own INI file (``--linuxcnc-ini``), None on the generated configuration."""
        return None if self._own is None else self._own.path

    # --- connection -----------------------------------------------------------------------
    def _connect(self) -> None:
        lc = self._lc
        self._halcomp = self._hal.component(f"jogmeasure-hmi-{os.getpid()}")
        self._halcomp.ready()
        self._cmd = lc.command()
        self._err = lc.error_channel()
        deadline = time.monotonic() + CONNECT_TIMEOUT_S
        s = self._stat()
        while s.task_state not in (lc.STATE_ESTOP, lc.STATE_ESTOP_RESET, lc.STATE_OFF, lc.STATE_ON):
            if time.monotonic() > deadline:
                raise LinuxCncStartError("LinuxCNC's task does not answer")
            time.sleep(0.01)
            s = self._stat()
        if self._own is None:
            self._set_pin("latency", float(self._scenario.machine.latency_s))
        else:
            deadline += HOMING_S                # the machine's own homing moves the axes
        self._ensure_on()
        while not all(self._stat().homed[:3]):
            if time.monotonic() > deadline:
                raise LinuxCncStartError("LinuxCNC did not home")
            time.sleep(0.005)
        self._mdi("G21 G17 G90 G94 G40 G92.1")
        if self._own is None:
            self._mdi(f"T{self._tool} M6")
            self._mdi(f"G43.1 Z{_num(self._offset_length)}")
        else:                                   # the machine's tools: the table and the spindle as LinuxCNC has them
            s = self._stat()
            self._tools = self._own_tools(s)
            self._tool = int(s.tool_in_spindle) or None
            self._offset_length = float(s.tool_offset[2])
        self._drain()
        self._messages.clear()

    def _stat(self):
        """This thread's ``linuxcnc.stat``, polled now."""
        s = getattr(self._local, "stat", None)
        if s is None:
            s = self._local.stat = self._lc.stat()
        try:
            s.poll()
        except self._lc.error:            # a stale buffer: one new connection, then the error stands
            s = self._local.stat = self._lc.stat()
            s.poll()
        return s

    def _set_pin(self, name: str, value) -> None:
        self._hal.set_p(f"{COMPONENT}.{name}", repr(value) if isinstance(value, float) else str(value))

    def _pin(self, name: str):
        return self._hal.get_value(f"{COMPONENT}.{name}")

    def _drain(self) -> list[str]:
        """New messages from LinuxCNC's error channel; the errors' texts are returned."""
        lc = self._lc
        errors = []
        with self._nml:
            while True:
                try:
                    message = self._err.poll()
                except lc.error:          # "Error buffer invalid": seen once right after a start; reconnect
                    self._err = lc.error_channel()
                    try:
                        message = self._err.poll()
                    except lc.error:
                        break
                if not message:
                    break
                kind, text = message
                self._messages.append((kind, text))
                if kind in (lc.NML_ERROR, lc.OPERATOR_ERROR):
                    errors.append(text.strip())
        del self._messages[:-100]
        return errors

    # --- the Protocol's simple members -----------------------------------------------------
    @property
    def controller(self) -> str:
        return "linuxcnc"

    @property
    def axes(self) -> tuple[str, ...]:
        return GEOMETRY_AXES

    @property
    def scene(self):
        """The truth the probe input is fed from (tests only; the HMI never sees it)."""
        return self._contact.scene

    def protection_model(self) -> dict | None:
        """The start guard's model (issue 24 §1), as the simulator's: the generated configuration
        is commissioned from the scenario, so its scene and limits are this control's protection
        zones (plain data, MCS). The machine's own configuration has none (None): the guard says
        so in the plan and the warnings."""
        if self._own is not None:
            return None
        limits = {a: [float(lo), float(hi)] for a, (lo, hi) in self._kin.limits.items()}
        return {"bodies": protection_data(self._contact.scene), "limits": limits}

    def _position(self) -> np.ndarray:
        """The joint positions as the servo thread has them now (the comparator's own inputs):
        never a task cycle late, unlike ``stat.actual_position``."""
        if self._own is not None:
            return np.array([self._hal.get_value(f"joint.{j}.pos-fb") for j in range(3)], dtype=float)
        return np.array([self._pin("pos-x"), self._pin("pos-y"), self._pin("pos-z")], dtype=float)

    def status(self) -> MachineStatus:
        try:
            if self._closed:
                raise self._lc.error("LinuxCNC was stopped")
            s = self._stat()
            position = np.array(s.actual_position[:3], dtype=float)
            estop, machine_on = s.task_state == self._lc.STATE_ESTOP, s.task_state == self._lc.STATE_ON
            spindle = s.spindle[0]
            speed = float(spindle["speed"]) * (1.0 if spindle["direction"] >= 0 else -1.0) \
                if spindle["enabled"] else 0.0
        except self._lc.error as exc:
            position = getattr(self, "_last_position", np.zeros(3))
            speed = 0.0
            estop, machine_on = False, False
            if not self._closed:
                self._raise(Alarm.of(alarms.CONTROLLER_ERROR, f"LinuxCNC does not answer: {exc}"))
        self._last_position = position
        with self._lock:
            length = self._offset_length if self._tool is not None else 0.0
            tip = position - length * np.array([0.0, 0.0, 1.0])
            p_wcs = np.linalg.inv(np.asarray(self._frame.wcs2bcs, dtype=float)) @ np.append(tip, 1.0)
            return MachineStatus(
                mcs=self._kin.as_dict(position), wcs={a: float(p_wcs[i]) for i, a in enumerate(GEOMETRY_AXES)},
                active_offset=self._frame.name, tool=self._tool, tool_length=float(length),
                feed_override=float(self._override), spindle_angle=float(self._spindle_angle),
                spindle_speed=float(speed) if speed else 0.0, busy=self._busy, alarms=self._alarms.shown(),
                estop=bool(estop), machine_on=bool(machine_on))

    def post_alarm(self, alarm: Alarm) -> None:
        self._raise(alarm)

    def _raise(self, alarm: Alarm) -> Alarm:
        return self._alarms.raise_(alarm)

    def _break_probe(self) -> Alarm:
        return self._alarms.break_probe()

    def _controller_alarm(self, errors: list[str]) -> Alarm:
        """The catalogue entry for LinuxCNC's error messages (the first that names one)."""
        for text in errors:
            low = text.lower()
            if "probe tripped" in low:
                return Alarm.of(alarms.PROBE_COLLISION, f"Probe collision (LinuxCNC: {text})")
            if "exceed" in low and "limit" in low:
                return Alarm.of(alarms.SOFTWARE_LIMIT, f"Software limit switch (LinuxCNC: {text})")
        return Alarm.of(alarms.CONTROLLER_ERROR, f"LinuxCNC: {'; '.join(errors)}")

    # --- the one motion ------------------------------------------------------------------
    def _begin(self, may_move: bool = True) -> None:
        with self._lock:
            if self._closed:
                raise MachineAlarm(Alarm.of(alarms.CONTROLLER_ERROR, "LinuxCNC was stopped (the HMI is closing)"))
            if self._busy:
                raise MachineBusy("a motion is already running")
            if may_move:
                self._alarms.refuse_if_broken()
            self._busy = True
            self._abort.clear()
            self._stop.clear()

    def _finish(self) -> None:
        with self._idle:
            self._busy = False
            self._idle.notify_all()

    def _wait_idle(self, timeout: float = 3.0) -> None:
        deadline = time.monotonic() + timeout
        with self._idle:
            while self._busy and time.monotonic() < deadline:
                self._idle.wait(0.01)

    def _ensure_mode(self, mode) -> None:
        if self._stat().task_mode != mode:
            with self._nml:
                self._cmd.mode(mode)
                self._cmd.wait_complete(2.0)

    def _wait_taken(self, serial: int | None) -> None:
        """Until LinuxCNC's task echoes the command ``serial`` (it has taken the block up): before
        that, an idle status is the state before the block, not its end (seen on a loaded CI
        computer, where wait_complete's 2 s passed first)."""
        if serial is None:
            return
        deadline = time.monotonic() + TAKEN_S
        while int(self._stat().echo_serial_number) < serial:
            if self._abort.is_set() or self._stop.is_set():
                return
            if time.monotonic() > deadline:
                raise MachineAlarm(self._raise(Alarm.of(alarms.CONTROLLER_ERROR, "LinuxCNC: the block was not taken "
                                                        f"up within {TAKEN_S:.0f} s")))
            time.sleep(POLL_S / 2)

    def _wait_motion(self, timeout: float, start: np.ndarray | None = None, seq: int | None = None) -> str:
        """Until LinuxCNC is idle and the axes stand still: 'done', 'reset' or 'stop'.

        With ``start`` (a block that moves) the motion must first be seen to begin (the
        interpreter busy, a queue, the axes off ``start``, or the comparator armed as ``seq``
        tripped: a probe already switched does not move), within BEGIN_S: a status read before
        LinuxCNC took the block up must not count as its end (on a loaded computer LinuxCNC
        has been seen to take more than 0.5 s)."""
        lc = self._lc
        deadline = time.monotonic() + timeout
        if start is not None:
            self._wait_begun(start, seq)
        last, still = None, 0
        while True:
            s = self._stat()
            position = self._position()
            idle = s.interp_state == lc.INTERP_IDLE and s.queue == 0 and s.inpos and s.state != lc.RCS_EXEC
            still = still + 1 if last is not None and np.all(position == last) else 0
            if idle and still >= 2:
                break
            if time.monotonic() > deadline:
                with self._nml:
                    self._cmd.abort()
                raise MachineAlarm(self._raise(Alarm.of(alarms.CONTROLLER_ERROR, "LinuxCNC: the motion did not end "
                                                        f"within {timeout:.0f} s (aborted)")))
            last = position
            time.sleep(POLL_S)
        if self._abort.is_set():
            return "reset"
        if self._stop.is_set():
            return "stop"
        return "done"

    def _wait_begun(self, start: np.ndarray, seq: int | None) -> None:
        """Until the motion of a block from ``start`` is seen to begin (``_wait_motion``), a Reset
        or a stop, or at most BEGIN_S."""
        lc = self._lc
        begun = time.monotonic() + BEGIN_S
        while time.monotonic() < begun and not (self._abort.is_set() or self._stop.is_set()):
            s = self._stat()
            if s.interp_state != lc.INTERP_IDLE or s.queue > 0 or np.any(self._position() != start):
                return
            if seq is not None and self._tripped(seq):
                return
            time.sleep(POLL_S / 2)

    def _mdi(self, line: str, timeout: float = 10.0, start: np.ndarray | None = None,
             seq: int | None = None, travel: float = 0.0) -> tuple[list[str], str]:
        """One MDI block, waited for: (LinuxCNC's error texts, outcome); ``start`` for a block that
        moves, ``seq`` the comparator's arming for it (_wait_motion)."""
        for attempt in (1, 2):
            self._ensure_mode(self._lc.MODE_MDI)
            self._drain()
            with self._nml:
                self._cmd.mdi(line)
                serial = getattr(self._cmd, "serial", None)     # the command's number, echoed when taken up
                self._cmd.wait_complete(2.0)
            self._wait_taken(serial)
            outcome = self._wait_motion(timeout, start, seq)
            errors = self._drain()
            if (start is None or travel < MIN_TRAVEL or outcome != "done" or errors
                    or (seq is not None and self._tripped(seq)) or np.any(self._position() != start)):
                return errors, outcome
            # a block that moves ended where it began, and LinuxCNC said nothing (seen once on a
            # loaded CI computer, every block of one start): its late word, or its state, and once more
            time.sleep(0.2)
            errors = self._drain()
            if errors:
                return errors, outcome
            state = self._state_text()
            self._messages.append((0, f"block not run ({state}): {line}"))
            if attempt == 2:
                raise MachineAlarm(self._raise(Alarm.of(alarms.CONTROLLER_ERROR, "LinuxCNC did not run the block "
                                                        f"and gave no reason ({state})")))
            self._ensure_on()
        raise AssertionError("unreachable")

    def _state_text(self) -> str:
        s = self._stat()
        return (f"task_state {s.task_state}, task_mode {s.task_mode}, interp_state {s.interp_state}, "
                f"exec_state {s.exec_state}, state {s.state}, homed {list(s.homed[:3])}, enabled {s.enabled}, "
                f"paused {s.paused}, feedrate {s.feedrate}, rapidrate {s.rapidrate}, queue {s.queue}")

    def _ensure_on(self) -> None:
        """The machine on and homed, as after the start (a block that did not run)."""
        lc = self._lc
        with self._nml:
            if self._stat().task_state != lc.STATE_ON:
                for state in (lc.STATE_ESTOP_RESET, lc.STATE_ON):
                    self._cmd.state(state)
                    self._cmd.wait_complete(5.0)
            if not all(self._stat().homed[:3]):
                self._cmd.home(-1)
                self._cmd.wait_complete(5.0)

    def _setup(self, line: str) -> None:
        """A block that does not move (G10, G43.1, M19 ...): its errors are CONTROLLER_ERROR alarms."""
        errors, _ = self._mdi(line)
        if errors:
            raise MachineAlarm(self._raise(self._controller_alarm(errors)))

    def _arm(self, start: np.ndarray, d: np.ndarray, s_switch: float | None) -> int:
        """Arm the comparator for the straight path start + s·d; returns the arming's seq.
        The machine's own probe needs no arming (its switch in a non-probe move is LinuxCNC's error)."""
        if self._own is not None:
            self._seq += 1
            return self._seq
        for axis, p0, di in zip("xyz", start, d, strict=True):
            self._set_pin(f"p0-{axis}", float(p0))
            self._set_pin(f"d-{axis}", float(di))
        self._set_pin("s-switch", float(NO_SWITCH if s_switch is None else s_switch))
        self._seq += 1
        self._set_pin("seq", self._seq)
        deadline = time.monotonic() + 1.0
        while self._pin("armed") != self._seq:         # the servo thread has taken it (< 1 ms)
            if time.monotonic() > deadline:
                raise MachineAlarm(self._raise(Alarm.of(alarms.CONTROLLER_ERROR, "LinuxCNC: the probe comparator "
                                                        "does not run (servo thread stopped?)")))
            time.sleep(0.0005)
        return self._seq

    def _tripped(self, seq: int) -> bool:
        if self._own is not None:
            return False
        return self._pin("latched-seq") == seq

    def _latch(self) -> np.ndarray:
        return np.array([self._pin("latch-x"), self._pin("latch-y"), self._pin("latch-z")], dtype=float)

    def _event(self, start: np.ndarray, d: np.ndarray, length: float) -> Event | None:
        if self._own is not None:
            return None                         # the machine's own probe: no scene known
        with self._lock:
            tool, angle = self._tool, self._spindle_angle
        return self._contact.first_event(start, d, length, tool, angle)

    def _is_probe(self) -> bool:
        if self._own is not None:
            return self._tool is not None and self._tool == self._scenario.probe.t
        return self._contact.is_probe(self._tool)

    def _check_limits(self, target: np.ndarray) -> None:
        alarm = self._kin.limit_alarm(target)
        if alarm is not None:
            raise MachineAlarm(self._raise(alarm))

    @staticmethod
    def _timeout(length: float, feed_mm_min: float) -> float:
        return 10.0 + 3.0 * 60.0 * length / max(feed_mm_min, 1.0)

    def _effective(self, feed: float | None) -> float:
        if feed is None:
            return self._scenario.machine.rapid * max(min(self._override, 100.0), 1.0) / 100.0
        return feed * max(self._override, 1.0) / 100.0

    def _move(self, target: np.ndarray, feed: float | None) -> MoveResult:
        """Positioning in machine coordinates, the comparator armed with the path's first contact."""
        start = self._position()
        self._check_limits(target)
        delta = target - start
        length = float(np.linalg.norm(delta))
        if length == 0.0:
            return MoveResult(self._kin.as_dict(start), True)
        d = delta / length
        event = self._event(start, d, length)
        s_arm = None if event is None else (event.s_switch if event.kind == "switch" else event.s_contact)
        seq = self._arm(start, d, s_arm)
        words = " ".join(f"{a}{_num(v)}" for a, v in zip(GEOMETRY_AXES, target, strict=True))
        line = f"G90 G53 G0 {words}" if feed is None else f"G90 G53 G1 {words} F{_num(feed)}"
        errors, outcome = self._mdi(line, self._timeout(length, self._effective(feed)), start, seq, length)
        end = self._position()
        if outcome == "reset":
            return MoveResult(self._kin.as_dict(end), False, Alarm.of(alarms.RESET_ABORT, "Motion aborted by Reset"))
        if self._tripped(seq):
            return self._collision(event, start, d, end)
        if outcome == "stop":
            return MoveResult(self._kin.as_dict(end), False)
        if errors:
            alarm = self._raise(self._controller_alarm(errors))
            if alarm.is_(alarms.SOFTWARE_LIMIT):
                raise MachineAlarm(alarm)
            return MoveResult(self._kin.as_dict(end), False, alarm)
        return MoveResult(self._kin.as_dict(end), True)

    def _collision(self, event: Event | None, start, d, end) -> MoveResult:
        alarm = self._raise(Alarm.of(alarms.PROBE_COLLISION, event.text if event else "Probe collision"))
        if event is not None and event.kind == "switch" and self._is_probe():
            if float((end - start) @ d) - event.s_contact > self._scenario.probe.max_deflection:
                self._break_probe()
        return MoveResult(self._kin.as_dict(end), False, alarm)

    # --- motions -------------------------------------------------------------------------
    def _target(self, target_mcs: dict[str, float]) -> np.ndarray:
        if not isinstance(target_mcs, dict):
            raise ValueError("target must be a dict of axis -> position")
        target = self._position()
        for axis, value in target_mcs.items():
            target[self._kin.index(axis)] = finite(value, f"target.{axis}")
        return target

    def goto(self, target_mcs: dict[str, float], feed: float | None = None) -> MoveResult:
        target = self._target(target_mcs)
        if feed is not None:
            feed = positive(feed, "feed")
        self._begin()
        try:
            return self._move(target, feed)
        finally:
            self._finish()

    def jog(self, axis: str, distance: float, feed: float | None = None) -> MoveResult:
        index = self._kin.index(axis)
        distance = finite(distance, "distance")
        feed = self._scenario.machine.jog_feed if feed is None else positive(feed, "feed")
        self._begin()
        try:
            target = self._position()
            target[index] += distance
            return self._move(target, feed)
        finally:
            self._finish()

    def jog_continuous(self, axis: str, direction: int, feed: float | None = None) -> None:
        """A teleop jog towards the limit until ``stop()``, Reset, the limit or a probe switch."""
        index = self._kin.index(axis)
        if direction not in (1, -1):
            raise ValueError("direction must be +1 or -1")
        feed = self._scenario.machine.jog_feed if feed is None else positive(feed, "feed")
        self._begin()
        try:
            lc = self._lc
            start = self._position()
            lo, hi = self._kin.limits[axis]
            limit = hi if direction > 0 else lo
            d = np.zeros(3)
            d[index] = float(direction)
            length = abs(limit - start[index])
            event = self._event(start, d, length) if length > 0 else None
            s_arm = None if event is None else (event.s_switch if event.kind == "switch" else event.s_contact)
            seq = self._arm(start, d, s_arm)
            self._ensure_mode(lc.MODE_MANUAL)
            with self._nml:
                self._cmd.teleop_enable(1)
                self._cmd.wait_complete(2.0)
                self._drain()
                self._cmd.jog(lc.JOG_CONTINUOUS, False, index, direction * feed / 60.0)
        except BaseException:
            self._finish()
            raise

        def run() -> None:
            try:
                moved_at = time.monotonic()
                last = None
                while True:
                    time.sleep(POLL_S)
                    position = self._position()
                    if last is None or np.any(position != last):
                        moved_at = time.monotonic()
                    elif time.monotonic() - moved_at > 0.3 or self._stop.is_set() or self._abort.is_set() \
                            or self._tripped(seq):
                        break
                    last = position
                errors = self._drain()
                if self._abort.is_set() or self._stop.is_set():
                    return
                if self._tripped(seq):
                    self._collision(event, start, d, position)
                elif abs(position[index] - limit) < 1e-3:
                    self._raise(Alarm.of(alarms.SOFTWARE_LIMIT, f"Axis {axis} at software limit switch"))
                elif errors:
                    self._raise(self._controller_alarm(errors))
            finally:
                with self._lock:
                    self._jog = None
                self._finish()

        thread = threading.Thread(target=run, name="linuxcnc-jog", daemon=True)
        with self._lock:
            self._jog = (index, thread)
        thread.start()

    def _end_jog(self) -> None:
        with self._lock:
            jog = self._jog
        if jog is not None:
            with self._nml:
                self._cmd.jog(self._lc.JOG_STOP, False, jog[0])

    def stop(self) -> None:
        """Stop motion without an alarm: a continuous jog ends at once, an MDI motion is aborted."""
        with self._lock:
            busy, jogging = self._busy, self._jog is not None
        if not busy:
            return
        self._stop.set()
        if jogging:
            self._end_jog()
        else:
            with self._nml:
                self._cmd.abort()
        self._wait_idle()

    def reset(self) -> None:
        """Abort any motion (LinuxCNC's abort, which also stops the spindle), clear resettable alarms."""
        self._abort.set()
        self._end_jog()
        with self._nml:
            self._cmd.abort()
            self._cmd.wait_complete(2.0)
        self._wait_idle()
        self._drain()
        self._alarms.reset()

    def probe(self, direction, distance: float, feed: float) -> ProbeResult:
        """G38.3 along ``direction``; the result is the comparator's latch (the generated
        configuration) or LinuxCNC's own probed position, two-stage (own_probe.py)."""
        d = np.asarray(direction, dtype=float).reshape(-1)
        if d.shape != (3,) or not np.all(np.isfinite(d)) or not np.linalg.norm(d) > 0.0:
            raise ValueError("direction must be a finite, non-zero [dx, dy, dz]")
        d = d / np.linalg.norm(d)
        distance = positive(distance, "distance")
        feed = positive(feed, "feed")
        if self._probing is not None:
            self._begin()
            try:
                return self._probing.probe(d, distance, feed)
            finally:
                self._finish()
        self._begin()
        try:
            start = self._position()
            end = start + distance * d
            self._check_limits(end)
            override = self._override
            event = self._event(start, d, distance)
            s_arm = self._arm_distance(event)
            seq = self._arm(start, d, s_arm)
            program = self._program_point(end)
            words = " ".join(f"{a}{_num(v)}" for a, v in zip(GEOMETRY_AXES, program, strict=True))
            errors, outcome = self._mdi(f"G90 G38.3 {words} F{_num(feed)}",
                                        self._timeout(distance, feed * override / 100.0), start, seq, distance)
            reached = self._position()
            if outcome != "done":
                raise MachineAlarm(Alarm.of(alarms.RESET_ABORT, "Motion aborted by Reset" if outcome == "reset"
                                            else "Motion stopped"))
            if not self._tripped(seq):
                self.last_probe = {"tripped": False, "end": reached.tolist(), "start": start.tolist(),
                                   "planned_end": end.tolist(), "direction": d.tolist(), "s_switch": s_arm,
                                   "event": None if event is None else event.kind, "s": float(self._pin("s")),
                                   "armed": int(self._pin("armed")), "seq": seq, "errors": errors}
                return self._missed(errors, reached, feed, override)
            if event is None or event.kind == "crash":
                raise MachineAlarm(self._raise(Alarm.of(alarms.PROBE_COLLISION, event.text if event
                                                        else "Probe collision")))
            latched = self._latch()
            s = self._stat()
            self.last_probe = {"latch": latched.tolist(), "linuxcnc_probed": list(s.probed_position[:3]),
                               "linuxcnc_tripped": bool(s.probe_tripped), "end": reached.tolist(),
                               "start": start.tolist(), "direction": d.tolist(), "s_switch": s_arm,
                               "s_latch": float(self._pin("latch-s")), "feed": feed, "override": override}
            if self._is_probe() and float((reached - start) @ d) - event.s_contact > self._scenario.probe.max_deflection:
                raise MachineAlarm(self._break_probe())
            return ProbeResult(True, self._kin.as_dict(latched), self._kin.as_dict(reached), feed, override)
        finally:
            self._finish()

    def _arm_distance(self, event: Event | None) -> float | None:
        """Where along the probing the comparator is armed to switch: the scenario's switching
        point (with the probe's noise) or its contact; None without an event."""
        if event is None:
            return None
        s_arm = event.s_switch if event.kind == "switch" else event.s_contact
        sigma = self._scenario.probe.noise_sigma
        if event.kind == "switch" and self._is_probe() and sigma > 0.0:
            s_arm = max(0.0, s_arm + float(self._rng.normal(0.0, sigma)))
        return s_arm

    def _missed(self, errors: list[str], reached: np.ndarray, feed: float, override: float) -> ProbeResult:
        """A probing that did not switch: LinuxCNC's errors as an alarm, else the miss."""
        if errors:
            raise MachineAlarm(self._raise(self._controller_alarm(errors)))
        return ProbeResult(False, None, self._kin.as_dict(reached), feed, override)

    def _program_point(self, mcs: np.ndarray) -> np.ndarray:
        """Machine coordinates -> LinuxCNC's active program coordinates.

        LinuxCNC: machine_xy = Rot(r)·(prog_xy + g92_xy) + g5x_xy + tlo_xy; Z alike without rotation.
        """
        s = self._stat()
        g5x = np.array(s.g5x_offset[:3], dtype=float)
        g92 = np.array(s.g92_offset[:3], dtype=float)
        tlo = np.array(s.tool_offset[:3], dtype=float)
        r = math.radians(float(s.rotation_xy))
        v = mcs - g5x - tlo
        c, sn = math.cos(r), math.sin(r)
        return np.array([c * v[0] + sn * v[1], -sn * v[0] + c * v[1], v[2]]) - g92

    # --- without motion ------------------------------------------------------------------
    def _quiet(self, action) -> None:
        """A setting block now when the axes stand still, refused while they move."""
        self._begin(may_move=False)
        try:
            action()
        finally:
            self._finish()

    def change_tool(self, tool: int | None, offset_length: float) -> None:
        offset_length = finite(offset_length, "offset_length")
        if self._own is not None:
            if tool is not None and tool not in self._tools:       # refused, nothing changed: no lasting alarm
                raise MachineAlarm(Alarm.of(alarms.NO_TOOL_FOR_IDENTIFIER, f"No tool for the given tool "
                                            f"identifier: T{tool} is not in LinuxCNC's tool table"))
        elif tool is not None and tool != self._scenario.probe.t and self._scenario.tool(tool) is None:
            raise MachineAlarm(self._raise(Alarm.of(alarms.NO_TOOL_FOR_IDENTIFIER, f"No tool for the given tool "
                                                    f"identifier: T{tool} is not in the magazine")))

        def change() -> None:
            if tool is not None and tool not in self._tools:
                self._tools[tool] = {"type": 120, "length": offset_length, "radius": 0.0,
                                     "wear": {"length": 0.0, "radius": 0.0}}
                self._load_tool_table()
            self._setup(f"T{tool} M6" if tool is not None else "M61 Q0")
            self._setup(f"G43.1 Z{_num(offset_length)}" if tool is not None else "G49")
            with self._lock:
                self._tool, self._offset_length = tool, offset_length
                self._alarms.repair_probe()

        self._quiet(change)

    def set_tool_offset(self, offset_length: float) -> None:
        offset_length = finite(offset_length, "offset_length")
        self._quiet(lambda: self._setup(f"G43.1 Z{_num(offset_length)}"))
        with self._lock:
            self._offset_length = offset_length

    def write_tool(self, t: int, data: dict) -> None:
        self._nc.write_tool(t, data)                  # ValueError naming the field
        if self._own is not None:
            self._write_own_tool(t, self._nc.tools[t])
            return
        self._tools[t] = self._nc.tools[t]
        self._quiet(self._load_tool_table)

    # --- the machine's own tool table (LinuxCNC owns it: G10 L1, never the file) ------------------
    @staticmethod
    def _own_tools(s) -> dict[int, dict]:
        tools = {}
        for entry in s.tool_table:
            t = int(entry.id)
            if t > 0:
                tools[t] = {"type": 120, "length": float(entry.zoffset), "radius": float(entry.diameter) / 2.0,
                            "wear": {"length": 0.0, "radius": 0.0}}
        return tools

    def nc_tool_table(self) -> dict[int, dict]:
        """The machine's own tool table (``--linuxcnc-ini``): {T: {"length", "radius"}} as LinuxCNC
        holds it (the HMI takes it over at its start); {} on the generated configuration."""
        if self._own is None:
            return {}
        return {t: {"length": d["length"], "radius": d["radius"]} for t, d in self._tools.items()}

    def _write_own_tool(self, t: int, data: dict) -> None:
        """A tool LinuxCNC has gets the HMI's length and radius (geometry + wear) by ``G10 L1``; a tool
        it does not have stays the HMI's (LinuxCNC's table is the machine owner's)."""
        if t not in self._tools:
            return
        wear = data.get("wear") or {}
        length = float(data["length"]) + float(wear.get("length", 0.0))
        radius = float(data["radius"]) + float(wear.get("radius", 0.0))
        held = self._tools[t]
        if held["length"] == length and held["radius"] == radius:
            return
        self._quiet(lambda: self._setup(f"G10 L1 P{t} Z{_num(length)} R{_num(radius)}"))
        self._tools[t] = {**held, "length": length, "radius": radius}

    def _load_tool_table(self) -> None:
        (self._process.folder / TOOL_TABLE).write_text(tool_table_text(self._tools), encoding="utf-8")
        with self._nml:
            self._cmd.load_tool_table()
            self._cmd.wait_complete(2.0)
        errors = self._drain()
        if errors:
            raise MachineAlarm(self._raise(self._controller_alarm(errors)))

    def spindle_position(self, angle: float) -> None:
        """SPOS: ``M19 R<angle>`` (the orientation is wired in HAL; the eccentricity turns with it)."""
        angle = finite(angle, "angle") % 360.0
        self._quiet(lambda: self._setup(f"M19 R{_num(angle)}"))
        with self._lock:
            self._spindle_angle = angle

    def spindle_rotate(self, speed_rpm: float) -> None:
        speed = finite(speed_rpm, "speed_rpm")
        line = "M5" if speed == 0 else (f"M3 S{_num(speed)}" if speed > 0 else f"M4 S{_num(-speed)}")
        self._quiet(lambda: self._setup(line))

    def set_override(self, percent: float) -> None:
        percent = finite(percent, "percent")
        if not 0.0 <= percent <= 120.0:
            raise ValueError(f"feed override must be within 0..120 %, got {percent}")
        with self._nml:
            self._cmd.feedrate(percent / 100.0)
            self._cmd.rapidrate(min(percent, 100.0) / 100.0)
        with self._lock:
            self._override = percent

    # --- frames ---------------------------------------------------------------------------
    def holds(self, name: str, frame: dict) -> Alarm | None:
        """None when LinuxCNC can hold ``frame`` as ``name``, else the alarm a write would raise.

        For the HMI to ask before it measures into (or stores) a frame: a tilted plane into G54,
        a basic frame, G505.. (nothing is written, no alarm is posted)."""
        scratch = NcData(GEOMETRY_AXES)
        scratch.write_offset(name, frame)              # ValueError naming the field
        checked = scratch.offsets[name]
        if name not in G5X:
            if all(v == 0.0 for part in checked.values() for v in part.values()):
                return None                            # identity: nothing to hold, nothing lost
            return Alarm.of(alarms.ZO_NUMBER, f"Check ZO memory number: LinuxCNC cannot hold {name} (it has "
                            "G54..G59.3 only): nothing written")
        rot = checked["rot"]
        if rot.get("X", 0.0) != 0.0 or rot.get("Y", 0.0) != 0.0:
            return Alarm.of(alarms.ZO_NUMBER, f"Check ZO memory number: LinuxCNC's {name} holds no rotation about X "
                            f"or Y (rot X={rot.get('X', 0.0):g}, Y={rot.get('Y', 0.0):g}): nothing written")
        return None

    def write_offset(self, name: str, frame: dict) -> None:
        """G54..G59.3 into LinuxCNC's G5x (trans + fine, rotation about Z); see the module docstring."""
        refused = self.holds(name, frame)
        if refused is not None:
            raise MachineAlarm(self._raise(refused))
        if name not in G5X:                            # an identity frame LinuxCNC has no place for
            self._nc.write_offset(name, frame)
            return
        data = NcData(GEOMETRY_AXES)
        data.write_offset(name, frame)
        checked = data.offsets[name]
        rot_z = checked["rot"].get("Z", 0.0)
        trans = {a: checked["trans"].get(a, 0.0) + checked["fine"].get(a, 0.0) for a in GEOMETRY_AXES}
        words = " ".join(f"{a}{_num(trans[a])}" for a in GEOMETRY_AXES)
        self._quiet(lambda: self._setup(f"G90 G10 L2 P{G5X[name]} {words} R{_num(rot_z)}"))
        self._nc.write_offset(name, frame)

    def activate_frame(self, frame: ActiveFrame) -> None:
        matrix = np.asarray(frame.wcs2bcs, dtype=float)
        if matrix.shape != (4, 4) or not np.all(np.isfinite(matrix)):
            raise ValueError("frame.wcs2bcs must be a finite 4x4 matrix")
        with self._lock:
            self._frame = frame
        if frame.name in G5X:
            try:
                self._quiet(lambda: self._setup(frame.name))
            except MachineBusy:
                pass                     # display only: LinuxCNC's selection follows at the next activation

    # --- read-back (tests, diagnostics) ---------------------------------------------------
    def nc_offset(self, name: str) -> dict:
        """LinuxCNC's own G5x ``name`` (its parameters #5221.., read with a DEBUG message)."""
        base = 5201 + 20 * G5X[name]
        out: dict = {}

        def read() -> None:
            self._mdi(f"(DEBUG,G5X {base} #{base} #{base + 1} #{base + 2} #{base + 9})")
            for _, text in reversed(self._messages):
                match = re.search(rf"G5X {base} (\S+) (\S+) (\S+) (\S+)", text)
                if match:
                    x, y, z, r = (float(v) for v in match.groups())
                    out.update(trans={"X": x, "Y": y, "Z": z}, rot={"Z": r})
                    return
            raise RuntimeError(f"LinuxCNC did not answer the read of {name}")

        self._quiet(read)
        return out

    def nc_tool(self, t: int) -> dict:
        """LinuxCNC's tool data of T ``t``: {"length": Z, "diameter": D}, from the tool table file
        its io has loaded (``stat.tool_table`` comes through a memory map that the python module
        opens once per process: stale after a LinuxCNC restart in the same process)."""
        if self._own is not None:
            held = self._tools[t]
            return {"length": held["length"], "diameter": 2.0 * held["radius"]}
        text = (self._process.folder / TOOL_TABLE).read_text(encoding="utf-8")
        for line in text.splitlines():
            words = dict((w[0], w[1:]) for w in line.split(";", 1)[0].split())
            if words.get("T") == str(t):
                return {"length": float(words["Z"]), "diameter": float(words["D"])}
        raise KeyError(t)

    def linuxcnc_stat(self):
        """A polled ``linuxcnc.stat`` (read-only, for checks against LinuxCNC itself)."""
        return self._stat()

    # --- life cycle -------------------------------------------------------------------------
    def close(self) -> None:
        """Stop motion, then LinuxCNC; may be called again."""
        with self._lock:
            if self._closed:
                return
        try:
            self.stop()
            self._end_jog()
            with self._nml:
                self._cmd.abort()
        except Exception:   # noqa: BLE001 - LinuxCNC may already be gone; it is stopped below anyway
            log.info("closing: stopping LinuxCNC's motion failed (it may be gone already)", exc_info=True)
        self._wait_idle()
        with self._lock:
            self._closed = True
        try:
            self._halcomp.exit()
        except Exception:   # noqa: BLE001 - closing goes on; the HAL component goes with its process
            log.info("closing: the HAL component did not exit", exc_info=True)
        if not self.attached:                  # a LinuxCNC the HMI attached to runs on
            self._process.stop()

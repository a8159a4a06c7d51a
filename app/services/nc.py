"""Part programs on the product's machine (design.md §9.4): the NC runtime over the machine
service, the measuring environment of the cycles, one NC channel (MDA / AUTOMATIC) and the
stored programs.

- ``MachineRuntime`` implements ``app.nc.runtime.NcRuntime`` on ``MachineService``: motion and
  probing through the ``Machine`` Protocol, frames from the stored offsets (``build_chain``),
  activation and tool change through the machine service (so that JOG, the database and the
  machine agree), tool lengths L1 = geometry + wear from the tool table.
- ``NcMeasuringEnv`` is the JOG ``MeasuringEnv`` as a cycle sees it: the program's plane, the
  cycle's measuring path/feed/bits in place of the JOG settings, the program and block in the
  log entry; everything else (context snapshot, one-transaction commit, activation) is JOG's.
- ``NcService``: the channel. One interpreter (its modal state persists between runs like a real
  channel), run in a worker thread; ``run`` loads the MDA text or a stored program and starts it,
  ``start`` continues after M0 / single block / NC Stop, ``stop``, ``reset``; the mode (JOG, MDA,
  AUTO) is what the header and ``GET /api/machine`` show.
- ``ProgramService``: the programs table.
"""

from __future__ import annotations

import contextvars
import dataclasses
import logging
import re
import threading
from collections.abc import Mapping
from typing import Any

import numpy as np

from app import checks
from app.errors import ConflictError, HmiError, InvalidInput, ModeError, NotFoundError, TooLarge
from app.machine.lathe import LatheStatus
from app.machine.protocol import Lathe, MachineAlarm, MachineBusy
from app.nc import (
    CallbackBacking,
    Interpreter,
    NcRuntimeError,
    NcStateError,
    NcSyntaxError,
    VariableError,
    Variables,
)
from app.nc.cycles import measuring_cycles
from app.nc.interpreter import CycleContext
from app.nc.nodes import Assign
from app.nc.parser import MAX_PROGRAM_BYTES
from app.nc.runtime import MeasureResult
from app.nc.variables import InvalidValue
from app.services.machine_service import MachineService
from app.services.measuring import MeasuringEnv
from app.services.memories import MEMORY_COUNT, WRITE_FUNCTION
from app.services.memories import check_value as check_memory_value
from app.services.nc_records import tool_probe_backing
from app.services.probes import ToolProbeService
from app.services.protocols import ProtocolFileStore
from app.services.settings import SettingsService
from app.workflow.service import WorkflowService, system_frame_missing
from db import Database
from engine import alarms
from engine.frames import G500, FrameChain, is_basic
from engine.planes import plane as plane_by_name

log = logging.getLogger(__name__)

XYZ = ("X", "Y", "Z")
MDA = "MDA"
#: NC variables that are the HMI's stored data -> the access function their write needs on every
#: route (JSON API, screen, MDA, AUTO): one write path (issue 24 §7); the value checks and the
#: audit row are the data's own (``_memory_backing``: the memories' range, ``put_memory``'s audit)
PROTECTED = {"_EV": WRITE_FUNCTION, "_MV": WRITE_FUNCTION, "_TP": "probe_data", "_TPW": "probe_data"}


def protected_function(reference: str) -> str | None:
    """The access function a write of ``reference`` (``_EV[9]``, ``r1``) needs, or None."""
    return PROTECTED.get(reference.split("[", 1)[0].strip().upper())


class WriteRefused(VariableError):
    """A program assigns stored data its starter may not write: 17070, nothing written."""

    alarm = alarms.NC_WRITE_PROTECTED


#: how long a Reset waits for the program thread after its motion was aborted
RESET_WAIT_S = 2.0
#: what the mode group refuses from outside a running program (MachineService.interlock actions)
LOCKED_BY_A_PROGRAM = ("jog", "probe", "spindle", "tool_change", "scenario", "measure")
PROGRAM_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]{0,31}$")


# --- the runtime -----------------------------------------------------------------------------------

class MachineRuntime:
    """``NcRuntime`` on the machine service (see the module docstring)."""

    def __init__(self, machine_service: MachineService, db: Database):
        self._ms = machine_service
        self._db = db
        self._edge = 1
        self._tools: tuple[int, dict] | None = None

    @property
    def _machine(self):
        return self._ms.machine

    @staticmethod
    def _error(alarm) -> NcRuntimeError:
        definition = alarms.by_number(alarm.code) or alarms.NC_INTERNAL
        if alarm.code == alarms.PROBE_BROKEN.number:
            definition = alarms.PROBE_COLLISION if alarm.resettable else alarms.PROBE_BROKEN
        return NcRuntimeError(alarm.text, definition)

    def _checked(self, call):
        try:
            return call()
        except MachineAlarm as exc:
            raise self._error(exc.alarm) from None
        except MachineBusy as exc:
            raise NcRuntimeError(str(exc) or "a motion is running", alarms.NC_INTERNAL) from None
        except HmiError as exc:
            raise NcRuntimeError(exc.message, alarms.NC_VALUE_RANGE) from None
        except ValueError as exc:
            raise NcRuntimeError(str(exc), alarms.NC_VALUE_RANGE) from None

    # --- NcRuntime ---------------------------------------------------------------------------
    @property
    def axes(self) -> tuple[str, ...]:
        return self._ms.axes

    def position(self) -> dict[str, float]:
        return {a: float(v) for a, v in self._machine.status().mcs.items()}

    def move(self, target_mcs: Mapping[str, float], feed: float | None) -> None:
        result = self._checked(lambda: self._machine.goto({a: float(v) for a, v in target_mcs.items()}, feed))
        if not result.completed:
            if result.alarm is not None:
                raise self._error(result.alarm)
            raise NcRuntimeError("motion aborted", alarms.RESET_ABORT)

    def measure(self, target_mcs: Mapping[str, float], feed: float, stop_on_trigger: bool) -> MeasureResult:
        start = self._machine.status().mcs
        d = np.array([float(target_mcs.get(a, start[a])) - float(start[a]) for a in XYZ])
        distance = float(np.linalg.norm(d))
        if distance == 0.0:
            raise NcRuntimeError("measuring move without path", alarms.NO_MEASURING_PATH)
        before = len(self._machine.status().alarms)
        result = self._checked(lambda: self._machine.probe(d / distance, distance, feed))
        new = self._machine.status().alarms[before:]
        if new:                                   # broken probe, limit switch
            raise self._error(new[-1])
        if result.triggered and not stop_on_trigger:
            # MEAW: on to the end point (the simulator's stylus cannot be pushed on: a remaining
            # path is a collision there, as a real probe would be deflected further)
            self.move(target_mcs, feed)
        return MeasureResult(bool(result.triggered), dict(result.latched_mcs) if result.triggered else None)

    def offset_chain(self, name: str) -> FrameChain:
        if name != G500 and (is_basic(name) or name not in self._db.offset_names()):
            raise NcRuntimeError(f"zero offset {name} does not exist", alarms.ZO_NUMBER)
        return self._ms.build_chain(name)

    def active_offset(self) -> str:
        return self._ms.active_offset

    def activate_offset(self, name: str) -> None:
        self.offset_chain(name)
        self._checked(lambda: self._ms.activate(name))

    @property
    def is_lathe(self) -> bool:
        """A lathe: the interpreter runs the words of manual ch. 6 (app.nc.scope.LATHE_WORDS)."""
        return bool(self._ms.is_lathe)

    @property
    def diameter_programming(self) -> bool:
        """The lathe's DIAMON after Reset (the machine's setting, turning.md §0.3)."""
        return bool(self._ms.diameter_programming)

    def lathe_lengths(self) -> tuple[float, float]:
        """The NC's effective (L1, L2) of the tool in the turret (geometry + wear)."""
        status = self._machine.status()
        l1, l2 = status.tool_lengths if isinstance(status, LatheStatus) else (0.0, 0.0)
        return float(l1), float(l2)

    def tool_state(self) -> tuple[int | None, int]:
        tool = self._machine.status().tool
        return tool, (self._edge if tool is not None else 0)

    def _tool_row(self, tool: int) -> dict | None:
        generation = self._db.generation
        if self._tools is None or self._tools[0] != generation:
            with self._db.unit(readonly=True) as unit:
                self._tools = (generation, {t["t"]: t for t in unit.list_tools()})
        return self._tools[1].get(tool)

    def tool_length(self, tool: int | None, edge: int) -> float:
        if tool is None or edge == 0:
            return 0.0
        row = self._tool_row(tool)
        if row is None:
            raise NcRuntimeError(f"T{tool} is not in the tool list", alarms.NO_TOOL_FOR_IDENTIFIER)
        if edge != 1:
            raise NcRuntimeError(f"T{tool} has only D1", alarms.NC_D_NUMBER)
        return float(MachineService.offset_length(row))

    def change_tool(self, tool: int | None, edge: int) -> None:
        self.tool_length(tool, edge)
        self._checked(lambda: self._ms.change_tool(tool if tool is not None else 0))
        self._edge = edge
        if tool is not None and edge == 0:
            self._checked(lambda: self._machine.set_tool_offset(0.0))

    def select_edge(self, edge: int) -> None:
        tool = self._machine.status().tool
        length = self.tool_length(tool, edge)
        self._checked(lambda: self._machine.set_tool_offset(length))
        self._edge = edge

    def spindle(self, direction: int, speed: float) -> None:
        self._checked(lambda: self._machine.spindle_rotate(float(speed) if direction else 0.0))

    def spindle_position(self, angle: float) -> None:
        self._checked(lambda: self._machine.spindle_position(float(angle)))


# --- the measuring environment of a cycle ----------------------------------------------------------

class NcMeasuringEnv:
    """``WorkflowEnv`` of one cycle call: JOG's ``MeasuringEnv`` with the program's plane and the
    cycle's settings, the program and block in the log."""

    def __init__(self, base: MeasuringEnv, plane: str, settings: Mapping[str, Any], log_extra: Mapping[str, Any]):
        self._base = base
        self._plane = plane_by_name(plane)
        self._settings = dict(settings)
        self._log = dict(log_extra)

    @property
    def machine(self):
        return self._base.machine

    def _gud(self, gud):
        known = {k: v for k, v in self._settings.items() if k in type(gud).model_fields}
        return gud.model_copy(update=known)

    def measuring_setup(self):
        setup = self._base.measuring_setup()
        return dataclasses.replace(setup, plane=self._plane, settings=self._gud(setup.settings))

    def measuring_context(self):
        ctx = self._base.measuring_context(probe_number=self._settings.get("probe_record"))
        extra = ctx.extra
        if "diamon" in self._settings and "lathe" in (extra or {}):
            # the program's DIAMON/DIAMOF, not the machine's default (manual ch. 6)
            extra = {**extra, "lathe": {**extra["lathe"], "diamon": bool(self._settings["diamon"])}}
        return dataclasses.replace(ctx, plane=self._plane, settings=self._gud(ctx.settings), extra=extra)

    def commit_measurement(self, *, log_entry: dict, **commit):
        entry = dict(log_entry)
        entry["program"] = self._log.get("program")
        entry["block"] = self._log.get("block")
        entry["params"] = {**(entry.get("params") or {}), "cycle": self._log.get("cycle")}
        return self._base.commit_measurement(log_entry=entry, **commit)

    def activate(self, name: str) -> None:
        self._base.activate(name)

    def refresh_frames(self) -> None:
        self._base.refresh_frames()

    def post_alarm(self, code: int, text: str) -> None:
        self._base.post_alarm(code, text)

    def interlock(self, action: str) -> None:
        self._base.interlock(action)        # the channel's own thread passes (NcService.interlock)


class _CycleMeasuring:
    """``app.nc.cycles.NcMeasuring`` over an ``NcMeasuringEnv``."""

    def __init__(self, env: NcMeasuringEnv, on_workflow=None):
        self._env = env
        self._on_workflow = on_workflow

    def setup(self):
        return self._env.measuring_setup()

    def context(self):
        return self._env.measuring_context()

    def workflow(self, tasks):
        workflow = WorkflowService(self._env, tasks)
        if self._on_workflow is not None:
            self._on_workflow(workflow)         # a Reset aborts the cycle's measurement too
        return workflow


def _json_ready(value):
    if isinstance(value, dict):
        return {str(k): _json_ready(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_json_ready(v) for v in value]
    return value


# --- the channel --------------------------------------------------------------------------------------

def check_size(text: str, field: str) -> str:
    """A program text the NC reads: at most ``MAX_PROGRAM_BYTES`` (UTF-8), else 413."""
    size = len(text) if len(text) * 4 <= MAX_PROGRAM_BYTES else len(text.encode("utf-8"))
    if size > MAX_PROGRAM_BYTES:
        raise TooLarge(f"{field}: the program has {size} bytes; at most {MAX_PROGRAM_BYTES} "
                       f"({MAX_PROGRAM_BYTES // 1024} KiB)", field=field)
    return text


class NcSyntaxInput(InvalidInput):
    """A program that cannot run as written: 422 naming line and column, nothing moved."""

    code = "nc_syntax"

    def __init__(self, error: NcSyntaxError, field: str):
        super().__init__(str(error), field=field)
        self.detail = error.to_dict()


class NcService:
    """One NC channel (CHAN1): the interpreter, its worker thread, the mode, the MDA buffer."""

    def __init__(self, db: Database, machine_service: MachineService, env: MeasuringEnv,
                 settings: SettingsService):
        self._db = db
        self._ms = machine_service
        self._env = env
        self._settings = settings
        self.runtime = MachineRuntime(machine_service, db)
        self.variables = Variables(axes=machine_service.axes, backings={
            "_EV": _memory_backing(db, "EV", self._may_write), "_MV": _memory_backing(db, "MV", self._may_write),
            **{name: tool_probe_backing(name, ToolProbeService(db, settings), self._on_lathe, self._may_write)
               for name in ("_TP", "_TPW")}})
        self.protocol_files = ProtocolFileStore(db)     # CYCLE100..CYCLE106 write here (design.md §10.3)
        self.cycles = measuring_cycles(self)
        self.interpreter = Interpreter(self.runtime, self.variables, self.cycles)
        self._lock = threading.RLock()
        self._thread: threading.Thread | None = None
        self._source: str | None = None           # "MDA" or the name of the stored program loaded
        self._text: str = ""                      # the text loaded (MDA buffer or program)
        self.mda_text: str = ""                   # the MDA editor's buffer
        self.single_block = False
        self._crash: str | None = None
        self._authorize = None                    # the access check of who started the run
        self._cycle_workflow: WorkflowService | None = None   # the measurement of the cycle running
        machine_service.on_reset(self._reset_stop, self._reset_wait)
        machine_service.add_interlock(self.interlock)

    def _on_lathe(self) -> bool:
        return isinstance(self._ms.machine, Lathe)

    # --- cycle host ------------------------------------------------------------------------------
    def authorize(self, category, target) -> None:
        """A cycle is about to write into ``target``: the level of who started the run must
        allow it (the API and the screens hand in their check with the run)."""
        if self._authorize is not None:
            self._authorize(category, target)

    def _may_write(self, name: str) -> None:
        """Before a program's write of stored data lands: the starter's level (17070 else)."""
        function = PROTECTED.get(name)
        if function is None or self._authorize is None or threading.current_thread() is not self._thread:
            return
        try:
            self._authorize(None, None, function=function)
        except HmiError as exc:
            raise WriteRefused(f"{name}: {exc.message}") from None

    def _check_writes(self, authorize) -> None:
        """Before NC Start: every assignment of the program to stored data must be allowed to
        who starts it (403 ``access_level``, nothing moved), as the JSON API refuses it."""
        program = self.interpreter.program
        if authorize is None or program is None:
            return
        names = {w.target.name for b in program.blocks for w in b.words
                 if isinstance(w, Assign) and w.target.name in PROTECTED}
        for name in sorted(names):
            authorize(None, None, function=PROTECTED[name])

    def system_frame_missing(self) -> str | None:
        return system_frame_missing(self._ms.machine)

    def measuring(self, ctx: CycleContext, settings: Mapping[str, Any], cycle: Mapping[str, Any]):
        block = ctx.block
        text = block.text.strip()
        log_extra = {"program": self._source or MDA, "block": (f"L{block.line}: {text}")[:200],
                     "cycle": _json_ready({**cycle, "block": block.number, "line": block.line})}
        return _CycleMeasuring(NcMeasuringEnv(self._env, settings.get("plane", ctx.modal.plane), settings, log_extra),
                               on_workflow=self._set_cycle_workflow)

    def _set_cycle_workflow(self, workflow: WorkflowService) -> None:
        self._cycle_workflow = workflow

    # --- state -------------------------------------------------------------------------------------
    @property
    def loaded_text(self) -> str:
        """The text of the program in the channel ("" when none)."""
        return self._text if self._source is not None else ""

    @property
    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    @property
    def mode(self) -> str:
        """JOG, or MDA/AUTO while a program is active (running, interrupted, in alarm, or
        selected for AUTOMATIC and not yet started)."""
        state = self.interpreter.state
        if self._source is None:
            return "JOG"
        if state in ("running", "stopped", "alarm") or self.running:
            return MDA if self._source == MDA else "AUTO"
        if state == "ready" and self._source != MDA:
            return "AUTO"
        return "JOG"

    def status(self) -> dict:
        st = self.interpreter.status()
        last = self.interpreter.last_result
        alarm = st["alarm"]
        if self._crash and alarm is None and st["state"] == "alarm":
            alarm = {"code": alarms.NC_INTERNAL.number, "message": self._crash}
        state = "running" if self.running else ("idle" if self._source is None else st["state"])
        reason = last.reason if last else None
        if self.running and self._ms.feed_held:
            state, reason = "stopped", "feed_hold"          # NC Stop: held in the block, NC Start goes on
        return {"mode": self.mode, "program": self._source, "block": st["block"] if self._source else None,
                "state": state, "alarm": alarm,
                "reason": reason, "single_block": self.single_block,
                "message": st["message"], "modal": st["modal"]}

    def result(self) -> dict:
        """The design.md §9.4 answer of a run: state, block, alarm (+ reason, mode, program)."""
        st = self.status()
        last = self.interpreter.last_result
        block = last.block.to_dict() if last and last.block else st["block"]
        state = st["state"]
        if state in ("ready", "idle"):
            state = "stopped"
        return {"state": state, "block": block, "alarm": st["alarm"], "reason": st["reason"],
                "mode": st["mode"], "program": st["program"]}

    # --- programs into the channel -------------------------------------------------------------------
    def check(self, text: str, name: str = MDA) -> dict | None:
        """The syntax check of ``text`` as a load would make it (None = runs), without loading."""
        probe = Interpreter(self.runtime, Variables(axes=self._ms.axes), self.cycles)
        try:
            probe.load(text, name)
        except NcSyntaxError as exc:
            return exc.to_dict()
        return None

    def _load(self, text: str, source: str, field: str) -> None:
        if self.running:
            raise ConflictError("a program is running: NC Stop or Reset first", code="busy")
        try:
            self.interpreter.load(text, source)
        except NcSyntaxError as exc:
            raise NcSyntaxInput(exc, field) from None
        except NcStateError as exc:
            raise ConflictError(str(exc), code="busy") from None
        self._source, self._text, self._crash = source, text, None
        self._clear_results()

    def _clear_results(self) -> None:
        """_OVR/_OVI to 0: the results shown belong to the run that made them (issue 29 item 6);
        a program loaded or run again from its start has none yet. A cycle clears them too."""
        for name, size in (("_OVR", 32), ("_OVI", 14)):
            for i in range(size):
                self.variables.set(name, 0.0 if name == "_OVR" else 0, (i,))

    def user_hook(self, name: str) -> str | None:
        """CYCLE198 / CYCLE199 (manual §3.2): the stored program of that name, or None."""
        with self._db.unit(readonly=True) as unit:
            program = unit.get_program(name)
        return None if program is None else str(program["text"])

    def _program_text(self, name: str) -> str:
        with self._db.unit(readonly=True) as unit:
            program = unit.get_program(name)
        if program is None:
            raise NotFoundError(f"program {name!r} does not exist", field="program", code="unknown_program")
        return program["text"]

    def select(self, name: str) -> dict:
        """Select a stored program for AUTOMATIC (loaded, ready for NC Start)."""
        with self._lock:
            self._load(self._program_text(name), name, "program")
        return self.status()

    def run(self, *, program: str | None = None, mda: str | None = None, wait: bool = True,
            single_block: bool | None = None, authorize=None) -> dict:
        """Load the MDA text or a stored program and start it from its first block."""
        if (program is None) == (mda is None):
            raise InvalidInput("give either program (a stored program's name) or mda (the text)", field="program")
        if mda is not None:
            check_size(mda, "mda")
        self._ms.interlock("nc_run")
        with self._lock:
            if program is not None:
                self._load(self._program_text(program), program, "program")
            elif mda is not None:                 # always here: exactly one of them was given
                self.mda_text = mda
                self._load(mda, MDA, "mda")
            self._check_writes(authorize)
            if single_block is not None:
                self.single_block = bool(single_block)
            self._launch(authorize)
        return self._answer(wait)

    def start(self, *, wait: bool = True, single_block: bool | None = None, authorize=None) -> dict:
        """NC Start: continue the loaded program (after M0, single block, NC Stop), or run it
        again from the start when it has ended."""
        with self._lock:
            if self.running and self._ms.feed_held:        # held by NC Stop: the axes go on
                self.interpreter.cancel_stop()
                self._ms.feed_hold(False)
                return self._answer(wait)
            if self.running:
                raise ConflictError("the program is already running", code="busy")
            self._ms.interlock("nc_run")
            self._ms.feed_hold(False)
            state = self.interpreter.state
            if state == "idle" or self._source is None:
                raise ConflictError("no program loaded: run an MDA text or select a program", code="no_program")
            if state == "alarm":
                raise ConflictError("the channel has an alarm: press Reset first", code="alarm")
            if state == "done":
                self.interpreter.load(self._text, self._source)
                self._clear_results()
            self._check_writes(authorize)
            if single_block is not None:
                self.single_block = bool(single_block)
            self._launch(authorize)
        return self._answer(wait)

    def _launch(self, authorize=None) -> None:
        machine = self._ms.machine.status()
        if machine.busy:
            raise ConflictError("the machine is moving: wait or press Reset", code="busy")
        single = self.single_block
        interp = self.interpreter

        def work() -> None:
            try:
                interp.step() if single else interp.run()
            except Exception as exc:           # an interpreter bug: the channel shows it
                log.exception("NC channel crashed")
                self._crash = f"internal error: {exc}"
            finally:
                self._ms.feed_hold(False)        # stopped at a block's end: JOG moves at its override again

        self._authorize = authorize
        context = contextvars.copy_context()        # who pressed NC Start acts in the thread too (audit)
        thread = threading.Thread(target=context.run, args=(work,), name="nc-channel", daemon=True)
        self._thread = thread
        thread.start()

    def _answer(self, wait: bool) -> dict:
        thread = self._thread
        if wait and thread is not None:
            thread.join()
            return self.result()
        return {**self.result(), "state": "running" if self.running else self.result()["state"]}

    def wait(self, timeout: float | None = None) -> dict:
        thread = self._thread
        if thread is not None:
            thread.join(timeout)
        return self.result()

    def stop(self) -> dict:
        """NC Stop (feed hold): the axes stand where they are and the program stops at the end of
        its block; NC Start lets the axes go on and the program continue."""
        if self.running:
            self._ms.feed_hold(True)
        self.interpreter.request_stop()
        return self.status()

    def reset(self) -> dict:
        """NC Reset is the channel's one Reset (``MachineService.reset``): the program and its
        motion end, modal state to the defaults, measuring offsets cleared, the machine's alarms
        cleared, the program deselected; mode JOG."""
        self._ms.reset()
        return self.status()

    def _reset_stop(self) -> None:
        """Reset, first step: no new block and no new motion of a cycle."""
        self.interpreter.request_stop()
        workflow = self._cycle_workflow
        if workflow is not None:
            workflow.abort()

    def _reset_wait(self) -> None:
        """Reset, second step (the motion has been aborted): the program has ended; the channel
        back to its reset state."""
        thread = self._thread
        if thread is not None and thread is not threading.current_thread():
            thread.join(RESET_WAIT_S)
        if self.running:
            log.error("NC Reset: the program thread did not end within %.1f s", RESET_WAIT_S)
            return
        with self._lock:
            self.interpreter.reset()
            self._source, self._crash, self._cycle_workflow = None, None, None

    def lock(self) -> dict | None:
        """``{"mode", "program"}`` while a program runs (the screens grey out what it locks)."""
        if not self.running:
            return None
        program = self._source or MDA
        return {"mode": MDA if program == MDA else "AUTO", "program": program}

    def interlock(self, action: str) -> None:
        """The mode group: while a program runs in MDA/AUTO, motion and changes from outside
        the program are refused (409 ``mode`` naming the program); the program's own thread
        passes."""
        lock = self.lock()
        if lock is None or threading.current_thread() is self._thread or action not in LOCKED_BY_A_PROGRAM:
            return
        raise ModeError(f"Program {lock['program']} runs in {lock['mode']}: locked until the program ends "
                        "(NC Stop holds it, Reset ends it)", extra={**lock, "action": action})

    def set_single_block(self, on: bool) -> dict:
        self.single_block = bool(on)
        return self.status()

    # --- variables -----------------------------------------------------------------------------------
    def read_variables(self, names: list[str]) -> dict:
        out = {}
        for name in names:
            try:
                out[name] = _json_ready(self.variables.read(name))
            except VariableError as exc:
                raise NotFoundError(f"{name}: {exc.message}", field="names", code="unknown_variable") from None
        return out

    def write_variable(self, name: str, value) -> dict:
        if self.running:
            raise ConflictError("a program is running: write the variable when it has stopped", code="busy")
        if not isinstance(value, str):
            value = checks.number(value, "value")       # no bool, no NaN, no 400-digit integer
        try:
            self.variables.write(name, value)
            return {name: _json_ready(self.variables.read(name))}
        except VariableError as exc:
            status = NotFoundError if type(exc).__name__ == "UnknownVariable" else InvalidInput
            raise status(f"{name}: {exc.message}", field="name" if status is NotFoundError else "value") from None

    def close(self) -> None:
        if self.running:
            self.interpreter.request_stop()
            thread = self._thread
            if thread is not None:
                thread.join(5.0)


def _memory_backing(db: Database, kind: str, may_write):
    """_EV[i] / _MV[i] = memory n = i + 1 of the database (the same memories JOG uses);
    ``may_write(name)`` raises when the program's starter may not write them."""
    def read(key):
        n = int(key) + 1
        if not 1 <= n <= MEMORY_COUNT:
            return None
        with db.unit(readonly=True) as unit:
            return unit.get_memory(kind, n)

    def write(key, value):
        n = int(key) + 1
        if not 1 <= n <= MEMORY_COUNT:
            raise VariableError(f"_{kind}[{key}]: memory {n} is beyond the {MEMORY_COUNT} memories")
        may_write(f"_{kind}")
        try:        # the range of /api/memories: a program cannot store what the API refuses
            number = check_memory_value(value, f"_{kind}[{key}]")
        except InvalidInput as exc:
            raise InvalidValue(exc.message) from None
        with db.unit() as unit:
            unit.put_memory(kind, n, number, source="nc")

    return CallbackBacking(read, write)


# --- stored programs ----------------------------------------------------------------------------------

class ProgramService:
    """The programs table (design.md §9.4): names of letters, digits and _, starting with a letter."""

    def __init__(self, db: Database, nc: NcService):
        self._db = db
        self._nc = nc

    @staticmethod
    def check_name(name) -> str:
        if not isinstance(name, str) or not PROGRAM_NAME.match(name):
            raise InvalidInput("name: 1..32 letters, digits or _, starting with a letter", field="name")
        return name

    @staticmethod
    def _check_text(text) -> str:
        if not isinstance(text, str):
            raise InvalidInput("text: the program text", field="text")
        return check_size(text, "text")

    def _with_check(self, program: dict) -> dict:
        return {**program, "syntax": self._nc.check(program["text"], program["name"]),
                "selected": self._nc.status()["program"] == program["name"]}

    def list(self) -> list[dict]:
        with self._db.unit(readonly=True) as unit:
            return unit.list_programs()

    def get(self, name: str) -> dict:
        with self._db.unit(readonly=True) as unit:
            program = unit.get_program(name)
        if program is None:
            raise NotFoundError(f"program {name!r} does not exist", field="name", code="unknown_program")
        return self._with_check(program)

    def create(self, name, text) -> dict:
        name, text = self.check_name(name), self._check_text(text)
        with self._db.unit() as unit:
            if unit.get_program(name) is not None:
                raise ConflictError(f"program {name} exists already: PUT to change it", field="name",
                                    code="exists")
            program, _ = unit.put_program(name, text)
        return self._with_check(program)

    def put(self, name, text) -> tuple[dict, bool]:
        name, text = self.check_name(name), self._check_text(text)
        self._refuse_active(name, "changed")
        with self._db.unit() as unit:
            program, created = unit.put_program(name, text)
        return self._with_check(program), created

    def delete(self, name: str) -> None:
        self._refuse_active(name, "deleted")
        with self._db.unit() as unit:
            try:
                unit.delete_program(name)
            except KeyError:
                raise NotFoundError(f"program {name!r} does not exist", field="name",
                                    code="unknown_program") from None

    def _refuse_active(self, name: str, what: str) -> None:
        st = self._nc.status()
        if st["program"] == name and (st["state"] in ("running", "stopped") or self._nc.running):
            raise ConflictError(f"program {name} is active in the channel: Reset before it is {what}",
                                code="busy")

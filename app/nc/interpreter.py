"""The part-program interpreter: runs a program block by block on an ``NcRuntime``.

    interp = Interpreter(runtime, Variables(), cycles={"CYCLE977": my_handler})
    interp.load("N10 G54 G0 X10 Y10\\nN20 M30")      # parses and checks: NcSyntaxError
    result = interp.run()                            # RunResult(state="done"|"stopped"|"alarm", ...)

A block executes in two phases. First everything is evaluated and checked without side effects
(expressions, the modal state after the block, G101/G102, the MCS targets, the tool data); then
the machine is commanded (tool change, spindle, motion), and only when all of it succeeded are the
block's assignments and its modal state committed. A block that raises an alarm therefore leaves
the program-level state (G90/G91, plane, offset, units, F, measuring offsets, variables) as it was
before the block; physical facts that did happen are kept (the tool that was changed in, the
spindle that was started). A cycle called in a block runs after the block's own words have been
committed (it sees ``_MVAR=...`` of its own block); what it writes stays, even when it alarms.

The channel keeps its modal state from one program (or MDA run) to the next, like a real channel;
``reset()`` (NC Reset) returns it to the defaults and clears the measuring offsets.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from engine import alarms
from engine.alarms import AlarmDef
from engine.frames import Frame, FrameChain
from engine.types import MeasuringError

from . import nodes as n
from .errors import NcAlarm, NcRuntimeError, NcSyntaxError
from .expressions import FUNCTIONS, EvalError, Evaluator
from .modal import (
    DISTANCE,
    FEED_TYPE,
    GEOMETRY_AXES,
    M_END,
    M_END_RESET,
    M_SPINDLE,
    M_STOP,
    M_SUB_END,
    M_TOOL_CHANGE,
    MEASURING,
    MOTION,
    OFFSET,
    PLANE,
    PLANE_AXES,
    UNITS,
    ModalState,
    g_group,
    infeed_unit,
)
from .offsets import MeasuringOffsetError, MeasuringOffsets, NoMeasuredValue
from .parser import find_jump, parse_program, refuse_out_of_scope
from .runtime import MeasureResult, NcRuntime
from .scope import refusal
from .variables import CallbackBacking, VarDef, VariableError, Variables

log = logging.getLogger(__name__)
CycleHandler = Callable[["CycleContext"], None]

_PLANES = {17: "G17", 18: "G18", 19: "G19"}
_EMPTY_OFFSETS = MeasuringOffsets()


# --- what the interpreter shows ------------------------------------------------------------------

@dataclass(frozen=True)
class BlockRef:
    """A block of the loaded program, as the screens show it."""

    index: int
    line: int
    number: int | None
    label: str | None
    text: str

    @classmethod
    def of(cls, block: n.Block) -> BlockRef:
        return cls(block.index, block.line, block.number, block.label, block.text)

    def to_dict(self) -> dict:
        return {"index": self.index, "line": self.line, "number": self.number, "label": self.label,
                "text": self.text}


@dataclass(frozen=True)
class RunResult:
    """``state``: "done" (end of program), "stopped" (M0, stop request, single block: resumable),
    "alarm". ``reason``: "M0", "stop_request", "single_block", "M2", "M17", "M30", "end".
    ``block``: the block executed last (the alarm block)."""

    state: str
    reason: str | None
    block: BlockRef | None
    alarm: NcAlarm | None = None

    def to_dict(self) -> dict:
        return {"state": self.state, "reason": self.reason,
                "block": self.block.to_dict() if self.block else None,
                "alarm": self.alarm.to_dict() if self.alarm else None}


class NcStateError(RuntimeError):
    """The interpreter cannot do that now (run while running, run without a program, ...)."""


# --- coordinates of one block ---------------------------------------------------------------------

@dataclass(frozen=True)
class Coordinates:
    """WCS (tool tip) <-> MCS axis positions for a frame, a tool length and a plane.

    ``p_mcs_axes = R·p_wcs + T + L·infeed`` (design.md §3; tool length along the plane's infeed
    axis like app/workflow/executor.py). Rotary axes: MCS = WCS + the frame's rotary offset.
    """

    frame: Frame
    tool_length: float
    infeed: np.ndarray

    def tip_wcs(self, axes_mcs: Mapping[str, float]) -> np.ndarray:
        xyz = np.array([float(axes_mcs[a]) for a in GEOMETRY_AXES])
        return self.frame.parent2child(xyz - self.tool_length * self.infeed)

    def axes_for(self, p_wcs) -> np.ndarray:
        return self.frame.child2parent(np.asarray(p_wcs, dtype=float)) + self.tool_length * self.infeed

    def rotary_wcs(self, axis: str, mcs_value: float) -> float:
        return float(mcs_value) - self.frame.rotary_offset(axis)

    def rotary_mcs(self, axis: str, wcs_value: float) -> float:
        return float(wcs_value) + self.frame.rotary_offset(axis)


# --- the context a cycle handler gets -------------------------------------------------------------

@dataclass
class CycleContext:
    """What a cycle handler (``handler(ctx) -> None``) may use.

    ``variables``: the store (``_MVAR``, ``_SETVAL``... as programmed before the call; write the
    results to ``_OVR``/``_OVI``). ``modal``: the channel's state at the call (plane, offset,
    units, feed, tool). ``runtime``: the machine. The helpers convert and move in the active WCS
    (tool tip, tool length along the plane's infeed axis) the same way part-program blocks do.
    Raise ``ctx.alarm(definition, message)`` to stop the program with a located alarm;
    ``engine.types.MeasuringError`` and ``NcRuntimeError`` are converted the same way.
    """

    name: str
    args: tuple
    block: BlockRef
    variables: Variables
    modal: ModalState
    runtime: NcRuntime
    _interpreter: Interpreter = field(repr=False)
    _pos: n.Pos = field(repr=False)
    # (name, index) of each argument written as a plain variable, else None: the 840D's
    # call-by-reference parameters (CYCLE118 returns its text in its third argument)
    arg_refs: tuple[tuple[str, tuple] | None, ...] = ()

    def set_argument(self, number: int, value) -> None:
        """Write ``value`` into the variable given as argument ``number`` (0-based)."""
        ref = self.arg_refs[number] if number < len(self.arg_refs) else None
        if ref is None:
            raise self.alarm(alarms.NC_SYNTAX, f"{self.name}: argument {number + 1} must be a variable")
        self.variables.set(ref[0], value, ref[1])

    @property
    def plane_axes(self) -> tuple[str, str, str]:
        """(abscissa, ordinate, applicate) of the active plane (measuring-math §0.1)."""
        return PLANE_AXES[self.modal.plane]

    def chain(self) -> FrameChain:
        return self.runtime.offset_chain(self.modal.offset)

    def coordinates(self) -> Coordinates:
        return self._interpreter._coordinates(self.modal, suppress=False)

    def position_wcs(self) -> np.ndarray:
        """Tool tip (probe ball centre) in the active WCS now."""
        return self.coordinates().tip_wcs(self.runtime.position())

    def to_mcs(self, p_wcs) -> dict[str, float]:
        axes = self.coordinates().axes_for(p_wcs)
        return {a: float(v) for a, v in zip(GEOMETRY_AXES, axes, strict=True)}

    def to_wcs(self, axes_mcs: Mapping[str, float]) -> np.ndarray:
        return self.coordinates().tip_wcs(axes_mcs)

    def move(self, p_wcs, feed: float | None = None) -> None:
        """Collision-monitored positioning of the tool tip to ``p_wcs`` (rapid when feed is None)."""
        self.runtime.move(self.to_mcs(p_wcs), feed)

    def measure(self, p_wcs, feed: float, stop_on_trigger: bool = True) -> tuple[bool, np.ndarray | None]:
        """Measuring move to ``p_wcs``: (triggered, latched tool tip in the WCS). Also sets
        ``$AA_MM``/``$AA_MW``/``$AC_MEA[1]`` like MEAS."""
        coords = self.coordinates()
        result = self.runtime.measure(self.to_mcs(p_wcs), feed, stop_on_trigger)
        self._interpreter._store_measurement(result, coords, 1)
        if not result.triggered or result.latched_mcs is None:
            return False, None
        return True, coords.tip_wcs(result.latched_mcs)

    @property
    def stop_requested(self) -> bool:
        """NC Stop was requested: a long cycle may end early between its moves."""
        return self._interpreter._stop.is_set()

    def warn(self, definition: AlarmDef, message: str, stop: bool = False) -> None:
        """A warning-class alarm of the cycle (62304 oversize, ...): the program goes on; the
        channel shows it as its message; ``stop`` (``_CBIT[2]=1``): M0 after the cycle's block."""
        self._interpreter._message = f"{definition.number} {message}"
        if stop:
            self._interpreter.request_stop()

    def alarm(self, definition: AlarmDef, message: str) -> NcAlarm:
        """An alarm located at the cycle call (raise it)."""
        return NcAlarm(message, self._pos.line, self._pos.column, alarm=definition, block_text=self.block.text)


# --- one block on its way: what its words say, and the state after it ------------------------------

@dataclass
class _Plan:
    """A block between its phases: the words evaluated (in the order written), then the modal
    state after the block (``new``) as the checks build it, then what the motion measured."""

    block: n.Block
    ev: Evaluator
    before: ModalState
    new: ModalState = field(init=False)
    axis_values: dict[str, tuple[n.AxisWord, float]] = field(default_factory=dict)
    address: dict[str, tuple[n.Address, float]] = field(default_factory=dict)
    meas: tuple[n.Meas, float] | None = None
    spos: tuple[n.Spos, float] | None = None
    call: tuple[n.CycleCall, tuple] | None = None
    goto: n.Goto | None = None
    msg: tuple[n.Msg, str | None] | None = None
    suppress: bool = False
    tool_change: bool = False
    edge_word: tuple[n.Address, float] | None = None
    spindle: tuple[n.MCode, int] | None = None
    diameter: n.Diameter | None = None
    motion_kind: str | None = None
    measurement: tuple[MeasureResult, Coordinates, int] | None = None

    def __post_init__(self) -> None:
        self.new = self.before
        self.gcodes = {g_group(g.number): g for g in self.block.gcodes()}
        self.mcodes = {m.number: m for m in self.block.words if isinstance(m, n.MCode)}


def _eval_define(plan: _Plan, w: n.Define) -> None:
    for item in w.items:
        if item.init is not None:
            plan.ev.fill(item.name, plan.ev.eval(item.init), item.init.pos)


def _eval_if_goto(plan: _Plan, w: n.IfGoto) -> None:
    if _truth(plan.ev.eval(w.condition), w.condition.pos):
        plan.goto = w.goto


def _eval_msg(plan: _Plan, w: n.Msg) -> None:
    value = None if w.value is None else plan.ev.eval(w.value)
    plan.msg = (w, None if value is None else _text(value))


def _nothing(plan: _Plan, w) -> None:
    """G and M words are read by the checks from the block itself; STOPRE needs nothing here."""


#: evaluation of each kind of word, in the order written (an assignment is seen by later words)
_EVALUATE: dict[type, Callable[[_Plan, Any], None]] = {
    n.Assign: lambda plan, w: plan.ev.assign(w),
    n.Define: _eval_define,
    n.AxisWord: lambda plan, w: plan.axis_values.__setitem__(w.axis, (w, plan.ev.number(w.value, w.axis))),
    n.Address: lambda plan, w: plan.address.__setitem__(w.letter, (w, plan.ev.number(w.value, w.letter))),
    n.Meas: lambda plan, w: setattr(plan, "meas", (w, plan.ev.number(w.value, w.kind))),
    n.Spos: lambda plan, w: setattr(plan, "spos", (w, plan.ev.number(w.value, "SPOS"))),
    n.CycleCall: lambda plan, w: setattr(plan, "call", (w, tuple(plan.ev.eval(a) for a in w.args))),
    n.IfGoto: _eval_if_goto,
    n.Goto: lambda plan, w: setattr(plan, "goto", w),
    n.Msg: _eval_msg,
    n.GCode: _nothing, n.MCode: _nothing, n.Stopre: _nothing,
    n.Diameter: lambda plan, w: setattr(plan, "diameter", w),
}


# --- the interpreter ------------------------------------------------------------------------------

_IDLE, _READY, _RUNNING, _STOPPED, _DONE, _ALARM = "idle", "ready", "running", "stopped", "done", "alarm"

#: jumps one NC Start may execute: a loop beyond it is a runaway (alarm NC_RUNAWAY)
MAX_JUMPS = 100_000
#: seconds a run may compute without a command to the machine before the watchdog ends it
WATCHDOG_S = 10.0


class _Control:
    """How a block ends: go on, jump, stop (M0) or end the program."""

    def __init__(self, kind: str = "next", target: int | None = None, reason: str | None = None):
        self.kind = kind
        self.target = target
        self.reason = reason


class Interpreter:
    """Runs part programs on ``runtime`` with ``variables`` and the ``cycles`` registry.

    ``defaults``: the channel's reset state (G1 G17 G90 G71 unless given); the active settable
    offset and the tool come from the runtime at every ``load()``. ``on_block(BlockRef)`` is called
    before each block executes (live display).
    """

    def __init__(self, runtime: NcRuntime, variables: Variables | None = None,
                 cycles: Mapping[str, CycleHandler] | None = None, *, defaults: ModalState | None = None,
                 on_block: Callable[[BlockRef], None] | None = None, max_jumps: int = MAX_JUMPS,
                 watchdog_s: float = WATCHDOG_S):
        self.runtime = runtime
        self.max_jumps = max_jumps
        self.watchdog_s = watchdog_s
        self._command_count = 0             # machine commands given (the watchdog's sign of life)
        self.variables = variables if variables is not None else Variables(axes=runtime.axes)
        self.cycles: Mapping[str, CycleHandler] = cycles if cycles is not None else {}
        self._defaults = defaults or ModalState()
        self._on_block = on_block
        self._lock = threading.RLock()
        self._stop = threading.Event()
        self._program: n.Program | None = None
        self._pc = 0
        self._state = _IDLE
        self._current: BlockRef | None = None
        self._last: RunResult | None = None
        self._modal = self._defaults
        self._message: str | None = None
        self._bind_system_variables()

    # --- what the screens and the API read -------------------------------------------------------
    @property
    def state(self) -> str:
        """"idle" (no program), "ready", "running", "stopped", "done", "alarm"."""
        return self._state

    @property
    def program(self) -> n.Program | None:
        return self._program

    @property
    def current_block(self) -> BlockRef | None:
        """The block executing now; when not running the block that executes next (or, after the
        end or an alarm, the block executed last)."""
        with self._lock:
            return self._current

    @property
    def modal(self) -> ModalState:
        return self._modal

    @property
    def measuring_offsets(self) -> MeasuringOffsets:
        return self._modal.measuring

    @property
    def message(self) -> str | None:
        """The text of the last MSG("...") (None after MSG())."""
        return self._message

    @property
    def last_result(self) -> RunResult | None:
        return self._last

    def status(self) -> dict:
        """JSON-ready: state, program, current block, modal state, message, last alarm."""
        with self._lock:
            alarm = self._last.alarm if self._last and self._state == _ALARM else None
            return {"state": self._state, "program": self._program.name if self._program else None,
                    "block": self._current.to_dict() if self._current else None,
                    "modal": self._modal.to_dict(), "message": self._message,
                    "alarm": alarm.to_dict() if alarm else None}

    # --- life cycle --------------------------------------------------------------------------------
    def load(self, program: str | n.Program, name: str = "MDA") -> n.Program:
        """Parse (if text) and check ``program`` against the variables, the cycle registry and the
        machine's axes; raises ``NcSyntaxError`` before anything moves."""
        with self._lock:
            if self._state == _RUNNING:
                raise NcStateError("a program is running: stop it before loading another")
        if isinstance(program, str):
            refuse_out_of_scope(program, self.lathe)
        parsed = parse_program(program, name) if isinstance(program, str) else program
        try:
            self.variables.define_locals(_local_definitions(parsed, self.variables))
            self._check(parsed)
        except Exception:
            self.variables.clear_locals()
            raise
        with self._lock:
            self._program = parsed
            self._pc = 0
            self._state = _READY
            self._last = None
            self._current = BlockRef.of(parsed.blocks[0]) if parsed.blocks else None
            self._sync_machine_state()
        return parsed

    def reset(self) -> None:
        """NC Reset: program back to its start, modal state to the defaults, measuring offsets
        cleared, alarm cleared. Refused while a program runs (stop it first)."""
        with self._lock:
            if self._state == _RUNNING:
                raise NcStateError("a program is running: stop it before Reset")
            self._modal = self._defaults
            self._sync_machine_state()
            self._message = None
            self._pc = 0
            self._last = None
            if self._program is not None:
                self._state = _READY
                self._current = BlockRef.of(self._program.blocks[0]) if self._program.blocks else None
            else:
                self._state = _IDLE
                self._current = None

    def request_stop(self) -> None:
        """NC Stop (thread-safe): the running program stops before its next block; run() resumes."""
        self._stop.set()

    def cancel_stop(self) -> None:
        """NC Start after an NC Stop that the program has not reached yet: it goes on."""
        self._stop.clear()

    def run(self) -> RunResult:
        """Run to the end, M0, a stop request or an alarm."""
        return self._go(single=False)

    def step(self) -> RunResult:
        """Single block: execute exactly one block."""
        return self._go(single=True)

    # --- execution ---------------------------------------------------------------------------------
    def _go(self, single: bool) -> RunResult:
        program = self._begin()
        last: BlockRef | None = None
        watch = _Watchdog(self)
        try:
            while True:
                result, last = self._next_block(program, watch, single, last)
                if result is not None:
                    return result
        except NcAlarm as alarm:
            return self._finish(_ALARM, None, BlockRef.of(program.blocks[self._pc]), alarm)
        except BaseException:
            with self._lock:
                self._state = _ALARM
            raise

    def _begin(self) -> n.Program:
        """NC Start: the loaded program runs from its current block."""
        with self._lock:
            if self._program is None:
                raise NcStateError("no program loaded")
            if self._state == _RUNNING:
                raise NcStateError("the program is already running")
            if self._state in (_DONE, _ALARM):
                raise NcStateError(f"the program has {'ended' if self._state == _DONE else 'an alarm'}: "
                                   "load it again or press Reset")
            self._state = _RUNNING
            self._stop.clear()
            return self._program

    def _next_block(self, program: n.Program, watch: _Watchdog, single: bool,
                    last: BlockRef | None) -> tuple[RunResult | None, BlockRef | None]:
        """Execute the block at ``_pc``: (the run's result if it ends here, the block executed last)."""
        if self._pc >= len(program.blocks):
            return self._finish(_DONE, "end", last), last
        if self._stop.is_set():
            return self._finish(_STOPPED, "stop_request", last, next_block=True), last
        block = program.blocks[self._pc]
        ref = BlockRef.of(block)
        with self._lock:
            self._current = ref
        if self._on_block is not None:
            self._on_block(ref)
        control = self._execute(block)
        if control.kind == "end":
            return self._finish(_DONE, control.reason, ref), ref
        watch.check(block, control)
        if control.kind == "jump":
            assert control.target is not None       # a jump names its block (_control)
            self._pc = control.target
        else:
            self._pc += 1
        if control.kind == "stop":
            return self._finish(_STOPPED, control.reason, ref, next_block=True), ref
        if single:
            if self._pc >= len(program.blocks):
                return self._finish(_DONE, "end", ref), ref
            return self._finish(_STOPPED, "single_block", ref, next_block=True), ref
        return None, ref

    def _finish(self, state: str, reason: str | None, block: BlockRef | None, alarm: NcAlarm | None = None,
                next_block: bool = False) -> RunResult:
        result = RunResult(state, reason, block, alarm)
        with self._lock:
            self._state = state
            self._last = result
            if next_block and self._program is not None and self._pc < len(self._program.blocks):
                self._current = BlockRef.of(self._program.blocks[self._pc])
            elif block is not None:
                self._current = block
        return result

    def _execute(self, block: n.Block) -> _Control:
        try:
            return self._execute_block(block)
        except NcAlarm as e:
            if e.block_text is None:
                e.block_text = block.text
            raise
        except EvalError as e:
            pos = e.pos or block.pos
            raise NcAlarm(e.message, pos.line, pos.column, alarm=e.alarm, block_text=block.text) from None
        except VariableError as e:
            raise NcAlarm(e.message, block.line, block.pos.column, alarm=e.alarm, block_text=block.text) from None
        except NcRuntimeError as e:
            raise NcAlarm(e.message, block.line, block.pos.column, alarm=e.alarm, block_text=block.text) from None
        except MeasuringError as e:
            raise NcAlarm(e.message, block.line, block.pos.column, alarm=e.definition,
                          block_text=block.text) from None
        except Exception as e:          # a bug: the channel alarms, the log keeps the traceback
            log.exception("NC block %s (line %s): internal error", block.text, block.line)
            raise NcAlarm(f"internal error: {e}", block.line, block.pos.column, alarm=alarms.NC_INTERNAL,
                          block_text=block.text) from e

    def _alarm(self, word, definition: AlarmDef, message: str) -> NcAlarm:
        pos = word.pos if hasattr(word, "pos") else word
        return NcAlarm(message, pos.line, pos.column, alarm=definition)

    def _located(self, word, call):
        """Run ``call``; an ``NcRuntimeError`` becomes an alarm located at ``word``."""
        self._command_count += 1
        try:
            return call()
        except NcRuntimeError as e:
            raise self._alarm(word, e.alarm or alarms.NC_INTERNAL, e.message) from None

    # --- one block: word groups, each checked, commanded, committed (two phases) ------------------
    def _execute_block(self, block: n.Block) -> _Control:
        """Evaluate the words in the order written, check every word group's part of the state
        after the block (nothing moves yet), command the machine group by group, then commit."""
        plan = _Plan(block, Evaluator(self.variables), self._modal)
        for word in block.words:
            _EVALUATE.get(type(word), _nothing)(plan, word)
        plan.new = plan.before
        for check in self._checks():
            check(plan)
        for command in self._commands():
            command(plan)
        self._commit(plan)
        return self._control(plan)

    def _checks(self) -> tuple[Callable[[_Plan], None], ...]:
        """The state after the block, group by group, checked before anything moves."""
        return (self._check_modal_groups, self._check_feed, self._check_spindle_speed, self._check_tool,
                self._check_spindle, self._check_measuring_offsets, self._check_meas, self._check_motion_kind)

    def _commands(self) -> tuple[Callable[[_Plan], None], ...]:
        """What the machine does, in the 840D's order: tool, spindle, motion."""
        return (self._command_tool, self._command_spos, self._command_spindle, self._command_motion)

    # --- checks (phase 1) --------------------------------------------------------------------------
    def _check_modal_groups(self, plan: _Plan) -> None:
        gcodes = plan.gcodes
        new = plan.new
        if MOTION in gcodes:
            new = new.replace(motion=gcodes[MOTION].name)
        if PLANE in gcodes:
            new = new.replace(plane=_PLANES[gcodes[PLANE].number])
        if DISTANCE in gcodes:
            new = new.replace(distance=gcodes[DISTANCE].name)
        if UNITS in gcodes:
            new = new.replace(units=gcodes[UNITS].name)
        if FEED_TYPE in gcodes:
            new = new.replace(feed_type=gcodes[FEED_TYPE].name)
        if OFFSET in gcodes:
            new = new.replace(offset=gcodes[OFFSET].name)
            offset = new.offset
            self._located(gcodes[OFFSET], lambda: self.runtime.offset_chain(offset))   # it must exist
        if plan.diameter is not None:
            new = new.replace(diamon=plan.diameter.on)
        plan.new = new
        plan.suppress = 53 in {g.number for g in plan.block.gcodes()}

    def _check_feed(self, plan: _Plan) -> None:
        if "F" in plan.address:
            word, value = plan.address["F"]
            if not value > 0.0:
                raise self._alarm(word, alarms.NC_FEED_MISSING, f"F{value:g}: the feed must be greater than 0")
            plan.new = plan.new.replace(feed=plan.new.feed_to_mm(value))

    def _check_spindle_speed(self, plan: _Plan) -> None:
        if "S" in plan.address:
            word, value = plan.address["S"]
            if value < 0.0:
                raise self._alarm(word, alarms.NC_VALUE_RANGE, f"S{value:g}: the spindle speed cannot be negative")
            plan.new = plan.new.replace(spindle_speed=value)

    def _check_tool(self, plan: _Plan) -> None:
        """T preselects, M6 changes, D selects the edge; the tool data must exist before anything moves."""
        if "T" in plan.address:
            word, value = plan.address["T"]
            t = _whole(value, word, "T", self)
            plan.new = plan.new.replace(preselected=t if t > 0 else None)
        # the lathe's turret: T changes the tool at once (840D lathe, manual ch. 6: "N10 T7 D1");
        # the milling machine: T preselects, M6 changes
        plan.tool_change = M_TOOL_CHANGE in plan.mcodes or (self.lathe and "T" in plan.address)
        plan.edge_word = plan.address.get("D")
        new = plan.new
        if plan.tool_change:
            new = new.replace(tool=new.preselected, edge=1 if new.preselected is not None else 0)
        if plan.edge_word is not None:
            word, value = plan.edge_word
            d = _whole(value, word, "D", self)
            if d > 0 and new.tool is None:
                raise self._alarm(word, alarms.NC_D_NUMBER, f"D{d}: there is no tool in the spindle")
            new = new.replace(edge=d)
        plan.new = new
        if new.tool != plan.before.tool or new.edge != plan.before.edge:
            where = plan.edge_word[0] if plan.edge_word else self._tool_change_word(plan)
            self._located(where, lambda: self.runtime.tool_length(new.tool, new.edge))

    def _check_spindle(self, plan: _Plan) -> None:
        for number, direction in M_SPINDLE.items():
            if number in plan.mcodes:
                plan.spindle = (plan.mcodes[number], direction)
        if plan.spindle is not None:
            word, direction = plan.spindle
            plan.new = plan.new.replace(spindle_direction=direction)
            if direction != 0 and not plan.new.spindle_speed > 0.0:
                raise self._alarm(word, alarms.NC_VALUE_RANGE, f"M{word.number}: program a spindle speed S greater than 0")
        if plan.spos is not None:
            if not math.isfinite(plan.spos[1]):
                raise self._alarm(plan.spos[0], alarms.NC_VALUE_RANGE, "SPOS: the angle is not a number")
            plan.new = plan.new.replace(spindle_direction=0)

    def _check_measuring_offsets(self, plan: _Plan) -> None:
        """G101/G102 include or remove measuring offsets: their axis words are factors, no motion."""
        measuring = plan.gcodes.get(MEASURING)
        if measuring is not None and measuring.number in (101, 102):
            plan.new = plan.new.replace(measuring=self._measuring_offsets(measuring, plan.new.measuring,
                                                                          plan.axis_values))
            plan.axis_values = {}

    def _check_meas(self, plan: _Plan) -> None:
        if plan.meas is None:
            return
        word, value = plan.meas
        if value not in (1, 2):
            hint = " (the falling edge, MEAS=-n, is not supported)" if value in (-1, -2) else ""
            raise self._alarm(word, alarms.NC_VALUE_RANGE,
                              f"{word.kind}={value:g}: the measuring input must be 1 or 2{hint}")
        if plan.new.motion == "G0":
            raise self._alarm(word, alarms.NC_SYNTAX,
                              f"{word.kind} is a measuring move at feed: G0 is active, program G1")

    def _check_motion_kind(self, plan: _Plan) -> None:
        measuring = plan.gcodes.get(MEASURING)
        if measuring is not None and measuring.number == 100:
            plan.motion_kind = "G100"
        elif plan.axis_values:
            plan.motion_kind = "MEAS" if plan.meas is not None else plan.new.motion
        if plan.motion_kind in ("G1", "MEAS", "G100") and plan.new.path_feed() is None:
            first = next(iter(plan.axis_values.values()))[0]
            what = "G100" if plan.motion_kind == "G100" else "G1"
            if plan.new.feed is not None:           # G95 with the spindle standing
                raise self._alarm(first, alarms.NC_FEED_MISSING,
                                  f"{what}: G95 is a feed per revolution and the spindle stands: program M3/M4 "
                                  "with S, or G94")
            raise self._alarm(first, alarms.NC_FEED_MISSING, f"{what}: no feed programmed; program F")

    # --- commands (phase 2): physical facts that happened stay ---------------------------------------
    def _command_tool(self, plan: _Plan) -> None:
        new = plan.new
        if plan.tool_change:
            self._located(self._tool_change_word(plan), lambda: self.runtime.change_tool(new.tool, new.edge))
            self._modal = self._modal.replace(tool=new.tool, edge=new.edge, preselected=new.preselected)
        elif plan.edge_word is not None and new.edge != plan.before.edge:
            self._located(plan.edge_word[0], lambda: self.runtime.select_edge(new.edge))
            self._modal = self._modal.replace(edge=new.edge)

    @staticmethod
    def _tool_change_word(plan: _Plan):
        return plan.mcodes[M_TOOL_CHANGE] if M_TOOL_CHANGE in plan.mcodes else plan.address["T"][0]

    def _command_spos(self, plan: _Plan) -> None:
        spos = plan.spos
        if spos is not None:
            self._located(spos[0], lambda: self.runtime.spindle_position(spos[1]))
            self._modal = self._modal.replace(spindle_direction=0)

    def _command_spindle(self, plan: _Plan) -> None:
        new = plan.new
        if plan.spindle is None and not ("S" in plan.address and new.spindle_direction != 0):
            return
        word = plan.spindle[0] if plan.spindle is not None else plan.address["S"][0]
        self._located(word, lambda: self.runtime.spindle(new.spindle_direction, new.spindle_speed))
        self._modal = self._modal.replace(spindle_direction=new.spindle_direction, spindle_speed=new.spindle_speed)

    def _command_motion(self, plan: _Plan) -> None:
        if plan.motion_kind == "G100":
            plan.new = plan.new.replace(measuring=self._g100(plan.ev, plan.new, plan.axis_values))
        elif plan.motion_kind is not None:
            axis_values = plan.axis_values
            if plan.new.diamon and "X" in axis_values:     # DIAMON: X is a diameter (G90 and G91 alike)
                word, value = axis_values["X"]
                axis_values = {**axis_values, "X": (word, value / 2.0)}
            plan.measurement = self._motion(plan.new, plan.suppress, axis_values, plan.meas, plan.motion_kind)

    # --- commit, then the cycle and the program flow ---------------------------------------------------
    def _commit(self, plan: _Plan) -> None:
        new = plan.new
        if new.offset != plan.before.offset or OFFSET in plan.gcodes:
            # programming the active WO again re-selects it with its current data (the manual's
            # §5.7 listing, N90 "G54 C0": only then the written C offset takes effect)
            self._located(plan.gcodes.get(OFFSET, plan.block), lambda: self.runtime.activate_offset(new.offset))
        plan.ev.commit()
        if plan.measurement is not None:
            self._store_measurement(*plan.measurement, diamon=new.diamon)
        self._modal = new
        if plan.msg is not None:
            self._message = plan.msg[1]
        if plan.call is not None:
            self._call_cycle(plan.block, *plan.call)

    def _control(self, plan: _Plan) -> _Control:
        mcodes, goto = plan.mcodes, plan.goto
        for number, reason in ((M_END_RESET, "M30"), (M_END, "M2"), (M_SUB_END, "M17")):
            if number in mcodes:
                return _Control("end", reason=reason)
        if goto is not None:
            assert self._program is not None                # a block runs within its loaded program
            target = find_jump(self._program, plan.block.index, goto)
            if target is None:  # checked at load; a program given as nodes may still lack it
                raise self._alarm(goto, alarms.NC_JUMP_TARGET, f"{goto.direction} {goto.target}: jump target not found")
            if M_STOP in mcodes:
                return _Control("stop", target=target, reason="M0")
            return _Control("jump", target=target)
        if M_STOP in mcodes:
            return _Control("stop", reason="M0")
        return _Control()

    # --- motion ------------------------------------------------------------------------------------
    def _coordinates(self, modal: ModalState, suppress: bool) -> Coordinates:
        frame = Frame.identity() if suppress else self.runtime.offset_chain(modal.offset).wcs2bcs
        if self.lathe:
            # the lathe: tip = F − (L1·x̂ + L2·ẑ) (turning.md §0.1), X a radius
            active = modal.tool is not None and modal.edge > 0
            l1, l2 = self.runtime.lathe_lengths() if active else (0.0, 0.0)
            return Coordinates(frame, 1.0, np.array([float(l1), 0.0, float(l2)]))
        length = 0.0
        if modal.tool is not None and modal.edge > 0:
            length = float(self.runtime.tool_length(modal.tool, modal.edge))
        return Coordinates(frame, length, infeed_unit(modal.plane))

    def _motion(self, new: ModalState, suppress: bool, axis_values, meas, kind: str):
        first_word = next(iter(axis_values.values()))[0]
        coords = self._located(first_word, lambda: self._coordinates(new, suppress))
        position = self._located(first_word, self.runtime.position)
        offsets = _EMPTY_OFFSETS if suppress else new.measuring
        target = _target_mcs(coords, position, new, axis_values, offsets)
        if not all(math.isfinite(v) for v in target.values()):
            raise self._alarm(first_word, alarms.NC_VALUE_RANGE, "the target position is not a finite number")
        if kind == "G0":
            self._located(first_word, lambda: self.runtime.move(target, None))
            return None
        if kind == "G1":
            self._located(first_word, lambda: self.runtime.move(target, new.path_feed()))
            return None
        word, value = meas
        if any(a not in GEOMETRY_AXES for a in axis_values):
            raise self._alarm(word, alarms.NC_VALUE_RANGE, f"{word.kind}: measuring moves are linear moves of X, Y, Z")
        if all(abs(target[a] - float(position[a])) < 1e-9 for a in GEOMETRY_AXES):
            raise self._alarm(word, alarms.NO_MEASURING_PATH,
                              f"{word.kind}: the probe is already at the programmed end point")
        feed = new.path_feed()
        assert feed is not None                         # _execute_block refused MEAS/MEAW without F
        result = self._located(first_word, lambda: self.runtime.measure(target, feed, word.kind == "MEAS"))
        # $AA_MW is given in the active WCS, also when G53 suppressed the frames of this block
        return result, (coords if not suppress else self._coordinates(new, False)), int(value)

    def _store_measurement(self, result: MeasureResult, coords: Coordinates, probe_input: int,
                           diamon: bool | None = None) -> None:
        """$AC_MEA[n], and on a switch $AA_MM (MCS) and $AA_MW (WCS, tool tip) of every axis. With
        DIAMON (``diamon``, default the block's modal state) $AA_MW[X] is a diameter, as the WCS
        position $AA_IW[X] and the X words; $AA_MM[X] stays the machine axis' radius, as $AA_IM
        (turning.md §0.3: machine axes stay radius values)."""
        if diamon is None:
            diamon = self._modal.diamon
        v = self.variables
        v.set_system("$AC_MEA", bool(result.triggered), (probe_input,))
        if not result.triggered or result.latched_mcs is None:
            return
        latched = result.latched_mcs
        wcs = coords.tip_wcs(latched)
        for a, value in latched.items():
            v.set_system("$AA_MM", float(value), (a,))
        for i, a in enumerate(GEOMETRY_AXES):
            v.set_system("$AA_MW", 2.0 * float(wcs[i]) if a == "X" and diamon else float(wcs[i]), (a,))
        for a, value in latched.items():
            if a not in GEOMETRY_AXES:
                v.set_system("$AA_MW", coords.rotary_wcs(a, value), (a,))

    # --- G100 / G101 / G102 ------------------------------------------------------------------------
    def _g100(self, ev: Evaluator, new: ModalState, axis_values) -> MeasuringOffsets:
        """Measuring move towards the target and on through the measuring path ``_FA`` (mm);
        records Δ = switching position − target (absolute WCS)."""
        (axis, (word, value)), = axis_values.items()
        i = GEOMETRY_AXES.index(axis)
        fa = float(ev.read(n.Var("_FA", (), word.pos)))       # sees _FA=... of the same block
        if not fa > 0.0:
            raise self._alarm(word, alarms.MEASURING_PATH, f"G100 {axis}: the measuring path _FA must be greater "
                                                           f"than 0 (is {fa:g})")
        coords = self._located(word, lambda: self._coordinates(new, False))
        position = self._located(word, self.runtime.position)
        now = coords.tip_wcs(position)
        value = new.length_to_mm(value)
        target = value if new.distance == "G90" else now[i] + value
        path = target - now[i]
        if abs(path) < 1e-9:
            raise self._alarm(word, alarms.NO_MEASURING_PATH,
                              f"G100 {axis}: the probe is already at the target {axis}{target:.4f}; start in front "
                              "of the surface")
        end = now.copy()
        end[i] = target + math.copysign(fa, path)
        axes = coords.axes_for(end)
        mcs = {a: float(v) for a, v in zip(GEOMETRY_AXES, axes, strict=True)}
        feed = new.path_feed()
        assert feed is not None                         # _execute_block refused G100 without F
        result = self._located(word, lambda: self.runtime.measure(mcs, feed, True))
        if not result.triggered:
            raise self._alarm(word, alarms.PROBE_NOT_SWITCHED,
                              f"G100 {axis}{_fmt(target)}: the probe did not switch between {axis}{_fmt(now[i])} "
                              f"and {axis}{_fmt(end[i])}")
        latched = coords.tip_wcs(result.latched_mcs)
        self._store_measurement(result, coords, 1, diamon=new.diamon)
        return new.measuring.record(axis, float(latched[i] - target))

    def _measuring_offsets(self, g: n.GCode, offsets: MeasuringOffsets, axis_values) -> MeasuringOffsets:
        words = {a: w for a, (w, _v) in axis_values.items()}
        try:
            if g.number == 101:
                return offsets.include({a: v for a, (_w, v) in axis_values.items()})
            return offsets.extract(list(axis_values))
        except MeasuringOffsetError as e:
            definition = alarms.NO_MEASURED_VALUE if isinstance(e, NoMeasuredValue) else alarms.NO_MEASURING_OFFSET
            raise self._alarm(words.get(e.axis, g), definition, e.message) from None

    # --- cycles ------------------------------------------------------------------------------------
    def _call_cycle(self, block: n.Block, word: n.CycleCall, args: tuple) -> None:
        handler = self.cycles.get(word.name)
        if handler is None:
            raise self._alarm(word, alarms.NC_NAME_UNKNOWN, f"{word.name} is not a cycle of this control")
        ev = Evaluator(self.variables)
        refs = tuple((a.name, ev.index(a, self.variables.definition(a.name))) if isinstance(a, n.Var) else None
                     for a in word.args)
        ctx = CycleContext(word.name, args, BlockRef.of(block), self.variables, self._modal, self.runtime,
                           self, word.pos, refs)
        try:
            handler(ctx)
        except NcAlarm as e:
            if e.line is None:
                e.line, e.column = word.pos.line, word.pos.column
            raise
        except NcRuntimeError as e:
            raise self._alarm(word, e.alarm or alarms.NC_INTERNAL, f"{word.name}: {e.message}") from None
        except MeasuringError as e:
            raise self._alarm(word, e.definition, f"{word.name}: {e.message}") from None
        except VariableError as e:
            raise self._alarm(word, e.alarm, f"{word.name}: {e.message}") from None
        except EvalError as e:
            raise self._alarm(word, e.alarm, f"{word.name}: {e.message}") from None
        except Exception as e:          # a bug: the channel alarms, the log keeps the traceback
            log.exception("NC cycle %s: internal error", word.name)
            raise self._alarm(word, alarms.NC_INTERNAL, f"{word.name}: internal error: {e}") from e

    # --- machine state at program start --------------------------------------------------------------
    def _sync_machine_state(self) -> None:
        """The physical state comes from the machine: active offset, tool and D in the spindle."""
        offset = self.runtime.active_offset()
        tool, edge = self.runtime.tool_state()
        preselected = tool if self._modal.preselected is None else self._modal.preselected
        self._modal = self._modal.replace(offset=offset, tool=tool, edge=edge, preselected=preselected)
        if self.lathe:      # the lathe's reset state: G18, DIAMON as the machine is set up (turning.md §0.3)
            self._modal = self._modal.replace(
                plane="G18" if self._modal.plane == "G17" else self._modal.plane,
                diamon=bool(getattr(self.runtime, "diameter_programming", False)))

    @property
    def lathe(self) -> bool:
        """The machine is a lathe (runtime ``is_lathe``): the turret changes with T, the tool
        offset is L1 on X and L2 on Z, DIAMON/DIAMOF and the lathe cycles (manual ch. 6) run."""
        return bool(getattr(self.runtime, "is_lathe", False))

    def _bind_system_variables(self) -> None:
        v = self.variables

        def position(key):
            return self.runtime.position().get(key)

        def wcs(key):
            coords = self._coordinates(self._modal, False)
            pos = self.runtime.position()
            if key in GEOMETRY_AXES:
                value = float(coords.tip_wcs(pos)[GEOMETRY_AXES.index(key)])
                return 2.0 * value if key == "X" and self._modal.diamon else value
            return coords.rotary_wcs(key, pos[key]) if key in pos else None

        bindings = {
            "$AA_IM": CallbackBacking(position),
            "$AA_IW": CallbackBacking(wcs),
            "$P_TOOLNO": CallbackBacking(lambda key: self._modal.tool or 0),
            "$P_TOOL": CallbackBacking(lambda key: self._modal.edge),
        }
        for name, backing in bindings.items():
            if v.has(name):
                v.bind(name, backing)

    # --- checks at load ------------------------------------------------------------------------------
    def _check(self, program: n.Program) -> None:
        axes = set(self.runtime.axes)
        for block in program.blocks:
            try:
                for w in block.words:
                    self._check_word(w, axes)
            except NcSyntaxError as e:
                e.block_text = block.text
                raise

    def _check_word(self, w, axes: set[str]) -> None:
        if isinstance(w, n.AxisWord) and w.axis not in axes:
            raise NcSyntaxError(f"{w.axis}: this machine has no axis {w.axis} (axes: {' '.join(sorted(axes))})",
                                w.pos.line, w.pos.column, alarm=alarms.NC_NAME_UNKNOWN)
        if isinstance(w, n.Diameter) and not self.lathe:
            raise NcSyntaxError(refusal(w.name) or w.name, w.pos.line, w.pos.column, alarm=alarms.NC_NAME_UNKNOWN)
        if isinstance(w, n.CycleCall) and (w.name not in self.cycles or refusal(w.name, self.lathe)):
            raise NcSyntaxError(refusal(w.name, self.lathe) or (f"{w.name} is not a cycle of this control"
                                + (f" (known: {', '.join(sorted(self.cycles))})" if self.cycles else "")),
                                w.pos.line, w.pos.column, alarm=alarms.NC_NAME_UNKNOWN)
        if isinstance(w, n.Assign):
            self._check_var(w.target, write=True)
        for expr in _expressions(w):
            self._check_expr(expr)

    def _check_expr(self, e: n.Expr) -> None:
        if isinstance(e, n.Var):
            self._check_var(e, write=False)
        elif isinstance(e, n.Unary):
            self._check_expr(e.operand)
        elif isinstance(e, n.Binary):
            self._check_expr(e.left)
            self._check_expr(e.right)
        elif isinstance(e, n.Func):
            if e.name not in FUNCTIONS:
                kind = "a cycle, not a function" if e.name in self.cycles else "not a function of this control"
                raise NcSyntaxError(f"{e.name} is {kind}", e.pos.line, e.pos.column, alarm=alarms.NC_NAME_UNKNOWN)
            arity = FUNCTIONS[e.name][0]
            if len(e.args) != arity:
                raise NcSyntaxError(f"{e.name} takes {arity} argument{'s' if arity > 1 else ''}",
                                    e.pos.line, e.pos.column)
            for a in e.args:
                self._check_expr(a)

    def _check_var(self, var: n.Var, write: bool) -> None:
        d = self._known_var(var)
        if write and not d.writable:
            raise NcSyntaxError(f"{d.name} is written by the control only", var.pos.line, var.pos.column,
                                alarm=alarms.NC_WRITE_PROTECTED)
        _check_indexing(d, var)
        if d.axis_indexed:
            return
        for i in var.indices:
            self._check_expr(i)
        constant = [i.value if isinstance(i, n.Num) else None for i in var.indices]
        if constant and all(c is not None for c in constant):
            try:
                d.key(tuple(constant))
            except VariableError as e:
                where = var.indices[0].pos
                raise NcSyntaxError(e.message, where.line, where.column, alarm=e.alarm) from None

    def _known_var(self, var: n.Var) -> VarDef:
        if not self.variables.has(var.name):
            hint = ""
            if var.name in GEOMETRY_AXES or len(var.name) == 1:
                hint = " (an axis is only an index here, e.g. $AA_MM[X])"
            raise NcSyntaxError(refusal(var.name) or f"{var.name} is not a known variable{hint}; define local "
                                "variables with DEF", var.pos.line, var.pos.column, alarm=alarms.NC_NAME_UNKNOWN)
        return self.variables.definition(var.name)


# --- helpers -----------------------------------------------------------------------------------------

class _Watchdog:
    """The run-time bounds of one NC Start: at most ``max_jumps`` jumps, and no more than
    ``watchdog_s`` seconds of blocks without a command to the machine (a computing loop)."""

    def __init__(self, interp: Interpreter):
        self._interp = interp
        self._jumps = 0
        self._commands = interp._command_count
        self._since = time.monotonic()

    def check(self, block: n.Block, control: _Control) -> None:
        interp = self._interp
        if control.kind == "jump":
            self._jumps += 1
            if self._jumps > interp.max_jumps:
                raise NcAlarm(f"the program jumped {interp.max_jumps} times without ending: a loop that never ends "
                              "(check its condition)", block.line, block.pos.column, alarm=alarms.NC_RUNAWAY,
                              block_text=block.text)
        now = time.monotonic()
        if interp._command_count != self._commands:
            self._commands, self._since = interp._command_count, now
        elif now - self._since > interp.watchdog_s:
            raise NcAlarm(f"the program computed for {interp.watchdog_s:g} s without moving: watchdog",
                          block.line, block.pos.column, alarm=alarms.NC_RUNAWAY, block_text=block.text)


def _expressions(w) -> list[n.Expr]:
    if isinstance(w, n.Assign):
        return list(w.target.indices) + list(w.values)
    if isinstance(w, (n.AxisWord, n.Address, n.Meas, n.Spos)):
        return [w.value]
    if isinstance(w, n.CycleCall):
        return list(w.args)
    if isinstance(w, n.IfGoto):
        return [w.condition]
    if isinstance(w, n.Msg):
        return [w.value] if w.value is not None else []
    if isinstance(w, n.Define):
        return [i.init for i in w.items if i.init is not None]
    return []


def _local_definitions(program: n.Program, variables: Variables) -> list[VarDef]:
    """The program's DEF variables (LUD); a name may exist only once, and not as global data."""
    out: list[VarDef] = []
    variables.clear_locals()
    for block in program.blocks:
        for w in block.words:
            if not isinstance(w, n.Define):
                continue
            for item in w.items:
                if item.name in {d.name for d in out} or variables.has(item.name):
                    raise NcSyntaxError(f"DEF {item.name}: a variable {item.name} already exists",
                                        item.pos.line, item.pos.column, block_text=block.text)
                default = "" if w.type == "STRING" else 0
                out.append(VarDef(item.name, w.type, item.dims, default, length=w.length, scope="LUD"))
    return out


def _target_mcs(coords: Coordinates, position: Mapping[str, float], new: ModalState, axis_values,
                offsets: MeasuringOffsets) -> dict[str, float]:
    """The MCS axis targets of a block's axis words: geometry axes through the frame and the tool
    length (measuring offsets shift the programmed point), rotary axes by their frame offset;
    G90 absolute, G91 from where the tool tip is."""
    shift = np.array([offsets.offset(a) for a in GEOMETRY_AXES])
    target: dict[str, float] = {}
    geometry = [a for a in axis_values if a in GEOMETRY_AXES]
    if geometry:
        now_prog = coords.tip_wcs(position) - shift
        prog = now_prog.copy()
        for a in geometry:
            i = GEOMETRY_AXES.index(a)
            value = new.length_to_mm(axis_values[a][1])
            prog[i] = value if new.distance == "G90" else now_prog[i] + value
        axes = coords.axes_for(prog + shift)
        target.update({a: float(v) for a, v in zip(GEOMETRY_AXES, axes, strict=True)})
    for a, (_word, value) in axis_values.items():
        if a not in GEOMETRY_AXES:
            now = coords.rotary_wcs(a, position[a])
            target[a] = coords.rotary_mcs(a, value if new.distance == "G90" else now + value)
    return target


def _check_indexing(d: VarDef, var: n.Var) -> None:
    """An array is named with its indices (an axis name where it is indexed by axes), a scalar without."""
    def refuse(message: str) -> NcSyntaxError:
        return NcSyntaxError(message, var.pos.line, var.pos.column, alarm=alarms.NC_ARRAY_INDEX)

    if d.is_array and not var.indices:
        raise refuse(f"{d.name} is an array: name the element, e.g. {d.name}[0]")
    if not d.is_array and var.indices:
        raise refuse(f"{d.name} is not an array and takes no index")
    if d.axis_indexed:
        index = var.indices[0] if len(var.indices) == 1 else None
        if not (isinstance(index, n.Var) and not index.indices and index.name in GEOMETRY_AXES + ("A", "B", "C")):
            raise refuse(f"{d.name} takes an axis name as index, e.g. {d.name}[X]")
        return
    if d.shape and len(var.indices) != len(d.shape):
        raise refuse(f"{d.name} needs {len(d.shape)} ind{'ex' if len(d.shape) == 1 else 'ices'}")


def _truth(value, pos) -> bool:
    if isinstance(value, str):
        raise EvalError(f"IF needs a condition, not the text \"{value}\"", pos, alarms.NC_VALUE_RANGE)
    return bool(value)


def _text(value) -> str:
    return value if isinstance(value, str) else f"{value:g}" if isinstance(value, float) else str(value)


def _fmt(x: float) -> str:
    return f"{x:.4f}".rstrip("0").rstrip(".")


def _whole(value: float, word, letter: str, interp: Interpreter) -> int:
    if not math.isfinite(value) or value != int(value) or value < 0:
        definition = alarms.NC_D_NUMBER if letter == "D" else alarms.NC_VALUE_RANGE
        raise interp._alarm(word, definition, f"{letter}{value:g}: {letter} takes a whole number 0 or greater")
    return int(value)

"""Measuring workflow service: NC Start per point, invalidate, Calculate, abort.

Data flow (design.md §2): screen/API -> here -> engine.plan -> machine.probe per step ->
stored Pn -> engine.evaluate -> engine.correction -> db (offset + audit + log in one
transaction) -> activation. The service holds at most one session per machine.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

from app.machine.protocol import Machine, MachineAlarm
from app.workflow.executor import MotionAborted, StepExecutor
from app.workflow.session import MeasureSession, stored_point_to_api
from engine.frames import Frame, FrameChain
from engine.plan import run_program
from engine.planes import Plane
from engine.types import MeasuringError, ProbeRecord

MEASURE_ONLY = "measure_only"


class WorkflowError(Exception):
    """A request the workflow refuses; ``status`` is the HTTP status to answer with."""

    def __init__(self, status: int, code: str, message: str, field: str | None = None):
        super().__init__(message)
        self.status, self.code, self.message, self.field = status, code, message, field


@dataclass(frozen=True)
class MeasuringContext:
    """Snapshot of everything a measurement needs, taken when NC Start is pressed."""

    active_offset: str                  # WO active while measuring ("G500", "G54", ..)
    offsets: dict[str, Frame]           # every stored frame by name
    frame_chain: FrameChain             # WCS -> BCS while measuring (settable = active_offset)
    basic_names: tuple[str, ...]        # names of frame_chain.basic (BASIC_0, BASIC_1, ..)
    plane: Plane
    tool_length: float                  # NC offset length of the tool in the spindle
    tool: dict | None                   # tool table row of the tool in the spindle
    spindle_angle: float
    feed_override: float
    settings: dict                      # GUD settings (app.gud)
    probe: ProbeRecord | None           # active workpiece probe record, None if no probe
    probe_data: dict | None = None      # the stored probe record as JSON
    extra: dict = field(default_factory=dict)

    def chain(self) -> FrameChain:
        return self.frame_chain

    @staticmethod
    def in_chain(target: str) -> bool:
        """A basic frame (BASIC_REF, BASIC_n): always part of the active chain, unlike a WO."""
        return target.startswith("BASIC")

    def parent2bcs_of(self, target: str) -> Frame:
        """Composition of the frames outside ``target`` (MCS side first)."""
        if target in self.basic_names:
            return self.frame_chain.parent2bcs_of_basic(self.basic_names.index(target))
        if self.in_chain(target):           # BASIC_REF, the SETFRAME: nothing outside it
            return Frame.identity()
        return self.frame_chain.below_settable


class WorkflowEnv(Protocol):
    """What the app provides to the workflow (implemented in app.services)."""

    machine: Machine

    def measuring_context(self) -> MeasuringContext: ...

    def commit_measurement(self, *, offset: tuple[str, dict, dict, dict] | None, log_entry: dict,
                           probe_update: tuple[int, dict] | None = None,
                           tool_update: tuple[int, dict] | None = None,
                           tool_probe_update: tuple[int, dict] | None = None) -> int:
        """Write offset (name, before, after, detail) + audit + log (+ data records) in one transaction."""

    def activate(self, name: str) -> None: ...

    def refresh_frames(self) -> None:
        """Re-send the active frame chain to the machine (after a basic frame changed)."""

    def post_alarm(self, code: int, text: str) -> None: ...


# A finisher turns the stored points into (answer, commit kwargs) for one task family.
Finisher = Callable[[MeasureSession, MeasuringContext], tuple[dict, dict]]


class WorkflowService:
    def __init__(self, env: WorkflowEnv, finishers: dict[str, Finisher],
                 plan_module, task_points: dict[str, int]):
        self._env = env
        self._finishers = finishers
        self._plan = plan_module
        self._task_points = task_points
        self._lock = threading.Lock()
        self._session: MeasureSession | None = None

    # --- sessions -----------------------------------------------------------------------
    @property
    def session(self) -> MeasureSession | None:
        return self._session

    def get(self, session_id: str) -> MeasureSession:
        if self._session is None or self._session.id != session_id:
            raise WorkflowError(404, "no_session", f"measuring session {session_id} does not exist")
        return self._session

    def create(self, task: str, params: dict, target: str | None = None) -> MeasureSession:
        if task not in self._task_points:
            raise WorkflowError(400, "unknown_task", f"unknown measuring task {task!r}", "task")
        ctx = self._env.measuring_context()
        try:
            normalised = self._plan.validate_params(task, dict(params or {}), ctx.plane)
        except ValueError as exc:
            raise WorkflowError(400, "invalid_param", str(exc), getattr(exc, "field", None)) from exc
        self._check_rotary_axis(normalised)
        chosen = target or ctx.active_offset
        if chosen == "G500":
            chosen = MEASURE_ONLY if task.split(".")[0] not in ("probe", "tool", "toolprobe") else chosen
        self._check_target(task, chosen, ctx)
        # never wait for a running NC Start (it holds the lock for the whole measurement)
        if not self._lock.acquire(blocking=False):
            raise WorkflowError(409, "busy", "a measurement is running; press Reset first")
        try:
            if self._session is not None and self._session.running:
                raise WorkflowError(409, "busy", "a measurement is running; press Reset first")
            self._session = MeasureSession.create(task, normalised, chosen, ctx.active_offset,
                                                  self._task_points[task])
            return self._session
        finally:
            self._lock.release()

    def _check_rotary_axis(self, params: dict) -> None:
        """A rotary-axis angle correction names a configured rotary axis (spec §2.3 [I])."""
        axis = params.get("angle_correction")
        if axis in (None, "rotation", "none"):
            return
        if axis not in tuple(getattr(self._env.machine, "axes", ())):
            raise WorkflowError(400, "invalid_param",
                                f"angle_correction: {axis} is not a rotary axis of this machine",
                                "angle_correction")

    # params that only enter the calculation may change while points are stored (spec §3.1 [I])
    EDITABLE_WHILE_STORED = frozenset({"setpoint", "setpoint_angle", "angle_correction", "set_p1", "target"})

    def update_params(self, session_id: str, params: dict, target: str | None = None) -> MeasureSession:
        """Change setpoints/target of an open session until Calculate; probing params stay locked."""
        session = self.get(session_id)
        if session.running:
            raise WorkflowError(409, "busy", "a measurement is running")
        ctx = self._env.measuring_context()
        try:
            normalised = self._plan.validate_params(session.task, dict(params or {}), ctx.plane)
        except ValueError as exc:
            raise WorkflowError(400, "invalid_param", str(exc), getattr(exc, "field", None)) from exc
        if any(s.stored for s in session.slots):
            for key in set(normalised) | set(session.params):
                if key not in self.EDITABLE_WHILE_STORED and normalised.get(key) != session.params.get(key):
                    raise WorkflowError(409, "locked", f"{key} is locked while a point is stored", key)
        self._check_rotary_axis(normalised)
        chosen = target or session.target
        self._check_target(session.task, chosen, ctx)
        session.params, session.target = normalised, chosen
        return session

    def _check_target(self, task: str, target: str, ctx: MeasuringContext) -> None:
        if task.split(".")[0] in ("probe", "tool", "toolprobe"):
            return
        if target != MEASURE_ONLY and target not in ctx.offsets:
            raise WorkflowError(400, "invalid_target", f"unknown zero offset {target!r}", "target")

    def delete(self, session_id: str) -> None:
        """Leave the screen: abort and discard stored points (spec §3.1)."""
        session = self.get(session_id)
        if session.running:
            self._env.machine.reset()
        self._session = None

    def invalidate(self, session_id: str, n: int) -> MeasureSession:
        session = self.get(session_id)
        if session.running:
            raise WorkflowError(409, "busy", "a measurement is running")
        try:
            session.invalidate(n)
        except KeyError:
            raise WorkflowError(404, "no_point", f"point P{n} does not exist for {session.task}",
                                    "point") from None
        return session

    # --- NC Start -----------------------------------------------------------------------
    def start(self, session_id: str, point: int | None = None) -> dict:
        session = self.get(session_id)
        if not self._lock.acquire(blocking=False):
            raise WorkflowError(409, "busy", "a measurement is already running")
        try:
            if session.running or self._env.machine.status().busy:
                raise WorkflowError(409, "busy", "the machine is moving")
            n = point if point is not None else session.next_point()
            if n is None:
                if session.single_point:
                    n = 1
                else:
                    raise WorkflowError(409, "all_stored",
                                        "all points are stored: press Calculate or invalidate a point")
            try:
                slot = session.slot(n)
            except KeyError:
                raise WorkflowError(404, "no_point", f"point P{n} does not exist for {session.task}",
                                    "point") from None
            alarms = [a for a in self._env.machine.status().alarms]
            if alarms:
                raise WorkflowError(409, "alarm", f"{alarms[-1].code} {alarms[-1].text}: press Reset first")
            session.running = True
            session.last_alarm = None
            ctx = self._env.measuring_context()
            if session.task.split(".")[0] not in ("tool", "toolprobe") and ctx.probe is None:
                raise WorkflowError(409, "alarm", "61309 Check probe type: the tool in the spindle is "
                                                  "not a 3D probe (type 710); change to the probe first")
            session.warnings = self._warnings(session, ctx)
            if self._refuse_override(ctx):
                raise WorkflowError(409, "override_mismatch", session.warnings[-1])
            try:
                stored, raw = self._measure_point(session, n, ctx)
            except (MachineAlarm, MeasuringError, MotionAborted) as exc:
                slot.point, slot.raw = None, []
                session.last_alarm = self._alarm_of(exc)
                if isinstance(exc, MeasuringError):
                    self._env.post_alarm(exc.alarm, exc.message)
                raise WorkflowError(409, "alarm", f"{session.last_alarm['code']} {session.last_alarm['text']}") from exc
            slot.point, slot.raw = stored, raw
            session.running = False
            answer = {"session": session.to_api(), "point": slot.to_api()}
            if session.single_point:
                answer.update(self._finish(session, ctx))
            return answer
        finally:
            session.running = False
            self._lock.release()

    @staticmethod
    def _alarm_of(exc: Exception) -> dict:
        if isinstance(exc, MachineAlarm):
            return {"code": exc.alarm.code, "text": exc.alarm.text}
        if isinstance(exc, MeasuringError):
            return {"code": exc.alarm, "text": exc.message}
        return {"code": 0, "text": "Measurement aborted by Reset"}

    def _warnings(self, session: MeasureSession, ctx: MeasuringContext) -> list[str]:
        warnings: list[str] = []
        probe = ctx.probe
        if session.task.split(".")[0] in ("tool", "toolprobe"):
            return warnings
        if probe is None:
            return warnings
        if session.task != "probe.radius" and not probe.calibrated_radius:
            warnings.append("Probe not calibrated (radius): results carry its eccentricity and pre-travel")
        if (probe.calibration_override is not None
                and abs(probe.calibration_override - ctx.feed_override) > 1e-9
                and not session.task.startswith("probe.")):
            warnings.append(f"Feed override {ctx.feed_override:g} % differs from the calibration's "
                            f"{probe.calibration_override:g} %: set the same override (spec §1.7)")
        return warnings

    def _refuse_override(self, ctx: MeasuringContext) -> bool:
        probe = ctx.probe
        return bool(ctx.settings.get("override_mismatch") == "refuse" and probe is not None
                    and probe.calibration_override is not None
                    and abs(probe.calibration_override - ctx.feed_override) > 1e-9)

    def _measure_point(self, session: MeasureSession, n: int, ctx: MeasuringContext):
        plan_ctx = self._plan.context_from(ctx, session)
        executor = StepExecutor(self._env.machine, ctx.chain().wcs2bcs, ctx.tool_length,
                                ctx.plane.infeed_unit)
        coords = "MCS" if session.task.split(".")[0] in ("tool", "toolprobe") else "WCS"
        start = executor.current(coords)
        program = self._plan.point_program(session.task, session.params, n, start, plan_ctx)
        raw: list[dict] = []

        def execute(step):
            latch = executor.run(step)
            if latch is not None:      # the raw latches go into the log
                raw.append({"triggered": latch.triggered, "rec": _floats(latch.rec),
                            "mcs": _floats(latch.latched_mcs)})
            return latch

        return run_program(program, execute), raw

    # --- Calculate ----------------------------------------------------------------------
    def calculate(self, session_id: str) -> dict:
        session = self.get(session_id)
        if session.running:
            raise WorkflowError(409, "busy", "a measurement is running")
        if session.single_point:
            raise WorkflowError(409, "single_point", "this task computes on NC Start; there is no Calculate")
        if not session.can_calculate:
            missing = [s.n for s in session.slots if not s.stored]
            raise WorkflowError(409, "points_missing",
                                "Calculate needs all points stored; missing " + ", ".join(f"P{n}" for n in missing))
        ctx = self._env.measuring_context()
        return self._finish(session, ctx)

    def _finish(self, session: MeasureSession, ctx: MeasuringContext) -> dict:
        family = session.task.split(".")[0]
        finisher = self._finishers.get(session.task) or self._finishers.get(family) \
            or self._finishers["workpiece"]
        try:
            answer, commit = finisher(session, ctx)
        except MeasuringError as exc:
            session.last_alarm = {"code": exc.alarm, "text": exc.message}
            self._env.post_alarm(exc.alarm, exc.message)
            raise WorkflowError(409, "alarm", f"{exc.alarm} {exc.message}") from exc
        log_entry = {
            "task": session.task,
            "params": session.params,
            "target": session.target,
            "measuring_wo": session.measuring_wo,
            "raw": {f"P{s.n}": s.raw for s in session.slots},
            "points": {f"P{s.n}": stored_point_to_api(s.point) for s in session.slots},
            "result": answer.get("result"),
            "correction": answer.get("correction"),
            "probe": ctx.probe_data,
            "warnings": session.warnings,
            "status": "ok",
        }
        log_id = self._env.commit_measurement(log_entry=log_entry, **commit)
        answer["log_id"] = log_id
        activate = answer.pop("_activate", None)
        if activate:
            self._env.activate(activate)
        elif answer.get("_refresh_frames"):
            self._env.refresh_frames()
        answer.pop("_refresh_frames", None)
        answer["warnings"] = list(session.warnings)
        session.clear_points()        # spec §3.1 step 6: ready for a new measurement
        session.last = answer
        return answer


def points_of(session: MeasureSession) -> list:
    return [s.point for s in session.slots]


def _floats(v) -> list[float] | None:
    return None if v is None else [float(x) for x in v]

"""Measuring workflow service: NC Start per point, invalidate, Calculate, abort.

Data flow (design.md §2): screen/API -> here -> engine.plan -> machine.probe per step ->
stored Pn -> engine.evaluate -> engine.correction -> db (offset + audit + log in one
transaction) -> activation. The service holds at most one session per machine.
"""

from __future__ import annotations

import contextvars
import logging
import math
import threading
from collections.abc import Mapping

import numpy as np

from app.errors import ModeError, WorkflowError
from app.machine.protocol import Lathe, MachineAlarm, MachineData
from app.workflow import guard, probe_trust
from app.workflow.context import (
    MEASURE_ONLY,
    MeasuringContext,
    MeasuringSetup,
    OffsetOutcome,
    ToolOffsetOutcome,
    WorkflowEnv,
)
from app.workflow.executor import MotionAborted, StepExecutor
from app.workflow.finish import setpoints_of
from app.workflow.finish_tool_offset import target_label, tolerance_defaults, tool_target
from app.workflow.session import MeasureSession, stored_point_to_api
from app.workflow.tasks import TASKS, Category, Target, TaskSpec, task_spec
from db import StorageUnavailable
from engine import alarms
from engine.frames import chain_of, is_basic
from engine.plan import ideal_path, run_program
from engine.planes import axis_index
from engine.strategy import Tolerance
from engine.tasks import evaluate
from engine.types import MeasuringError, averaged, translated

__all__ = ["MEASURE_ONLY", "MeasuringContext", "WorkflowEnv", "WorkflowError", "WorkflowService"]

log = logging.getLogger(__name__)


def system_frame_missing(machine) -> str | None:
    """Why every measurement is refused with 61016 (manual ch. 10's alarm table: source "all";
    §9.1.1, jog-measuring.md §9.1): the cycles need the system frame for cycles, MD 28082 bit 5.
    None when it is set, or when the control's machine data cannot be read."""
    mask = machine.machine_data().get("28082") if isinstance(machine, MachineData) else None
    if isinstance(mask, int | float) and not int(mask) & 0x20:
        return f"MD 28082 MM_SYSTEM_FRAME_MASK is {int(mask):X}H, set bit 5 = 1"
    return None


class WorkflowService:
    def __init__(self, env: WorkflowEnv, tasks: Mapping[str, TaskSpec] = TASKS):
        self._env = env
        self._tasks = tasks
        self._lock = threading.Lock()
        self._ended = threading.Condition()     # a background NC Start ended (wait_ended)
        self._session: MeasureSession | None = None
        self._reset = threading.Event()        # Reset: the running measurement starts no further step
        self._runner: threading.Thread | None = None

    # --- Reset and the mode group (MachineService.on_reset / add_interlock) --------------------
    def abort(self) -> None:
        """Reset, first step: the running measurement starts no further motion."""
        if self._lock.locked():
            self._reset.set()

    def wait_idle(self, timeout: float = 2.0) -> None:
        """Reset, second step: returns when no measurement runs (at most ``timeout``)."""
        if self._runner is threading.current_thread():
            return
        if self._lock.acquire(timeout=timeout):
            self._lock.release()

    def lock(self) -> dict | None:
        """``{"mode": "JOG", "program": task}`` while a JOG measurement runs."""
        session = self._session
        return {"mode": "JOG", "program": session.task} if session is not None and session.running else None

    def interlock(self, action: str) -> None:
        """While a JOG measurement runs, a program may not start (409 ``mode`` naming the task)."""
        lock = self.lock()
        if action != "nc_run" or lock is None:
            return
        raise ModeError(f"The JOG measurement {lock['program']} runs: a program starts when it has ended "
                        "(Reset ends it)", extra={**lock, "action": action})

    # --- sessions -----------------------------------------------------------------------
    @property
    def session(self) -> MeasureSession | None:
        return self._session

    def get(self, session_id: str) -> MeasureSession:
        if self._session is None or self._session.id != session_id:
            raise WorkflowError(404, "no_session", f"measuring session {session_id} does not exist")
        return self._session

    def spec(self, task: str) -> TaskSpec:
        spec = self._tasks.get(task) if isinstance(task, str) else None
        return spec if spec is not None else task_spec(task)     # unknown: 400 naming "task"

    @staticmethod
    def _validate(spec: TaskSpec, params: dict, ctx: MeasuringSetup) -> dict:
        try:
            return spec.validate(dict(params or {}), ctx.plane)
        except ValueError as exc:
            raise WorkflowError(400, "invalid_param", str(exc), getattr(exc, "field", None)) from exc

    def create(self, task: str, params: dict, target: str | dict | None = None) -> MeasureSession:
        spec = self.spec(task)
        params = dict(params or {})
        guard_on = self._guard_switch(params.pop("guard", True), task)
        ctx = self._env.measuring_setup()
        wanted = ctx.settings.measuring_wo           # _JM_I[4]: the WO active while measuring (jog-measuring §4.4)
        if wanted != "active" and wanted != ctx.active_offset and not (self._session and self._session.running):
            self._env.activate(wanted)
            ctx = self._env.measuring_setup()
        self._check_machine_kind(spec)
        if spec.target_in_params:
            normalised, chosen = self._params_with_target(spec, params, target, ctx)
        else:
            normalised = self._validate(spec, params, ctx)
            try:
                spec.check_machine(normalised, self._env)
            except ValueError as exc:
                raise WorkflowError(400, "invalid_param", str(exc), getattr(exc, "field", None)) from exc
            self._check_rotary_axis(normalised)
            chosen = target or ctx.active_offset
            if chosen == "G500" and spec.corrects_zero_offset:
                chosen = MEASURE_ONLY
            chosen = self._check_target(spec, chosen, normalised, ctx)
        # never wait for a running NC Start (it holds the lock for the whole measurement)
        if not self._lock.acquire(blocking=False):
            raise WorkflowError(409, "busy", "a measurement is running; press Reset first")
        try:
            if self._session is not None and self._session.running:
                raise WorkflowError(409, "busy", "a measurement is running; press Reset first")
            self._session = MeasureSession.create(task, normalised, chosen, ctx.active_offset,
                                                  spec.points_of(normalised))
            self._session.guard = guard_on
            return self._session
        finally:
            self._lock.release()

    def _guard_switch(self, value, task: str) -> bool:
        """``params.guard``: true (default) or false; false needs the ``settings`` level and is
        audited (design.md §10.1)."""
        if not isinstance(value, bool):
            raise WorkflowError(400, "invalid_param", "guard: true or false", "guard")
        if not value:
            switch_off = getattr(self._env, "guard_off", None)
            if callable(switch_off):
                switch_off(task)
        return value

    def _check_machine_kind(self, spec: TaskSpec) -> None:
        """The lathe tasks need a lathe, the milling tasks a milling machine (turning.md §10.1)."""
        lathe = isinstance(self._env.machine, Lathe)
        if spec.lathe and not lathe:
            raise WorkflowError(409, "not_a_lathe", f"{spec.name} measures on a lathe; this machine is a "
                                "milling machine", "task")
        if lathe and not spec.lathe:
            raise WorkflowError(409, "lathe", f"{spec.name} is a milling task; on the lathe use the lathe tasks "
                                "(lathe.*)", "task")

    def _params_with_target(self, spec: TaskSpec, params: dict, target, ctx: MeasuringSetup):
        """Lathe tasks: ``target`` is one of the params the engine validates (turning.md §10.2); a
        zero offset must be one of the stored frames. -> (params, session target)."""
        params = dict(params or {})
        if target is not None:
            params["target"] = target
        normalised = self._validate(spec, params, ctx)
        chosen = normalised.get("target")
        if isinstance(chosen, str) and chosen != MEASURE_ONLY and chosen not in ctx.offset_names:
            raise WorkflowError(400, "invalid_target", f"unknown zero offset {chosen!r}", "target")
        return normalised, chosen

    def _check_rotary_axis(self, params: dict) -> None:
        """A rotary-axis angle correction names a configured rotary axis (jog-measuring §2.3 [I])."""
        axis = params.get("angle_correction")
        if axis in (None, "rotation", "none"):
            return
        if axis not in tuple(self._env.machine.axes):
            raise WorkflowError(400, "invalid_param",
                                f"angle_correction: {axis} is not a rotary axis of this machine",
                                "angle_correction")

    # params that only enter the calculation may change while points are stored (jog-measuring §3.1 [I])
    EDITABLE_WHILE_STORED = frozenset({"setpoint", "setpoint_angle", "angle_correction", "set_p1", "target"})

    def update_params(self, session_id: str, params: dict, target: str | dict | None = None) -> MeasureSession:
        """Change setpoints/target of an open session until Calculate; probing params stay locked."""
        session = self.get(session_id)
        if session.running:
            raise WorkflowError(409, "busy", "a measurement is running")
        ctx = self._env.measuring_setup()
        spec = self.spec(session.task)
        if spec.target_in_params:
            params = dict(params or {})
            if target is None and "target" not in params and session.target is not None:
                target = session.target
            session.params, session.target = self._params_with_target(spec, params, target, ctx)
            return session
        normalised = self._validate(spec, params, ctx)
        if any(s.stored for s in session.slots):
            for key in set(normalised) | set(session.params):
                if key not in self.EDITABLE_WHILE_STORED and normalised.get(key) != session.params.get(key):
                    raise WorkflowError(409, "locked", f"{key} is locked while a point is stored", key)
        self._check_rotary_axis(normalised)
        chosen = self._check_target(spec, target or session.target, normalised, ctx)
        session.params, session.target = normalised, chosen
        return session

    def _check_target(self, spec: TaskSpec, target, params: dict, ctx: MeasuringSetup):
        """The normalised target: a WO name, or a tool offset object (design.md §9.3)."""
        if isinstance(target, dict):
            if Target.TOOL_OFFSET not in spec.targets:
                raise WorkflowError(400, "invalid_target", f"{spec.name} does not correct tools: "
                                    "choose a zero offset", "target")
            try:
                normalised = tool_target(target)
                Tolerance.from_params(params.get("tolerance"), tolerance_defaults(ctx.settings))
            except ValueError as exc:
                text = str(exc)
                field = text.split(":", 1)[0] if text.startswith("target.") else "tolerance"
                raise WorkflowError(400, "invalid_target" if field.startswith("target") else "invalid_param",
                                    text, field) from None
            return normalised
        if "tolerance" in params and target != MEASURE_ONLY:    # measure only: the band of the verdict (§10.3)
            raise WorkflowError(400, "invalid_param", "tolerance: only for a tool offset target or measure only",
                                "tolerance")
        if "tolerance" in params:
            try:
                Tolerance.from_params(params.get("tolerance"), tolerance_defaults(ctx.settings))
            except ValueError as exc:
                raise WorkflowError(400, "invalid_param", str(exc), "tolerance") from None
        if not spec.corrects_zero_offset:
            return target
        if not isinstance(target, str) or (target != MEASURE_ONLY and target not in ctx.offset_names):
            raise WorkflowError(400, "invalid_target", f"unknown zero offset {target!r}", "target")
        if (target.startswith("BASIC_") and target != "BASIC_REF"
                and ctx.settings.compensation_choice != "extended"):          # jog-measuring §4.1/jog-measuring §4.2, _JM_I[5]
            raise WorkflowError(400, "invalid_target", f"{target}: a basic frame is a target of the extended "
                                "compensation choice only (setting Compensation choice = extended)", "target")
        return target

    def delete(self, session_id: str) -> None:
        """Leave the screen: abort and discard stored points (jog-measuring §3.1)."""
        session = self.get(session_id)
        if session.running:
            self._env.machine.reset()
        self._session = None

    def discard_points(self, reason: str) -> None:
        """The stored points lost their meaning (tool change, scenario load): discard them and
        let the session say why (design.md §9.1)."""
        session = self._session
        if session is None or session.running or not any(s.stored for s in session.slots):
            return
        session.clear_points()
        session.notice = f"{reason}: the stored points were discarded, measure them again"

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
    def start(self, session_id: str, point: int | None = None, wait: bool = True) -> dict:
        """NC Start: probe point ``point`` (default: the lowest unstored). With ``wait`` False the
        measurement runs in the background (the answer is 202-style: the session, ``running``
        true, its ``progress``); the session's ``answer``/``alarm`` tell how it ended."""
        session = self.get(session_id)
        try:
            self._env.interlock("measure")
        except ModeError as exc:                # the screens show a WorkflowError's message
            refusal = WorkflowError(409, "mode", exc.message)
            refusal.extra = exc.extra
            raise refusal from None
        if not self._lock.acquire(blocking=False):
            raise WorkflowError(409, "busy", "a measurement is already running")
        self._reset.clear()
        self._runner = threading.current_thread()
        try:
            spec, n, ctx = self._prepare_start(session, point)
        except BaseException:
            session.running = False
            self._lock.release()
            raise
        if wait:
            try:
                return self._run_point(session, spec, n, ctx, count_steps=False)
            finally:
                session.running = False
                self._lock.release()

        def background() -> None:
            self._runner = threading.current_thread()
            try:
                self._run_point(session, spec, n, ctx)
            except WorkflowError:
                pass                    # the session's alarm says what happened
            finally:
                session.running = False
                self._lock.release()
                with self._ended:
                    self._ended.notify_all()

        context = contextvars.copy_context()        # who pressed NC Start acts in the thread too (audit)
        threading.Thread(target=context.run, args=(background,), name=f"nc-start-{session.id}", daemon=True).start()
        return {"session": session.to_api(), "accepted": True}

    def wait_ended(self, session: MeasureSession, timeout_s: float) -> bool:
        """Wait up to ``timeout_s`` for a background NC Start of ``session`` to end (woken when it
        does, no polling); True when it is not running."""
        with self._ended:
            return self._ended.wait_for(lambda: not session.running, timeout_s)

    def _prepare_start(self, session: MeasureSession, point: int | None):
        """Every refusal of NC Start before anything moves; marks the session running."""
        if session.running or self._env.machine.status().busy:
            raise WorkflowError(409, "busy", "the machine is moving")
        n = self._start_point(session, point)
        pending = self._env.machine.status().alarms
        if pending:
            raise WorkflowError(409, "alarm", f"{pending[-1].code} {pending[-1].text}: press Reset first")
        self._check_system_frame()
        spec = self.spec(session.task)
        ctx = self._env.measuring_context()
        if spec.needs_probe and ctx.probe is None:
            raise WorkflowError(409, "alarm", f"{alarms.PROBE_TYPE.number} {alarms.PROBE_TYPE.text}: the tool in "
                                              "the spindle is not a 3D probe (type 710); change to the probe first")
        self._check_probe_ready(spec, ctx)
        self._check_probe_geometry(spec, ctx)
        warnings = self._start_warnings(session, spec, ctx)
        warnings += self._trust_and_guard(session, spec, n, ctx)
        session.warnings = warnings
        session.running = True
        session.last_alarm = None
        session.notice = None
        session.progress = {"point": n, "step": 0, "steps": None, "label": ""}
        return spec, n, ctx

    def _check_system_frame(self) -> None:
        missing = system_frame_missing(self._env.machine)
        if missing:
            raise WorkflowError(409, "alarm", f"{alarms.SYSTEM_FRAME_MISSING.number} {alarms.SYSTEM_FRAME_MISSING.text}: "
                                              f"{missing}")

    @staticmethod
    def _start_point(session: MeasureSession, point: int | None) -> int:
        """The point NC Start measures: the one asked for, else the next one not stored (P1 again
        on a single-point task)."""
        n = point if point is not None else session.next_point()
        if n is None:
            if not session.single_point:
                raise WorkflowError(409, "all_stored", "all points are stored: press Calculate or invalidate a point")
            n = 1
        try:
            session.slot(n)
        except KeyError:
            raise WorkflowError(404, "no_point", f"point P{n} does not exist for {session.task}", "point") from None
        return n

    def _start_warnings(self, session: MeasureSession, spec: TaskSpec, ctx: MeasuringContext) -> list[str]:
        """The warnings NC Start gives before the guard: the probe's, the unaligned tilt's; a
        refusal when the override does not match."""
        warnings = self._warnings(spec, ctx)
        tilt = getattr(self._env, "unaligned_tilt_warning", None)
        tilted = tilt() if callable(tilt) and spec.needs_probe and spec.category == Category.WORKPIECE else None
        if tilted and session.task != "plane.align":
            warnings.append(tilted)
        if self._refuse_override(ctx):
            raise WorkflowError(409, "override_mismatch", warnings[-1])
        return warnings

    def _trust_and_guard(self, session: MeasureSession, spec: TaskSpec, n: int, ctx: MeasuringContext) -> list[str]:
        """The probe-trust findings and the start guard's verdict: refusals, else warnings."""
        # the start guard runs the point's program once; the probe-trust check reads its probing
        # directions from that run (a second run with ideal latches only when it cannot tell)
        # every task: the collisions where the guard has a model, the probe's reach always
        guarded = session.guard
        report = self._guard_report(session, spec, n, ctx) if guarded else None
        directions = guard.ideal_directions(report) if isinstance(report, guard.GuardReport) else None
        distrust = probe_trust.findings(spec, session.params, n, ctx, self._env.machine, directions)
        if distrust and ctx.settings.calibration_invalid == "refuse":
            raise WorkflowError(409, distrust[0].code, distrust[0].message)
        warnings = [f.message for f in distrust]
        if guarded:
            warnings += self._guard_verdict(report, session, spec, n)
        return warnings

    def _guard_report(self, session: MeasureSession, spec: TaskSpec, n: int, ctx: MeasuringContext
                      ) -> guard.GuardReport | Exception | None:
        """The start guard's report of point ``n`` (None: the program raised its own alarm, which
        NC Start raises; an other exception is raised where the guard's verdict is taken)."""
        try:
            return guard.check_point(self._env.machine, spec, session.params, n, ctx)[0]
        except MeasuringError:
            return None
        except Exception as exc:     # noqa: BLE001 - raised in _guard_verdict, after the refusals before it
            return exc

    def _guard_verdict(self, report: guard.GuardReport | Exception | None, session: MeasureSession,
                       spec: TaskSpec, n: int) -> list[str]:
        """The start guard (issue 24 §1): refuse before any motion (409 ``guard``); the warning
        when the control has no model to check against, or the task is not modelled."""
        if isinstance(report, Exception):
            raise report
        if report is None:
            return []                      # NC Start raises the program's own alarm
        refused = guard.refusal_error(report, n, ("X", "Y", "Z"), session.params, x_radius=bool(spec.lathe))
        if refused is not None:
            raise refused
        if not guard.guarded(spec):
            return [guard.not_modelled_warning(spec)]
        return [guard.UNKNOWN_WARNING] if report.unknown else []

    def plan(self, session_id: str, point: int | None = None) -> dict:
        """``GET /api/measure/{id}/plan``: the planned segments of a point from where the probe
        stands, with the guard's verdict per segment (design.md §10.1)."""
        session = self.get(session_id)
        n = point if point is not None else (session.next_point() or 1)
        try:
            session.slot(n)
        except KeyError:
            raise WorkflowError(404, "no_point", f"point P{n} does not exist for {session.task}", "point") from None
        spec = self.spec(session.task)
        ctx = self._env.measuring_context()
        try:
            report, coords = guard.check_point(self._env.machine, spec, session.params, n, ctx)
        except MeasuringError as exc:
            raise WorkflowError(409, "alarm", f"{exc.alarm} {exc.message}") from None
        answer = guard.plan_to_api(report, n, coords, ("X", "Y", "Z"))
        answer["guard"] = session.guard
        return answer

    def _check_probe_ready(self, spec: TaskSpec, ctx: MeasuringContext) -> None:
        """A probe that cannot switch refuses NC Start with an alarm, before anything moves
        (design.md §10.4): not the tool in the spindle, not armed (radio), deflected already.
        A controller that cannot tell (state None) is trusted."""
        status = self._env.machine.status()
        which = spec.probe_used
        state = status.probe if which == "workpiece" else status.tool_probe if which == "tool" else None
        if state is None:
            return
        refusal = None
        if which == "workpiece" and spec.needs_probe and ctx.probe is not None and not state.in_spindle:
            refusal = alarms.PROBE_NOT_IN_SPINDLE
        elif state.armed is False:
            refusal = alarms.PROBE_NOT_ARMED if which == "workpiece" else alarms.TOOL_PROBE_NOT_ARMED
        elif state.deflected:
            refusal = alarms.PROBE_DEFLECTED if which == "workpiece" else alarms.TOOL_PROBE_DEFLECTED
        if refusal is not None:
            self._env.post_alarm(refusal.number, refusal.text)
            raise WorkflowError(409, "alarm", f"{refusal.number} {refusal.text}: {refusal.remedy}")

    def _run_point(self, session: MeasureSession, spec: TaskSpec, n: int, ctx: MeasuringContext,
                   count_steps: bool = True) -> dict:
        slot = session.slot(n)
        session.repetitions = 0
        while True:
            try:
                stored, raw = self._measure_point(spec, session, n, ctx, count_steps)
            except (MachineAlarm, MeasuringError, MotionAborted) as exc:
                slot.point, slot.raw, slot.context = None, [], None
                raise self._alarm(session, exc) from exc
            finally:
                session.progress = None
            slot.point, slot.raw, slot.context = stored, raw, ctx
            answer = {"session": session.to_api(), "point": slot.to_api()}
            if not spec.single_point:
                return answer
            answer.update(self._finish(session, spec))
            if not answer.get("_repeat"):
                answer.pop("_repeat", None)
                if session.params.get("verify"):
                    answer["verify"] = self._verify(spec, session, n, answer)
                    session.last = {**(session.last or {}), "verify": answer["verify"]}
                return answer
            session.repetitions += 1        # the repeat rule (_CBIT[0], measuring-math §3.6): measure again

    def _verify(self, spec: TaskSpec, session: MeasureSession, n: int, answer: dict) -> dict:
        """``params.verify`` (design.md §9.8, §10.2): probe the point again and report what remains
        of the deviation from the setpoints in the frame just written, whether it is active or not
        (the point is measured in the active WCS and expressed, through the BCS, in the written
        one); nothing written. Always a key: ``{"skipped": reason}`` when there is nothing to check."""
        reason = verify_skipped(session.target, answer)
        if reason is not None:
            return {"skipped": reason}
        target = str(session.target)
        ctx = self._env.measuring_context()
        try:
            point, _raw = self._measure_point(spec, session, n, ctx, count_steps=False)
        except (MachineAlarm, MeasuringError, MotionAborted) as exc:
            return {"ok": False, "alarm": self._alarm_of(exc)}
        finally:
            session.progress = None
        result = evaluate(session.task, session.params, [point], ctx.plane, ctx.probe)
        setpoints = setpoints_of(session, ctx.plane.axes)
        position = dict(result.fix.position)
        if target != ctx.active_offset and not is_basic(target):
            if result.fix.point is None:
                return {"skipped": f"{session.task} gives no point to express in the inactive {target}"}
            # p_target = (target WCS -> BCS)⁻¹ · (active WCS -> BCS) · p_active
            in_target = chain_of(ctx.offsets, target).p_in_wcs(ctx.chain().p_in_bcs(result.fix.point))
            position = {axis: float(in_target[axis_index(axis)]) for axis in position}
        remaining = {axis: float(value) - setpoints.get(axis, 0.0) for axis, value in position.items()}
        return {"ok": True, "result": result.values, "remaining": remaining, "wcs": target,
                "measured_in": ctx.active_offset}

    def _alarm(self, session: MeasureSession, exc: Exception) -> WorkflowError:
        """The alarm that ended the point: kept in the session, shown by the machine, logged."""
        session.last_alarm = self._alarm_of(exc)
        if isinstance(exc, MeasuringError):
            self._env.post_alarm(exc.alarm, exc.message)
        result = exc.result if isinstance(exc, MeasuringError) else None
        self._log_failure(session, result)
        refusal = WorkflowError(409, "alarm", f"{session.last_alarm['code']} {session.last_alarm['text']}")
        if result is not None:          # _TSA / _TDIF: the measured values and the decision (design.md §10.2)
            refusal.extra["result"] = result
        return refusal

    def _log_refusal(self, session: MeasureSession, code: str, message: str, result: dict) -> None:
        entry = {
            "task": session.task, "params": session.params, "measuring_wo": session.measuring_wo,
            "target": target_label(session.target) if isinstance(session.target, dict) else session.target,
            "status": f"refused {code}", "result": {**result, "refusal": {"code": code, "text": message}},
            "points": {f"P{s.n}": stored_point_to_api(s.point) for s in session.slots},
            "warnings": session.warnings,
        }
        try:
            self._env.commit_measurement(log_entry=entry)
        except StorageUnavailable:
            pass

    def _log_failure(self, session: MeasureSession, result: dict | None = None) -> None:
        """A failed attempt is a log entry too (status "alarm NNNNN"): which point, which step, why.
        Nothing else is written; a log that cannot be written leaves the alarm standing alone."""
        progress = session.progress or {}
        alarm = session.last_alarm or {}
        entry = {
            "task": session.task, "params": session.params, "measuring_wo": session.measuring_wo,
            "target": target_label(session.target) if isinstance(session.target, dict) else session.target,
            "status": f"alarm {alarm.get('code', '')}".strip(),
            "result": {**(result or {}),
                       "alarm": {**alarm, "point": progress.get("point"), "step": progress.get("label") or None}},
            "points": {f"P{s.n}": stored_point_to_api(s.point) for s in session.slots},
            "warnings": session.warnings,
            "calibration_id": self._calibration_id(session),
        }
        try:
            self._env.commit_measurement(log_entry=entry)
        except StorageUnavailable:
            pass

    def _calibration_id(self, session: MeasureSession) -> int | None:
        """The calibration a failed attempt was made with (its log entry carries it too)."""
        ctx = next((s.context for s in session.slots if s.context is not None), None)
        if ctx is None:
            try:
                ctx = self._env.measuring_context()
            except Exception:       # noqa: BLE001 - the alarm's log entry is written without it
                log.exception("the calibration of a failed measurement")
                return None
        return probe_trust.calibration_of(self.spec(session.task).category, ctx)["id"]

    @staticmethod
    def _alarm_of(exc: Exception) -> dict:
        if isinstance(exc, MachineAlarm):
            code, text = exc.alarm.code, exc.alarm.text
        elif isinstance(exc, MeasuringError):
            code, text = exc.alarm, exc.message
        else:
            return {"code": 0, "text": "Measurement aborted by Reset", "remedy": "Start the measurement again."}
        definition = alarms.by_number(code)
        return {"code": code, "text": text, "remedy": definition.remedy if definition else ""}

    MAX_PROBE_TILT_DEG = 45.0     # beyond, the plane's infeed is not the spindle axis (design.md §9.8)

    def _check_probe_geometry(self, spec: TaskSpec, ctx: MeasuringContext) -> None:
        """Refusals before motion (design.md §9.8, measuring-math §1.7): a plane whose infeed axis
        is not the spindle axis (the tool length would act along the wrong axis), a probe not
        calibrated in the active plane (61341), trigger values of another spindle orientation."""
        if not spec.needs_probe:
            return
        status = self._env.machine.status()
        tool_axis = np.asarray(getattr(status, "tool_axis", (0.0, 0.0, 1.0)), dtype=float)
        infeed = ctx.chain().wcs2bcs.dir_child2parent(ctx.plane.infeed_unit)
        tilt = math.degrees(math.acos(max(-1.0, min(1.0, float(tool_axis @ infeed)))))
        if tilt > self.MAX_PROBE_TILT_DEG:
            axis = "XYZ"[int(np.argmax(np.abs(tool_axis)))]
            raise WorkflowError(409, "alarm", f"{alarms.PROBE_PLANE.number} {alarms.PROBE_PLANE.text}: the infeed "
                                f"axis {ctx.plane.infeed} of {ctx.plane.name} is not the spindle axis ({axis}); "
                                f"measure in the plane whose infeed is {axis}, or align the head first")
        data = ctx.probe_data or {}
        if spec.category != Category.WORKPIECE or not data.get("calibrated_radius"):
            return
        planes = data.get("calibrated_planes") or []
        if planes and ctx.plane.name not in planes:
            raise WorkflowError(409, "alarm", f"{alarms.NOT_CALIBRATED_IN_PLANE.number} "
                                f"{alarms.NOT_CALIBRATED_IN_PLANE.text}: calibrated in {', '.join(planes)}, "
                                f"measuring in {ctx.plane.name}: calibrate the probe in {ctx.plane.name}")
        angle = data.get("calibrated_spindle_angle")
        if (data.get("pretravel_frame") or ctx.settings.pretravel_frame) != "machine" and angle is not None:
            off = abs((ctx.spindle_angle - float(angle) + 180.0) % 360.0 - 180.0)
            if off > 1e-6:
                raise WorkflowError(409, "spindle_orientation",
                                    f"The spindle is at {ctx.spindle_angle:g}°, the probe was calibrated at "
                                    f"{float(angle):g}°: its pre-travel turns with it. Position the spindle "
                                    f"(SPOS {float(angle):g}) first")

    @staticmethod
    def _warnings(spec: TaskSpec, ctx: MeasuringContext) -> list[str]:
        warnings: list[str] = []
        probe = ctx.probe
        if not spec.needs_probe or probe is None:
            return warnings
        if (probe.calibration_override is not None
                and abs(probe.calibration_override - ctx.feed_override) > 1e-9
                and spec.category == Category.WORKPIECE):
            warnings.append(f"Feed override {ctx.feed_override:g} % differs from the calibration's "
                            f"{probe.calibration_override:g} %: set the same override (jog-measuring §1.7)")
        return warnings

    def _refuse_override(self, ctx: MeasuringContext) -> bool:
        probe = ctx.probe
        return bool(ctx.settings.override_mismatch == "refuse" and probe is not None
                    and probe.calibration_override is not None
                    and abs(probe.calibration_override - ctx.feed_override) > 1e-9)

    def _measure_point(self, spec: TaskSpec, session: MeasureSession, n: int, ctx: MeasuringContext,
                       count_steps: bool = True):
        plan_ctx = spec.plan_context(ctx, session.params)        # planning.context_from; a lathe's own
        release = getattr(self._env, "release_jog", None)
        if callable(release):        # a jog's dead-man must never stop the measurement (MachineService)
            release()
        executor = StepExecutor(self._env.machine, ctx.chain().wcs2bcs, ctx.tool_length,
                                ctx.plane.infeed_unit, tip=spec.tool_tip(ctx))
        start = executor.current(spec.coords_for(session.params, plan_ctx))
        repeats = spec.repeats(session.params)        # _NMSP, measuring-math §1.4
        # the step count for the progress of a background NC Start (a waiting caller sees none)
        steps = repeats * len(ideal_path(spec.program(session.params, n, start, plan_ctx), start)) \
            if count_steps else None
        raw: list[dict] = []
        # pass: the repetition of the point's program (_NMSP), shown beside point and step
        progress = {"point": n, "step": 0, "steps": steps, "label": "", "pass": 1, "passes": repeats}
        session.progress = progress

        def execute(step):
            if self._reset.is_set():
                raise MotionAborted("Reset")
            current = session.progress
            assert current is not None, "set above for the run, cleared only after it (_run_point, _verify)"
            done = current["step"] + 1
            session.progress = {**progress, "step": min(done, steps) if steps else done,
                                "label": getattr(step, "label", "")}
            latch = executor.run(step)
            if latch is not None:      # the raw latches go into the log
                # tip_mcs: the NC's ball centre / tool tip in MCS, where the machine views draw the touch
                tip = executor.tip_conversion.tip_in_mcs(latch.latched_mcs) if latch.latched_mcs is not None else None
                raw.append({"triggered": latch.triggered, "rec": _floats(latch.rec),
                            "mcs": _floats(latch.latched_mcs), "tip_mcs": _floats(tip)})
            return latch

        points = []
        for k in range(repeats):
            progress["pass"] = k + 1
            points.append(run_program(spec.program(session.params, n, start, plan_ctx), execute))
        return averaged(points), raw

    # --- Calculate ----------------------------------------------------------------------
    def calculate(self, session_id: str) -> dict:
        session = self.get(session_id)
        if not self._lock.acquire(blocking=False):      # one Calculate or NC Start at a time
            raise WorkflowError(409, "busy", "a measurement or Calculate is running")
        try:
            if session.running:
                raise WorkflowError(409, "busy", "a measurement is running")
            if session.single_point:
                raise WorkflowError(409, "single_point", "this task computes on NC Start; there is no Calculate")
            if not session.can_calculate:
                missing = [s.n for s in session.slots if not s.stored]
                raise WorkflowError(409, "points_missing", "Calculate needs all points stored; missing "
                                    + ", ".join(f"P{n}" for n in missing))
            return self._finish(session, self.spec(session.task))
        finally:
            self._lock.release()

    def _finish(self, session: MeasureSession, spec: TaskSpec) -> dict:
        ctx, points = evaluation_inputs(session)
        try:
            answer, commit = spec.finish(session, ctx, points)
        except MeasuringError as exc:
            raise self._alarm(session, exc) from exc
        except WorkflowError as exc:
            if "result" in exc.extra:          # a refusal by a band keeps its measurement in the log
                self._log_refusal(session, exc.code, exc.message, exc.extra["result"])
            raise
        log_entry = {
            "task": session.task,
            "params": session.params,
            "target": target_label(session.target) if isinstance(session.target, dict) else session.target,
            "measuring_wo": session.measuring_wo,
            "raw": {f"P{s.n}": s.raw for s in session.slots},
            "points": {f"P{s.n}": stored_point_to_api(s.point) for s in session.slots},
            "result": answer.get("result"),
            "correction": answer.get("correction"),
            "probe": ctx.probe_data,
            "warnings": session.warnings,
            "status": "ok",
            "calibration_id": probe_trust.calibration_of(spec.category, ctx)["id"],
        }
        try:
            log_id, outcome = self._env.commit_measurement(log_entry=log_entry, **commit)
        except MeasuringError as exc:          # decided inside the transaction: nothing was written
            raise self._alarm(session, exc) from exc
        if isinstance(outcome, OffsetOutcome):
            answer.update(outcome.answer)
        elif isinstance(outcome, ToolOffsetOutcome):
            answer["result"] = {**answer["result"], **outcome.result}
            answer["correction"] = outcome.correction
            answer["_repeat"] = outcome.repeat
        answer["log_id"] = log_id
        answer["calibration"] = {**probe_trust.calibration_of(spec.category, ctx),
                                 "id": log_entry.get("calibration_id")}
        written = commit.get("probe_update") or commit.get("tool_probe_update")
        if written is not None:                 # this measurement was the calibration
            answer["calibration"].update(valid=True, invalid_reason=None, at=written[1].get("calibrated_at"))
        answer["calibration_id"] = log_entry.get("calibration_id")
        activate = answer.pop("_activate", None)
        if activate:
            self._env.activate(activate)
        elif answer.pop("_refresh_frames", None):
            self._env.refresh_frames()
        answer["warnings"] = list(session.warnings)
        if answer.get("_repeat"):
            return answer                # the same point is measured again (the repeat rule)
        answer.pop("_repeat", None)
        session.clear_points()        # jog-measuring §3.1 step 6: ready for a new measurement
        session.last = answer
        return answer


def verify_skipped(target, answer: dict) -> str | None:
    """Why ``params.verify`` cannot probe a check (design.md §10.2), or None."""
    if not isinstance(target, str):
        return "a tool offset is checked by measuring the next part, not by probing again"
    if target == MEASURE_ONLY:
        return "measure only: nothing was written to check"
    correction = answer.get("correction") or {}
    if correction.get("after") is None:
        return "nothing was written"
    if correction.get("rotary_axis"):
        return f"the rotary axis {correction['rotary_axis']} must be positioned before the written frame can be checked"
    return None


def evaluation_inputs(session: MeasureSession) -> tuple[MeasuringContext, list]:
    """The context to evaluate in (P1's) and every stored point in its WCS (design.md §9.1).

    Points taken in measuring systems that differ by a translation (another WO activated, a WO
    edited between the points) are moved into P1's WCS through the BCS. A change of the
    rotation, the plane, the probe record or the tool length between the points cannot be made
    good: Calculate is refused (409 ``context_changed``) and nothing is written."""
    slots = session.slots
    first = slots[0].context
    points = [slots[0].point]
    for slot in slots[1:]:
        ctx = slot.context
        if ctx is None or first is None:
            points.append(slot.point)
            continue
        reason = _changed(first, ctx)
        if reason:
            raise WorkflowError(409, "context_changed", f"{reason} between P1 and P{slot.n}: "
                                "measure the points again (invalidate them) before Calculate")
        between = first.chain().wcs2bcs.inverse().compose(ctx.chain().wcs2bcs)   # P_n's WCS -> P1's WCS
        assert slot.point is not None, "a slot's context is stored together with its point"
        points.append(translated(slot.point, between.translation))
    return first, points


def _changed(first: MeasuringContext, other: MeasuringContext) -> str | None:
    if other.plane.name != first.plane.name:
        return "The working plane changed"
    if other.probe != first.probe or other.tool_length != first.tool_length \
            or (other.tool or {}).get("t") != (first.tool or {}).get("t"):
        return "The probe data or the tool changed"
    r1, r2 = first.chain().wcs2bcs.rotation, other.chain().wcs2bcs.rotation
    if float(np.max(np.abs(r1 - r2))) > 1e-12 or first.chain().wcs2bcs.rotary != other.chain().wcs2bcs.rotary:
        return "The rotation of the measuring zero offset changed"
    return None


def _floats(v) -> list[float] | None:
    return None if v is None else [float(x) for x in v]

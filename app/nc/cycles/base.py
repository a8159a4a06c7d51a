"""What every measuring cycle shares: its parameters, its correction target, the JOG task it
runs, its results (measuring-math §2, measuring-math §3, measuring-math §4).

A cycle runs the JOG task that measures the same feature (``app.workflow.tasks.TASKS``) through
the same ``WorkflowService`` (validation, probing program, step executor, evaluation, tolerance
strategy, commit of offset + audit + log in one transaction, activation) on an environment the
``CycleHost`` provides for the call: the program's plane, the cycle's measuring path ``_FA``,
feed ``_VMS`` and bits in place of the JOG settings, and the program and block in the log entry.
Where the cycle probes differently (positions, directions, points) the cycle positions the probe
or hands the task a planner of its own; the evaluation stays the JOG one.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from app.errors import HmiError, WorkflowError
from app.nc.interpreter import CycleContext
from app.workflow.context import MEASURE_ONLY, MeasuringContext, MeasuringSetup
from app.workflow.service import WorkflowService
from app.workflow.tasks import TaskSpec
from engine import alarms
from engine.alarms import AlarmDef
from engine.frames import is_basic
from engine.planes import PLANES, Plane
from engine.types import MeasuringError

INCH = 25.4


class NcMeasuring(Protocol):
    """The measuring environment of one cycle call (``CycleHost.measuring``)."""

    def setup(self) -> MeasuringSetup:
        """Plane, active WO, offset names, settings as the cycle sees them (no tool/probe data)."""

    def context(self) -> MeasuringContext:
        """The measuring context now (probe record, tool, frames), as NC Start would take it."""

    def workflow(self, tasks: Mapping[str, TaskSpec]) -> WorkflowService:
        """A workflow over this environment that knows ``tasks`` (JOG specs, maybe varied)."""


class CycleHost(Protocol):
    """What the product gives the cycles (implemented in app.services.nc)."""

    def measuring(self, ctx: CycleContext, settings: Mapping[str, Any], cycle: Mapping[str, Any]) -> NcMeasuring:
        """The environment of this call: ``settings`` replace the GUD settings (app.gud names),
        ``cycle`` (name, variant, inputs) goes into the log entry with the program and block."""

    def authorize(self, category, target) -> None:
        """Raise (an ``HmiError``) when whoever started the program may not write ``target``."""

    def system_frame_missing(self) -> str | None:
        """Why no measuring cycle may run (61016: MD 28082 bit 5), or None."""


class CycleAlarm(Exception):
    """An alarm of a cycle with its catalogue entry (becomes an NcAlarm at the call)."""

    def __init__(self, definition: AlarmDef, message: str):
        super().__init__(message)
        self.definition = definition
        self.message = message


def digit(value: int, n: int) -> int:
    """Decimal digit n (1 = units) of ``value``."""
    return (abs(int(value)) // 10 ** (n - 1)) % 10


@dataclass
class Call:
    """One cycle call: its context, parameters and results."""

    ctx: CycleContext
    host: CycleHost
    number: int
    ovr: dict[int, float] = field(default_factory=dict)
    ovi: dict[int, int] = field(default_factory=dict)
    inputs: dict[str, Any] = field(default_factory=dict)

    # --- parameters -----------------------------------------------------------------------
    def get(self, name: str, index: tuple = ()):
        value = self.ctx.variables.get(name, index)
        key = name if not index else f"{name}[{','.join(str(i) for i in index)}]"
        self.inputs[key] = value
        return value

    def real(self, name: str, index: tuple = ()) -> float:
        return float(self.get(name, index))

    def integer(self, name: str, index: tuple = ()) -> int:
        return int(self.get(name, index))

    def bit(self, name: str, index: int) -> bool:
        return bool(self.get(name, (index,)))

    def length(self, name: str, index: tuple = ()) -> float:
        """A parameter in the active unit system (``unit: act.``, measuring-math §4.1) in mm."""
        return self.ctx.modal.length_to_mm(self.real(name, index))

    def out(self, mm: float) -> float:
        """mm -> the active unit system, for a result."""
        return float(mm) / INCH if self.ctx.modal.inch else float(mm)

    @property
    def variant(self) -> int:
        return self.integer("_MVAR")

    @property
    def plane(self) -> Plane:
        return PLANES[self.ctx.modal.plane]

    @property
    def fa(self) -> float:
        """_FA (always mm, measuring-math §1.1); <= 0 -> 61308."""
        fa = self.real("_FA")
        if not fa > 0.0:
            raise CycleAlarm(alarms.MEASURING_PATH, f"_FA = {fa:g}: the measuring path must be greater than 0")
        return fa

    def feed(self) -> float:
        """Measuring feed (measuring-math §1.2): _VMS, else 150 mm/min for _FA <= 1, 300 above."""
        vms = self.real("_VMS")
        if vms > 0.0:
            return self.ctx.modal.feed_to_mm(vms)
        return 150.0 if self.fa <= 1.0 else 300.0

    def settings(self, **extra) -> dict:
        """The GUD settings this cycle measures with (app.gud names)."""
        return {
            "plane": self.ctx.modal.plane,
            "measuring_path": self.fa,
            "measuring_feed": self.feed(),
            "spigot_safety": self.fa,
            "attempts": 1 if self.bit("_CHBIT", 15) else 5,          # measuring-math §1.6
            "two_stage": self.bit("_CHBIT", 17),                    # measuring-math §1.2: _SPEED[3] first
            "fast_feed": self.real("_SPEED", (3,)) or 900.0,
            "rapid_return": False,
            "ev_add": self.bit("_CHBIT", 5),
            "tool_offset_geometry": self.bit("_CHBIT", 6),
            "tol_keep_mean": self.bit("_CHBIT", 4),
            "repeat_on_violation": self.bit("_CBIT", 0),
            "probe_record": self.probe_record(),
            **extra,
        }

    def probe_record(self) -> int:
        """The workpiece probe record _PRNUM names (its last two digits, manual §2.3.1; 1..3 here)."""
        number = self.integer("_PRNUM") % 100 or 1
        if not 1 <= number <= 3:
            raise CycleAlarm(alarms.NC_VALUE_RANGE, f"_PRNUM = {self.integer('_PRNUM')}: probe record 1..3")
        return number

    def measurements(self) -> int:
        n = self.integer("_NMSP")
        if not 1 <= n <= 99:
            raise CycleAlarm(alarms.NC_VALUE_RANGE, f"_NMSP = {n}: measure 1..99 times at one point")
        return n

    # --- positions ------------------------------------------------------------------------
    def position(self) -> np.ndarray:
        """Probe (NC reference: ball centre) in the active WCS now, mm."""
        return np.asarray(self.ctx.position_wcs(), dtype=float)

    def move(self, p_wcs, feed: float | None) -> None:
        self.ctx.move(np.asarray(p_wcs, dtype=float), feed)

    # --- targets --------------------------------------------------------------------------
    def zo_target(self, setup: MeasuringSetup) -> str:
        """_KNUM as a zero offset (measuring-math §2.1)."""
        knum = self.integer("_KNUM")
        if knum == 0:
            return MEASURE_ONLY
        names = setup.offset_names
        name = _zo_name(knum, setup.active_offset, [n for n in names if n.startswith("BASIC_") and n != "BASIC_REF"])
        if name not in names:
            definition = alarms.BASIC_FRAME_MISSING if is_basic(name) else alarms.ZO_NUMBER
            raise CycleAlarm(definition, f"_KNUM={knum}: {name} is not configured")
        self.ovi[0] = knum
        return name

    def tool_target(self, correct_length: bool | None = None) -> dict | str:
        """_KNUM as a tool offset (measuring-math §2.3, 7 digits) -> the JOG tool target of
        design.md §9.3, or measure only for _KNUM = 0. ``correct_length``: the measuring axis is
        the applicate (digit 4 = 0/1 then means L1); None: the feature has a radius (digit 4 = 0/1
        not possible)."""
        knum = self.integer("_KNUM")
        if knum == 0:
            return MEASURE_ONLY
        d, correct = _tool_knum(knum, correct_length)
        t = self.integer("_TNUM")
        if t <= 0:
            raise CycleAlarm(alarms.TOOL_NUMBER, f"_KNUM={knum}: no tool for the correction: set _TNUM")
        self.ovi[0], self.ovi[8] = d, t
        return {"tool": t, "edge": d, "correct": correct,
                "mode": "geometry" if self.bit("_CHBIT", 6) else "wear"}

    def tolerance(self, setpoint_mm: float) -> dict:
        """design.md §9.3 ``params.tolerance`` from the cycle's parameters (measuring-math §3.2)."""
        return {"setpoint": setpoint_mm, "upper": self.length("_TUL"), "lower": self.length("_TLL"),
                "zero_range": self.length("_TZL"), "mean_range": self.length("_TMV"),
                "dim_difference": self.length("_TDIF"), "safe_area": self.length("_TSA"),
                "k": self.integer("_K"), "evnum": self.integer("_EVNUM"), "keep_mean": self.bit("_CHBIT", 4)}

    # --- running the JOG task -----------------------------------------------------------------
    def measuring(self, **settings) -> NcMeasuring:
        cycle = {"cycle": f"CYCLE{self.number}", "variant": self.variant}
        return self.host.measuring(self.ctx, self.settings(**settings), {**cycle, "inputs": self.inputs})

    def run(self, env: NcMeasuring, spec: TaskSpec, params: dict, target: str | dict, *,
            before_point: Callable[[int], None] | None = None, order: Sequence[int] | None = None) -> dict:
        """The JOG task ``spec`` as a workflow session: NC Start for every point (in ``order``,
        ``before_point(n)`` positions the probe for point n first), Calculate for several points.
        Returns the answer (result, correction, log id)."""
        workflow = env.workflow({spec.name: spec})
        session = None
        try:
            self.host.authorize(spec.category, target)
            session = workflow.create(spec.name, params, target)
            answer = None
            for n in (order or range(1, spec.points + 1)):
                if self.ctx.stop_requested:
                    raise CycleAlarm(alarms.RESET_ABORT, "NC Stop: the measurement was abandoned")
                if before_point is not None:
                    before_point(n)
                answer = workflow.start(session.id, n)
            if spec.points > 1:
                answer = workflow.calculate(session.id)
            self._warn_probe((answer or {}).get("warnings") or [])
            return answer or {}
        except WorkflowError as exc:
            raise self.alarm_of(exc, session) from None
        except HmiError as exc:          # access level, storage, correction out of range, ...
            raise _cycle_alarm_of(exc) from None

    def _warn_probe(self, warnings: Sequence[str]) -> None:
        """A warning of the measurement that names an alarm (an uncalibrated or invalid probe,
        app.workflow.probe_trust) becomes the channel's message: a program warns as the screen does."""
        for text in warnings:
            code = str(text)[:5]
            definition = alarms.by_number(int(code)) if code.isdigit() else None
            if definition is not None:
                self.ctx.warn(definition, f"CYCLE{self.number}: {str(text)[6:]}")

    @staticmethod
    def alarm_of(exc: WorkflowError, session) -> CycleAlarm:
        alarm = getattr(session, "last_alarm", None) if session is not None else None
        if alarm:
            code = int(alarm.get("code") or 0)
            definition = alarms.by_number(code) if code else alarms.RESET_ABORT
            if code == alarms.PROBE_COLLISION.number:
                definition = alarms.PROBE_COLLISION
            return CycleAlarm(definition or alarms.NC_INTERNAL, str(alarm.get("text") or exc.message))
        if exc.code == "access_level":
            return CycleAlarm(alarms.NC_WRITE_PROTECTED, exc.message)
        if exc.code in ("not_calibrated", "calibration_invalid", "repeatability", "alarm"):
            number = exc.message[:5]             # "61016 text": app.workflow.probe_trust, NC Start's refusals
            found = alarms.by_number(int(number)) if number.isdigit() else None
            if found is not None or exc.code != "alarm":
                return CycleAlarm(found or alarms.CALIBRATION_INVALID, exc.message[6:])
        if exc.code in ("invalid_param", "invalid_target", "unknown_task"):
            return CycleAlarm(alarms.WRONG_VARIANT, exc.message)
        return CycleAlarm(alarms.NC_VALUE_RANGE, exc.message)

    # --- results -----------------------------------------------------------------------------------
    def common_results(self, answer: dict) -> None:
        """_OVR[27..31], _OVR[20], _OVI of the tool-offset strategy (measuring-math §4.2)."""
        result = answer.get("result") or {}
        self.ovr[27] = self.out(self.length("_TZL"))
        self.ovr[28] = self.out(self.length("_TSA"))
        self.ovr[29] = self.out(self.length("_TDIF"))
        if "decision" in result:
            self.ovr[20] = self.out(result.get("compensation") or 0.0)
            self.ovr[30] = self.out(result.get("empirical_value") or 0.0)
            self.ovr[31] = self.out(result.get("mean_value") or 0.0)
            self.ovi[4] = self.integer("_K")
            evnum = self.integer("_EVNUM")
            if evnum:
                self.ovi[7] = evnum % 10000 if evnum > 9999 else evnum
                self.ovi[6] = evnum // 10000 if evnum > 9999 else evnum
            alarm = result.get("alarm")
            if alarm:
                self.ovi[9] = int(alarm["code"])
        correction = answer.get("correction") or {}
        written = correction.get("after") is not None and correction.get("target") not in (None, MEASURE_ONLY)
        self.ovi[11] = 1 if written else 0

    def write(self) -> None:
        """The results into _OVR/_OVI (elements not set stay 0)."""
        v = self.ctx.variables
        for i in range(32):
            v.set("_OVR", float(self.ovr.get(i, 0.0)), (i,))
        for i in range(14):
            v.set("_OVI", int(self.ovi.get(i, 0)), (i,))


def _cycle_alarm_of(exc: HmiError) -> CycleAlarm:
    """The cycle alarm of a refusal of the HMI (access level, storage, correction out of range, ...)."""
    if exc.code == "guard":      # the start guard refused the path: nothing moved (issue 24 §1)
        code = int((exc.extra.get("alarm") or {}).get("code") or 0)
        return CycleAlarm(alarms.by_number(code) or alarms.START_GUARD_COLLISION, exc.message)
    definition = alarms.NC_WRITE_PROTECTED if exc.code in ("access_level", "unauthenticated") \
        else alarms.NC_VALUE_RANGE
    return CycleAlarm(definition, exc.message)


def _zo_name(knum: int, active: str, basic: list[str]) -> str:
    """The zero offset _KNUM (not 0) names: 1..4 G54..G57, 5..99 G505.., 1000 the last basic frame,
    1011..1026 BASIC_0.., 2000 the system frame, 9999 the active one (G500: the last basic frame)."""
    if 1 <= knum <= 4:
        return f"G{53 + knum}"
    if 5 <= knum <= 99:
        return f"G{500 + knum}"
    if knum == 1000 or knum == 9999 and active == "G500":
        if not basic:
            which = "_KNUM=1000" if knum == 1000 else "_KNUM=9999 with G500"
            raise CycleAlarm(alarms.BASIC_FRAME_MISSING, f"{which}: the channel has no basic frame")
        return basic[-1]
    if 1011 <= knum <= 1026:
        return f"BASIC_{knum - 1011}"
    if knum == 2000:
        return "BASIC_REF"
    if knum == 9999:
        return active
    raise CycleAlarm(alarms.ZO_NUMBER, f"_KNUM={knum}: not a zero offset of this control "
                     "(1..99 G54.., 1000, 1011..1026 basic frames, 2000 system frame, 9999 active)")


def _tool_knum(knum: int, correct_length: bool | None) -> tuple[int, str]:
    """(D number, "length" or "radius") of a tool-offset _KNUM (not 0), its digits checked."""
    d, kind, which = _tool_knum_digits(knum)
    if which == 1 or which == 0 and kind in (0, 1) and correct_length:
        return d, "length"
    if which == 4 or kind == 2:
        return d, "radius"
    raise CycleAlarm(alarms.KNUM_DIGIT4, f"_KNUM={knum}: the length in the measuring axis is L1 only "
                     "when measuring in the applicate")


def _tool_knum_digits(knum: int) -> tuple[int, int, int]:
    """(D number, digit 4, digit 6) of a tool-offset _KNUM, each digit checked (manual §2.3)."""
    if knum < 0 or knum > 9_999_999:
        raise CycleAlarm(alarms.KNUM_DIGIT7, f"_KNUM={knum}: not a tool offset code")
    d = knum % 1000
    kind, inverse, which, dl = digit(knum, 4), digit(knum, 5), digit(knum, 6), knum // 1_000_000
    if d == 0:
        raise CycleAlarm(alarms.D_NUMBER, f"_KNUM={knum}: D number 0")
    if d != 1:
        raise CycleAlarm(alarms.D_NUMBER_TOO_HIGH, f"_KNUM={knum}: D{d}: the tool table holds D1 only")
    if kind not in (0, 1, 2):
        raise CycleAlarm(alarms.KNUM_DIGIT4, f"_KNUM={knum}: 4th digit must be 0, 1 or 2")
    if inverse not in (0, 1):
        raise CycleAlarm(alarms.KNUM_DIGIT5, f"_KNUM={knum}: 5th digit must be 0 or 1")
    if inverse:
        raise CycleAlarm(alarms.KNUM_DIGIT5, f"_KNUM={knum}: the inverse correction (5th digit 1) is not "
                         "supported")
    if which not in (0, 1, 4) and which not in (2, 3):
        raise CycleAlarm(alarms.KNUM_DIGIT6, f"_KNUM={knum}: 6th digit must be 0..4")
    if which in (2, 3):
        raise CycleAlarm(alarms.KNUM_DIGIT6, f"_KNUM={knum}: L2/L3 are not in the tool table (L1 and R only)")
    if dl:
        raise CycleAlarm(alarms.KNUM_DIGIT7, f"_KNUM={knum}: setup/sum offsets and tool environments "
                         "(7th digit) are not supported")
    return d, kind, which


def run_cycle(ctx: CycleContext, host: CycleHost, number: int, body: Callable[[Call], None]) -> None:
    """Common frame of a cycle: clear the results, run ``body``, write _OVR/_OVI (also the alarm
    number in _OVI[9] when it alarms) and convert the alarm into one located at the call."""
    call = Call(ctx, host, number)
    call.ovi[2] = number
    try:
        missing = host.system_frame_missing()      # before anything moves (manual ch. 10: "all")
        if missing:
            raise CycleAlarm(alarms.SYSTEM_FRAME_MISSING, missing)
        call.ovi[3] = call.variant
        call.ovi[5] = call.integer("_PRNUM")
        body(call)
    except (CycleAlarm, MeasuringError) as exc:
        call.ovi[9] = exc.definition.number
        raise ctx.alarm(exc.definition, f"CYCLE{number}: {exc.message}") from None
    finally:                        # _OVR/_OVI written whatever happened
        call.write()
    warning = alarms.by_number(call.ovi.get(9, 0)) if call.ovi.get(9) else None
    if warning is not None and warning.warning:
        ctx.warn(warning, f"CYCLE{number}: {warning.text}", stop=bool(ctx.variables.get("_CBIT", (2,))))


def variant_error(call: Call, what: str) -> CycleAlarm:
    return CycleAlarm(alarms.WRONG_VARIANT, f"_MVAR={call.variant}: {what}")


def with_finisher(spec: TaskSpec, wrap: Callable) -> TaskSpec:
    """``spec`` with its finisher wrapped: ``wrap(original)(session, ctx, points)``."""
    return dataclasses.replace(spec, finish=wrap(spec.finish))


def with_planner(spec: TaskSpec, planner: Callable) -> TaskSpec:
    return dataclasses.replace(spec, planner=planner)


def angle_wrap(deg: float) -> float:
    return (deg + 180.0) % 360.0 - 180.0


def finite(x: float) -> bool:
    return math.isfinite(float(x))

"""The measuring cycles of the lathe as NC calls (manual ch. 6, turning.md §10.2): CYCLE982,
CYCLE973, CYCLE974, CYCLE994, each a thin wrapper over the lathe task of the JOG screens that
runs the same cycle call (engine.turning_plan: params -> the cycle call -> point program ->
evaluation). The wrapper reads the cycle's parameters, names the task's params after them, runs
the task through the JOG workflow (app.nc.cycles.base.Call.run) and copies the engine's
``_OVR``/``_OVI`` into the variables.

| cycle | _MVAR | lathe task |
|---|---|---|
| CYCLE982 | 0, 10, 100000, 100010 calibrate the tool probe | lathe.toolprobe.calibrate |
| CYCLE982 | x…x1 measure a tool (mill digits, reversal, incremental) | lathe.tool.measure |
| CYCLE982 | x…x2 measure automatically | lathe.tool.auto |
| CYCLE973 | xxx13 in a groove (_CALNUM), 0 on a surface (_SETVAL) | lathe.probe.groove / .surface |
| CYCLE974 | 0 tool offset / measure only, 100 zero offset, 1000 reversal | lathe.point |
| CYCLE994 | 1 with, 2 without protection zone (inside) | lathe.two_point |

Units: with DIAMON (the program's, ``ModalState.diamon``) the X values of the cycles
(``_SETVAL``, the bands, ``_SZO``) and their results are diameters (turning.md §0.3); the context
of the task gets the program's DIAMON, not the machine's default (app.services.nc).
The lathe cycles run on a lathe only: on the milling machine the NC refuses them by name
(app.nc.scope.LATHE_WORDS).
"""

from __future__ import annotations

from typing import Any

from app.nc.cycles.base import Call, CycleAlarm, CycleHost, run_cycle, variant_error
from app.workflow.context import MEASURE_ONLY
from app.workflow.tasks import TASKS
from engine import alarms
from engine.turning import MA_AXIS
from engine.turning_offsets import decode_tool_knum
from engine.turning_probe import decode_973
from engine.turning_tools import decode_982

LATHE_CYCLE_NAMES = ("CYCLE982", "CYCLE973", "CYCLE974", "CYCLE994")


# --- parameters -------------------------------------------------------------------------------------

def _axis(call: Call, allowed: tuple[str, ...] = ("Z", "X")) -> str:
    """_MA: 1 Z, 2 X (3 Y where the cycle has it)."""
    ma = call.integer("_MA")
    axis = MA_AXIS.get(ma)
    if axis not in allowed:
        names = ", ".join(f"{k} {v}" for k, v in MA_AXIS.items() if v in allowed)
        raise CycleAlarm(alarms.MEASURING_AXIS, f"_MA = {ma}: the measuring axis is {names}")
    return axis


def _direction(call: Call) -> str:
    """_MD: 0 positive, 1 negative."""
    md = call.integer("_MD")
    if md not in (0, 1):
        raise CycleAlarm(alarms.NC_VALUE_RANGE, f"_MD = {md}: the measuring direction is 0 (+) or 1 (−)")
    return "+" if md == 0 else "-"


def _common(call: Call) -> dict[str, Any]:
    """_PRNUM, _FA, _VMS, _NMSP as the lathe tasks name them."""
    return {"probe": call.probe_record(), "measuring_path": call.fa, "feed": call.real("_VMS"),
            "measurements": call.measurements()}


def _bands(call: Call) -> dict[str, Any]:
    """The tolerance object of CYCLE974/994 (design.md §9.3) from _TUL, _TLL, _TZL, ... (display units)."""
    return {"upper": call.real("_TUL"), "lower": call.real("_TLL"), "zero_range": call.real("_TZL"),
            "mean_range": call.real("_TMV"), "dim_difference": call.real("_TDIF"), "safe_area": call.real("_TSA"),
            "k": call.integer("_K"), "evnum": call.integer("_EVNUM"), "keep_mean": call.bit("_CHBIT", 4)}


def _tool_target(call: Call) -> dict[str, Any] | str:
    """_KNUM (7 digits, manual §2.3) with _TNUM as the task's tool target; 0: measure only."""
    target = decode_tool_knum(call.integer("_KNUM"), tnum=call.integer("_TNUM"), geometry=call.bit("_CHBIT", 6))
    if target is None:
        return MEASURE_ONLY
    if target.dl or target.tenv:
        raise CycleAlarm(alarms.KNUM_DIGIT7, f"_KNUM={call.integer('_KNUM')}: setup/sum offsets and tool "
                         "environments (7th digit) are not supported")
    call.ovi[0], call.ovi[8] = target.d, target.t
    return {"tool": target.t, "edge": target.d, "correct": target.quantity, "inverse": target.inverse,
            "mode": "geometry" if target.geometry else "wear"}


# --- running a lathe task --------------------------------------------------------------------------

def _run(call: Call, task: str, params: dict[str, Any]) -> dict:
    """The lathe task with the program's DIAMON and plane G18; its _OVR/_OVI into the call."""
    env = call.measuring(plane="G18", diamon=call.ctx.modal.diamon)
    target = params.get("target")
    answer = call.run(env, TASKS[task], params, target if target is not None else MEASURE_ONLY)
    result = answer.get("result") or {}
    for i, value in enumerate(result.get("ovr") or []):
        call.ovr[i] = float(value)
    for i, value in enumerate(result.get("ovi") or []):
        if int(value):
            call.ovi[i] = int(value)
    alarm = result.get("alarm")
    if alarm:
        call.ovi[9] = int(alarm["code"])
    correction = answer.get("correction") or {}
    call.ovi[11] = 1 if correction.get("after") is not None and correction.get("target") not in (None, MEASURE_ONLY) \
        else 0
    return answer


# --- CYCLE982 (manual §6.2, §6.3) ---------------------------------------------------------------------

def cycle982(call: Call) -> None:
    v = call.variant
    variant = decode_982(v)
    params: dict[str, Any] = {**_common(call), "reference": "workpiece" if variant.workpiece else "machine"}
    if variant.kind != "auto":
        params["axis"] = _axis(call)
        params["incremental"] = variant.incremental
        if variant.incremental:
            params["direction"] = _direction(call)
    if variant.kind == "calibrate":
        params["tolerance"] = {"zero_range": call.real("_TZL"), "safe_area": call.real("_TSA")}
        _run(call, "lathe.toolprobe.calibrate", params)
        return
    if variant.kind == "auto" and variant.d4:
        raise variant_error(call, "the automatic measurement of mills (_MVAR=xx3xx2/xx4xx2) is not supported: "
                                  "measure L and R with _MVAR=x2xx1")
    params.update({"compensation": "wear" if call.bit("_CHBIT", 3) else "geometry",
                   "quantity": ("length", "radius", "length_radius")[variant.d4] if variant.kind == "measure"
                   else "length",
                   "reversal": variant.reversal, "position": "radial" if variant.radial else "axial",
                   "start_angle": call.real("_STA1"), "correction_angle": call.real("_CORA"),
                   "tolerance": {"zero_range": call.real("_TZL"), "dim_difference": call.real("_TDIF"),
                                 "safe_area": call.real("_TSA"), "evnum": call.integer("_EVNUM")}})
    _run(call, "lathe.tool.measure" if variant.kind == "measure" else "lathe.tool.auto", params)


# --- CYCLE973 (manual §6.4) -------------------------------------------------------------------------

def cycle973(call: Call) -> None:
    variant = decode_973(call.variant)
    tolerance = {"zero_range": call.real("_TZL"), "safe_area": call.real("_TSA")}
    if variant.surface:
        params = {**_common(call), "axis": _axis(call, ("Z", "X", "Y")), "direction": _direction(call),
                  "setpoint": call.real("_SETVAL"), "tolerance": tolerance}
        _run(call, "lathe.probe.surface", params)
        return
    calnum = call.integer("_CALNUM")
    if calnum < 1:
        raise CycleAlarm(alarms.NC_VALUE_RANGE, f"_CALNUM = {calnum}: the reference groove is 1 or higher")
    params = {**_common(call), "groove": {"number": calnum}, "axis": _axis(call),
              "direction": "both" if variant.both else _direction(call), "skew": variant.skew,
              "ball_diameter": variant.ball, "tolerance": tolerance}
    _run(call, "lathe.probe.groove", params)


# --- CYCLE974 (manual §6.5) -------------------------------------------------------------------------

def _measure_only_results(call: Call, answer: dict) -> None:
    """_OVR of a measurement without correction (_KNUM=0): setpoint, actual, difference (manual §6.5)."""
    result = answer.get("result") or {}
    if call.ovr or "actual" not in result:
        return
    call.ovr.update({0: float(result.get("setpoint") or 0.0), 4: float(result["actual"]),
                     16: float(result.get("difference") or 0.0), 27: call.real("_TZL"), 28: call.real("_TSA"),
                     29: call.real("_TDIF"), 30: float(result.get("empirical_value") or 0.0),
                     31: float(result.get("mean_value") or 0.0)})


def cycle974(call: Call) -> None:
    v = call.variant
    if v not in (0, 100, 1000):
        raise variant_error(call, "CYCLE974 measures 0 (tool offset or measure only), 100 (zero offset), "
                                  "1000 (with reversal)")
    params: dict[str, Any] = {**_common(call), "axis": _axis(call, ("Z", "X", "Y")), "setpoint": call.real("_SETVAL"),
                              "reversal": v == 1000, "start_angle": call.real("_STA1") % 360.0,
                              "tolerance": _bands(call)}
    if v == 100:
        params["target"] = call.zo_target(call.measuring(plane="G18").setup())
        params["tolerance"] = {k: params["tolerance"][k] for k in ("zero_range", "safe_area", "evnum")}
    else:
        params["target"] = _tool_target(call)
    answer = _run(call, "lathe.point", params)
    _measure_only_results(call, answer)


# --- CYCLE994 (manual §6.6) -------------------------------------------------------------------------

def cycle994(call: Call) -> None:
    v = call.variant
    if v not in (1, 2):
        raise variant_error(call, "CYCLE994 measures 1 (inside via the protection zone) or 2 (direct)")
    axis = _axis(call, ("Z", "X", "Y"))
    setval = call.real("_SETVAL")
    here = call.position()                      # the ball centre (NC reference) in the WCS, X a radius
    index = {"X": 0, "Y": 1, "Z": 2}[axis]
    half = setval / 2.0 if axis == "X" and call.ctx.modal.diamon else setval
    inside = abs(float(here[index])) < abs(half)
    zone = {"Z": call.real("_SZA"), "X": call.real("_SZO")}
    params: dict[str, Any] = {**_common(call), "axis": axis, "setpoint": setval, "inside": inside,
                              "use_ball_diameter": call.bit("_CHBIT", 7), "tolerance": _bands(call),
                              "target": _tool_target(call),
                              "zone": zone if (not inside or v == 1) else None}
    answer = _run(call, "lathe.two_point", params)
    _measure_only_results(call, answer)


def handlers(host: CycleHost) -> dict:
    return {f"CYCLE{number}": (lambda ctx, number=number, body=body: run_cycle(ctx, host, number, body))
            for number, body in ((982, cycle982), (973, cycle973), (974, cycle974), (994, cycle994))}

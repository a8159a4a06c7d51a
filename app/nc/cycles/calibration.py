"""CYCLE976 (calibrate the workpiece probe, measuring-math §7) and CYCLE971 (tool probe and tool
measuring, measuring-math §14) as NC calls on the JOG tasks probe.radius / probe.length and
toolprobe.calibrate / tool.length / tool.diameter.

CYCLE976: 4-direction bore variants (units digit 1 known or 8 unknown centre, 4th digit 0) run
the JOG ring calibration (centre search, passes at SPOS 180° and 0°: skew, trigger values and the
effective ball diameter are always determined); 10000 calibrates the length on a surface at
``_SETVAL``; 0 calibrates the trigger value of one direction (``_MA``, ``_MD``) on a surface at
``_SETVAL`` (manual §5.3.3, ``%_N_KALIBRIEREN_IN_Z_MPF``). CYCLE971: 0 calibrates the tool probe (``_MA`` 3: length only, else all
directions), 1 and 2 measure the length (``_MA`` 3) or the radius (``_MA`` 1/2) of the tool in
the spindle (stationary or rotating as the JOG task decides it from the tool and probe sizes),
``_CHBIT[3]`` 0 into the geometry, 1 into the wear; 100000 is the automatic calibration.
"""

from __future__ import annotations

import dataclasses

from app.nc.cycles.base import Call, CycleAlarm, digit, run_cycle, variant_error
from app.workflow import finish_probe
from app.workflow.tasks import TASKS, TaskSpec
from engine import alarms
from engine.plan_workpiece import bore_calibration_program, surface_program
from engine.planes import Plane
from engine.tasks import EngineTask, Family

TRIGGER_SLOTS = {"-1": 8, "+1": 10, "-2": 12, "+2": 14, "-3": 16, "+3": 18}


def _trigger_results(call: Call, new: dict, old: dict) -> None:
    """_OVR[8..19]: trigger values actual / difference per direction (−a, +a, −o, +o, −p, +p)."""
    plane = call.plane
    for i, axis in enumerate(plane.axes, start=1):
        for sign in ("-", "+"):
            key = f"{axis}{sign}"
            if key in new:
                slot = TRIGGER_SLOTS[f"{sign}{i}"]
                call.ovr[slot] = call.out(new[key])
                call.ovr[slot + 1] = call.out(new[key] - float(old.get(key, new[key])))


def _surface_params(params: dict, plane: Plane) -> dict:
    """The cycle builds these itself (never operator input): axis, direction, surface, _TSA."""
    return {k: params[k] for k in ("axis", "direction", "setpoint", "safe_area") if k in params}


def _surface_program(params, n, start, ctx, label):
    d = (1.0 if params["direction"] == "+" else -1.0) * ctx.plane.unit(params["axis"])
    return surface_program(d, float(params["setpoint"]), start, ctx, label,
                           stay=params["axis"] == ctx.plane.infeed)


# CYCLE976 _MVAR=0 (manual §5.3.3): a task of the cycle only; the JOG screens calibrate length and ring
SURFACE_CALIBRATION = dataclasses.replace(
    TASKS["probe.length"], engine=EngineTask("probe.surface", Family.PROBE, 1, _surface_params, _surface_program),
    finish=finish_probe.finish_probe_surface, validator=None, planner=None)


def _bore_params(params: dict, plane: Plane) -> dict:
    """The cycle builds these itself from _MVAR, _MA, _MD, _STA1, _SETVAL (never operator input)."""
    keys = ("diameter", "keys", "angle", "known_centre", "skew", "ball", "safe_area")
    return {k: params[k] for k in keys if k in params}


def _bore_program(params, n, start, ctx, label):
    return bore_calibration_program(params, start, ctx, label)


# CYCLE976 in a bore along 1, 2 or 4 directions, axis-parallel or at _STA1 (manual §5.3.1/§5.3.2)
BORE_CALIBRATION = dataclasses.replace(
    TASKS["probe.radius"], engine=EngineTask("probe.bore", Family.PROBE, 1, _bore_params, _bore_program),
    finish=finish_probe.finish_probe_bore, validator=None, planner=None, circle_points=False)


def _bore_keys(call: Call, directions: int) -> tuple[str, ...]:
    """The directions of xx0x0x / xx1x0x (_MA, _MD) / xx2x0x (_MA), manual §5.3.1."""
    if directions == 0:
        return ("+1", "-1", "+2", "-2")
    ma = call.integer("_MA")
    if ma not in (1, 2):
        raise CycleAlarm(alarms.MEASURING_AXIS, f"_MVAR={call.variant}: _MA = {ma}: the axis of 1 or 2 "
                                                "directions is 1 (abscissa) or 2 (ordinate) (manual §5.3.1)")
    if directions == 2:
        return (f"+{ma}", f"-{ma}")
    md = call.integer("_MD")
    if md not in (0, 1):
        raise CycleAlarm(alarms.NC_VALUE_RANGE, f"_MVAR={call.variant}: _MD = {md}: 0 positive, 1 negative "
                                                "direction (manual §5.3.1)")
    return (f"{'+' if md == 0 else '-'}{ma}",)


def _bore_variant(call: Call, setval: float) -> tuple[TaskSpec, dict] | None:
    """The bore variants xx0x01 / xx0x08 (digits: 3 ball, 4 directions, 5 skew, 6 angle, manual
    §5.3 table); None for the 4-direction, axis-parallel one with ball and skew (the JOG ring)."""
    v = call.variant
    ball, directions, skew, angled = digit(v, 3), digit(v, 4), digit(v, 5), digit(v, 6)
    if v >= 1_000_000 or digit(v, 2) != 0 or ball > 1 or directions > 2 or skew > 1 or angled > 1:
        raise variant_error(call, "the bore variants are xx0x01 and xx0x08: digit 3 ball 0/1, digit 4 directions "
                                  "0/1/2, digit 5 skew 0/1, digit 6 axis-parallel 0 / at the angle _STA1 1 "
                                  "(manual §5.3)")
    if digit(v, 1) == 8 and directions:
        raise variant_error(call, "an unknown centre (xx0x08) is always calibrated in 4 directions (manual §5.3.2)")
    if directions == 1 and (ball or skew):
        raise variant_error(call, "one direction (xx1x0x) determines neither the skew nor the ball (manual §5.3)")
    if not setval > 0.0:
        raise CycleAlarm(alarms.NC_VALUE_RANGE, f"_SETVAL = {setval:g}: the ring diameter must be > 0 (manual §5.3.1)")
    if (ball, directions, skew, angled) == (1, 0, 1, 0):
        return None
    keys = _bore_keys(call, directions)
    angle = call.real("_STA1") if angled else 0.0
    return BORE_CALIBRATION, {"diameter": setval, "keys": list(keys), "angle": angle,
                              "known_centre": digit(v, 1) == 1, "skew": bool(skew), "ball": bool(ball),
                              "safe_area": call.length("_TSA")}


def _surface_variant(call: Call, setval: float) -> tuple[TaskSpec, dict]:
    ma, md = call.integer("_MA"), call.integer("_MD")
    if ma not in (1, 2, 3):
        raise CycleAlarm(alarms.MEASURING_AXIS, f"_MVAR=0: _MA = {ma}: the measuring axis is 1, 2 or 3")
    if md not in (0, 1):
        raise CycleAlarm(alarms.NC_VALUE_RANGE, f"_MVAR=0: _MD = {md}: 0 positive, 1 negative direction")
    axis = call.plane.axes[ma - 1]
    return SURFACE_CALIBRATION, {"axis": axis, "direction": "+" if md == 0 else "-", "setpoint": setval,
                                 "safe_area": call.length("_TSA")}


def _task976(call: Call, setval: float) -> tuple[TaskSpec, str, dict[str, object]]:
    """(task spec, task name, the task's JSON params) of the _MVAR variant."""
    v = call.variant
    if v == 0:
        spec, params = _surface_variant(call, setval)
        return spec, spec.name, params
    if v == 10000:
        if call.integer("_MA") not in (0, 3):
            raise CycleAlarm(alarms.MEASURING_AXIS, "_MVAR=10000 calibrates the length in the applicate: _MA=3")
        return TASKS["probe.length"], "probe.length", {"setpoint": {call.plane.infeed: setval}}
    if digit(v, 1) in (1, 8):
        bore = _bore_variant(call, setval)
        if bore is not None:
            return bore[0], "probe.bore", bore[1]
        return TASKS["probe.radius"], "probe.radius", {"diameter": setval}
    raise variant_error(call, "supported: 0 (one direction on a surface), 10000 (length on a surface) and "
                              "the bore variants xx0x01 (known centre) and xx0x08 (unknown centre) (manual §5.3)")


def _results976(call: Call, task: str, result: dict, old) -> None:
    """_OVR of a probe calibration: trigger values, effective diameter, skew, centre, length."""
    probe = result.get("probe") or {}
    new_trigger = {k: float(x) for k, x in (probe.get("trigger") or {}).items()}
    _trigger_results(call, new_trigger, dict(old.trigger))
    effective = float(probe.get("effective_diameter") or 0.0)
    call.ovr[4] = call.out(effective)
    call.ovr[5] = call.out(effective - float(old.effective_diameter or 0.0)) if effective else 0.0
    skew = probe.get("skew") or {}
    call.ovr[20] = call.out(float(skew.get("X", 0.0)))
    call.ovr[21] = call.out(float(skew.get("Y", 0.0)))
    centre = result.get("center")
    if isinstance(centre, dict):
        plane = call.plane
        call.ovr[6] = call.out(float(centre.get(plane.first, 0.0)))
        call.ovr[7] = call.out(float(centre.get(plane.second, 0.0)))
    if task == "probe.length":
        call.ovr[8] = call.out(float(result.get("length", 0.0)))
        call.ovr[9] = call.out(float(result.get("difference", 0.0)))


def cycle976(call: Call) -> None:
    env = call.measuring()
    before = env.context()
    if before.probe is None:
        raise CycleAlarm(alarms.PROBE_TYPE, "the tool in the spindle is not a 3D probe (type 710): load the probe")
    old = before.probe
    setval = call.length("_SETVAL")
    spec, task, params = _task976(call, setval)
    params["measurements"] = call.measurements()
    answer = call.run(env, spec, params, "measure_only")
    _results976(call, task, answer.get("result") or {}, old)
    call.ovr[24] = float((answer.get("result") or {}).get("angle") or 0.0)    # _STA1 of a bore variant
    call.ovr[27] = call.out(call.length("_TZL"))
    call.ovr[28] = call.out(call.length("_TSA"))


def _calibrate971(call: Call, env, ma: int, v: int) -> None:
    """_MVAR 0 / 100000: calibrate the tool probe (length, or length and diameter). The automatic
    calibration (100000) calibrates every direction and needs no ``_MA`` (manual §5.2.3,
    ``%_N_AUTO_KALIBRIEREN_MPF`` sets none)."""
    if not (v == 100000 and ma == 0) and ma not in (1, 2, 3, 102, 201):
        raise CycleAlarm(alarms.MEASURING_AXIS, f"_MA = {ma}: 1, 2, 3, 102 or 201")
    mode = "length" if ma == 3 and v == 0 else "length_diameter"
    old = dict((env.context().extra.get("tool_probe") or {}).get("trigger") or {})
    answer = call.run(env, TASKS["toolprobe.calibrate"], {"mode": mode}, "measure_only")
    record = (answer.get("result") or {}).get("tool_probe") or {}
    new = {k: float(x) for k, x in (record.get("trigger") or {}).items()}
    _trigger_results(call, new, old)
    call.ovr[27] = call.out(call.length("_TZL"))
    call.ovr[28] = call.out(call.length("_TSA"))


def _measure971(call: Call, env, ma: int) -> None:
    """_MVAR 1 / 2: measure the tool's length or radius (stationary / rotating)."""
    if ma not in (1, 2, 3, 103, 203):
        raise CycleAlarm(alarms.MEASURING_AXIS, f"_MA = {ma}: 1/2 radius, 3/103/203 length")
    offset_v = call.length("_ID")
    if offset_v < 0.0:
        raise CycleAlarm(alarms.NC_VALUE_RANGE, f"_ID = {offset_v:g}: the offset must be >= 0")
    task = "tool.length" if ma in (3, 103, 203) else "tool.diameter"
    compensation = "wear" if call.bit("_CHBIT", 3) else "geometry"
    answer = call.run(env, TASKS[task], {"offset_v": offset_v, "compensation": compensation}, "measure_only")
    result = answer.get("result") or {}
    before = (answer.get("correction") or {}).get("before") or {}
    tool = result.get("tool") or {}
    wear_before = before.get("wear") or {}
    if task == "tool.length":
        value = float(result["length"])
        call.ovr[8] = call.out(value)
        call.ovr[9] = call.out(value - float(before.get("length", 0.0)) - float(wear_before.get("length", 0.0)))
    else:
        value = float(result["radius"])
        call.ovr[10] = call.out(value)
        call.ovr[11] = call.out(value - float(before.get("radius", 0.0)) - float(wear_before.get("radius", 0.0)))
    call.ovr[27] = call.out(call.length("_TZL"))
    call.ovr[28] = call.out(call.length("_TSA"))
    call.ovr[29] = call.out(call.length("_TDIF"))
    call.ovi[0] = 1
    call.ovi[8] = int(tool.get("t") or 0)


def cycle971(call: Call) -> None:
    v = call.variant
    ma = call.integer("_MA")
    env = call.measuring()
    if v in (0, 100000):
        _calibrate971(call, env, ma, v)
        return
    if v in (10, 11, 12, 10000, 10010, 100010):
        raise variant_error(call, "workpiece-related (_TPW) and incremental calibrations are not supported")
    if v not in (1, 2):
        raise variant_error(call, "CYCLE971: 0 / 100000 calibrate, 1 (stationary) / 2 (rotating) measure")
    _measure971(call, env, ma)


def handlers(host) -> dict:
    return {"CYCLE976": lambda ctx: run_cycle(ctx, host, 976, cycle976),
            "CYCLE971": lambda ctx: run_cycle(ctx, host, 971, cycle971)}

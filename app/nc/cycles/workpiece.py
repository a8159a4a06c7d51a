"""Workpiece measuring cycles as NC calls: CYCLE977, CYCLE978, CYCLE979, CYCLE998, CYCLE961
(measuring-math §8–measuring-math §12), each on the JOG task that measures the same feature.

| cycle | variants | JOG task (evaluation, correction) |
|---|---|---|
| CYCLE977 | 1/101 bore, 2/102 shaft, 3/103 slot, 4/104 web, 5/105 inner, 6/106 outer rectangle | hole.1, spigot.1, edge.distance (+, −), pocket.rect, spigot.rect |
| CYCLE978 | 0 surface + tool offset, 100 surface + ZO | edge.set |
| CYCLE979 | 1/101 bore, 2/102 shaft at an angle (3 or 4 points; ``_NPTS`` 3..36), 3/103 slot, 4/104 web at ``_STA1`` | hole.1 / spigot.1 / edge.distance (along the line, ``line_angle``) with the CYCLE979 plans (engine.cycles) |
| CYCLE998 | 105, 100105 one angle | edge.align |
| CYCLE961 | 105/106 rectangle corner, 107/108 any corner, 117/118 from 4 given points | corner.right / corner.any with the cycle's points and directions |

Hundreds digit 0: tool offset by ``_KNUM`` (or measure only for ``_KNUM=0``); 1: ZO ``_KNUM``.
``_NPTS`` > 0 (this HMI's extension, not the manual's): CYCLE977 bore/shaft and CYCLE979 fit their
circle to that many touches, as the JSON API's ``params.points`` (design.md §10.2).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from app.nc.cycles.base import (
    Call,
    CycleAlarm,
    angle_wrap,
    run_cycle,
    variant_error,
    with_finisher,
    with_planner,
)
from app.workflow.tasks import TASKS
from engine import alarms
from engine.compensation import effective_radius, trigger_radius
from engine.cycles import angle_circle_program, angle_line_program
from engine.params import MAX_CIRCLE_POINTS, MIN_CIRCLE_POINTS
from engine.plan_workpiece import edge_program
from engine.tasks import evaluate
from engine.types import MeasuringError

# --- helpers ---------------------------------------------------------------------------------------


def _probe(env):
    ctx = env.context()
    if ctx.probe is None:
        raise CycleAlarm(alarms.PROBE_TYPE, "the tool in the spindle is not a 3D probe (type 710): load the probe")
    return ctx.probe


def _position_feed(env) -> float:
    return float(env.setup().settings.position_feed)


def circle_points(call: Call) -> int | None:
    """``_NPTS``: the touches on a circle where a cycle fits one (this HMI's extension, as the
    JSON API's ``params.points``, design.md §10.2), 3..36; 0: the manual's own number."""
    n = call.integer("_NPTS")
    if n == 0:
        return None
    if not MIN_CIRCLE_POINTS <= n <= MAX_CIRCLE_POINTS:
        raise CycleAlarm(alarms.NC_VALUE_RANGE, f"_NPTS = {n}: the touches on a circle are "
                         f"{MIN_CIRCLE_POINTS}..{MAX_CIRCLE_POINTS} (0: as the manual)")
    return n


def _with_points(call: Call, kind: int, params: dict) -> None:
    """CYCLE977 bore and shaft (``kind`` 1, 2) fit their circle to ``_NPTS`` touches; the other
    variants fit no circle and refuse it."""
    n = circle_points(call)
    if n is None:
        return
    if kind not in (1, 2):
        raise CycleAlarm(alarms.NC_VALUE_RANGE, f"_NPTS = {n}: only bore and shaft (_MVAR 1, 2) fit a circle; "
                         "set _NPTS=0 for slot, web and rectangles")
    params["points"] = n


def _ao_unit(plane, theta_deg: float) -> np.ndarray:
    t = math.radians(theta_deg)
    return math.cos(t) * plane.unit(plane.first) + math.sin(t) * plane.unit(plane.second)


def _paraxial(plane, travel: np.ndarray) -> np.ndarray:
    """The plane axis with the larger component of ``travel``, along its sign (CYCLE961 [I])."""
    ta, to = float(travel @ plane.unit(plane.first)), float(travel @ plane.unit(plane.second))
    if abs(ta) >= abs(to):
        return math.copysign(1.0, ta) * plane.unit(plane.first)
    return math.copysign(1.0, to) * plane.unit(plane.second)


def _zo_safe_area(call: Call, differences) -> None:
    """ZO variants: only _TSA is checked (measuring-math §3.5) -> 61303, nothing written."""
    tsa = abs(call.length("_TSA"))
    worst = max((abs(float(d)) for d in differences), default=0.0)
    if worst > tsa:
        raise MeasuringError(alarms.SAFE_AREA, f"difference {worst:.4f} mm beyond the safe area _TSA {tsa:g} mm: "
                             "no correction")


def _check_safe_area(call: Call, differences_of):
    """A finisher wrapper that refuses the write when a difference exceeds _TSA (ZO variants)."""
    def wrap(original):
        def finish(session, ctx, points):
            answer, commit = original(session, ctx, points)
            _zo_safe_area(call, differences_of(answer.get("result") or {}))
            return answer, commit
        return finish
    return wrap


def _tolerance_results(call: Call, answer: dict, setval: float, tool: bool, slots=(0, 8, 12)) -> None:
    """_OVR[0] setpoint, [8] upper, [12] lower tolerance (symmetrised for tool offsets, measuring-math §3.2)."""
    tul, tll = call.length("_TUL"), call.length("_TLL")
    if tool:
        setval, tul, tll = setval + (tul + tll) / 2.0, (tul - tll) / 2.0, -(tul - tll) / 2.0
    for slot, value in zip(slots, (setval, tul, tll), strict=True):
        if slot is not None:
            call.ovr[slot] = call.out(value)


# --- CYCLE977 (measuring-math §8) -----------------------------------------------------------------------

_977_TASKS = {1: "hole.1", 2: "spigot.1", 3: "edge.distance", 4: "edge.distance", 5: "pocket.rect",
              6: "spigot.rect"}


def _variant977(call: Call) -> tuple[int, int]:
    """(kind 1..6, ZO digit) of _MVAR; the protection-zone variants are refused."""
    v = call.variant
    kind, zo, zone = v % 10, digit_at(v, 3), digit_at(v, 4)
    if v not in {k + 100 * z for k in range(1, 7) for z in (0, 1)} | {k + 100 * z + 1000 for k in range(1, 7)
                                                                       for z in (0, 1)}:
        raise variant_error(call, "CYCLE977 measures 1 bore, 2 shaft, 3 slot, 4 web, 5/6 rectangles "
                                  "(+100 ZO, +1000 protection zone)")
    if zone:
        raise variant_error(call, "protection zone variants (1xxx) are not supported")
    return kind, zo


def _params977(call: Call, env, kind: int, params: dict, start: np.ndarray, setval: float):
    """The task's params of ``kind`` (filled into ``params``): (the tolerances' setpoint, the move
    before each point or None)."""
    if kind in (1, 2, 3, 4) and not setval > 0.0:
        raise CycleAlarm(alarms.NC_VALUE_RANGE, f"_SETVAL = {setval:g}: the diameter/width must be > 0")
    infeed = 0.0
    if kind in (2, 4, 6):
        infeed = -call.length("_ID")
        if not infeed > 0.0:
            raise CycleAlarm(alarms.NC_VALUE_RANGE, f"_ID = {call.real('_ID'):g}: shaft, web and outer rectangle "
                             "need the infeed _ID < 0 (down from the start height)")
    if kind in (1, 2):
        params["diameter"] = setval
        if kind == 2:
            params["infeed"] = infeed
        return setval, None
    if kind in (3, 4):
        return setval, _slot_or_web977(call, env, kind, params, start, setval, infeed)
    length, width = call.length("_SETV", (0,)), call.length("_SETV", (1,))
    if not (length > 0.0 and width > 0.0):
        raise CycleAlarm(alarms.NC_VALUE_RANGE, "_SETV[0], _SETV[1]: the rectangle's lengths must be > 0")
    params.update({"length": length, "width": width})
    if kind == 6:
        params["infeed"] = infeed
    return 0.0, None            # the JOG strategy compares the mean length difference (measuring-math §8.3 [I])


def _slot_or_web977(call: Call, env, kind: int, params: dict, start: np.ndarray, setval: float, infeed: float):
    """Slot (3) or web (4) along _MA: its params, and the move before each of the two points."""
    plane = call.plane
    ma = call.integer("_MA")
    if ma not in (1, 2):
        raise CycleAlarm(alarms.MEASURING_AXIS, f"_MA = {ma}: slot and web are measured along the abscissa (1) "
                         "or the ordinate (2)")
    axis = plane.axes[ma - 1]
    u = plane.unit(axis)
    params.update({"axis": axis, "direction": "+", "direction_p2": "-",
                   "setpoint": {axis: float(start @ u)}})
    probe = _probe(env)
    fa, feed = call.fa, _position_feed(env)
    if kind == 3:
        def before_slot_point(n, u=u):
            d = u if n == 1 else -u
            reach = max(0.0, setval / 2.0 - trigger_radius(probe, d, plane) - fa)
            call.move(start + reach * d, feed)
        return before_slot_point
    low = start - infeed * plane.infeed_unit
    side = setval / 2.0 + effective_radius(probe) + fa

    def before_web_point(n, u=u):
        here = call.position()
        call.move(here + (float((start - here) @ plane.infeed_unit)) * plane.infeed_unit, feed)
        over = start + (-side if n == 1 else side) * u
        call.move(over, feed)
        call.move(over + (low - start), feed)
    return before_web_point


def _results977(call: Call, answer: dict, kind: int, params: dict, s_ao: tuple[float, float], setval: float,
                tool: bool) -> None:
    """_OVR of CYCLE977 (measuring-math §8): setpoints, actual values, differences, tolerances."""
    a, o = call.plane.first, call.plane.second
    sa, so = s_ao
    result = answer.get("result") or {}
    centre = result.get("center") or {}
    if kind in (5, 6):
        la, lo = float(result["length"]), float(result["width"])
        lengths = (params["length"], params["width"])
        for slot, value in ((0, lengths[0]), (1, lengths[1]), (2, sa), (3, so), (4, la), (5, lo),
                            (6, centre.get(a, sa)), (7, centre.get(o, so)),
                            (16, la - lengths[0]), (17, lo - lengths[1]),
                            (18, centre.get(a, sa) - sa), (19, centre.get(o, so) - so)):
            call.ovr[slot] = call.out(value)
        tul, tll = call.length("_TUL"), call.length("_TLL")
        if tool:
            tul, tll = (tul - tll) / 2.0, -(tul - tll) / 2.0
        for slot, value in ((8, tul), (9, tul), (12, tll), (13, tll)):
            call.ovr[slot] = call.out(value)
        return
    size = float(result["distance"] if kind in (3, 4) else result["diameter"])
    ca, co = centre.get(a, sa), centre.get(o, so)
    _tolerance_results(call, answer, setval, tool)
    for slot, value in ((1, sa), (2, so), (4, size), (5, ca), (6, co), (16, size - setval),
                        (17, ca - sa), (18, co - so)):
        call.ovr[slot] = call.out(value)


def cycle977(call: Call) -> None:
    kind, zo = _variant977(call)
    env = call.measuring()
    setup = env.setup()
    plane = call.plane
    a, o = plane.first, plane.second
    start = call.position()
    sa, so, sp = (float(x) for x in plane.to_aop(start))
    setval = call.length("_SETVAL")
    target = call.zo_target(setup) if zo else call.tool_target()
    tool = isinstance(target, dict)
    spec = TASKS[_977_TASKS[kind]]
    params: dict = {"setpoint": {a: sa, o: so}, "measurements": call.measurements()}
    _with_points(call, kind, params)
    tol_setpoint, before_point = _params977(call, env, kind, params, start, setval)
    if tool:
        params["tolerance"] = call.tolerance(tol_setpoint)
    elif zo:
        def differences(result):
            centre = result.get("center") or {}
            return [centre.get(k, s) - s for k, s in params["setpoint"].items()]
        spec = with_finisher(spec, _check_safe_area(call, differences))
    answer = call.run(env, spec, params, target, before_point=before_point)
    if kind == 4:                                  # web: back up over the centre
        here = call.position()
        call.move(here + float((start - here) @ plane.infeed_unit) * plane.infeed_unit, _position_feed(env))
        call.move(start, _position_feed(env))
    _results977(call, answer, kind, params, (sa, so), setval, tool)
    call.common_results(answer)


def digit_at(value: int, n: int) -> int:
    return (abs(int(value)) // 10 ** (n - 1)) % 10


# --- CYCLE978 (measuring-math §9) -----------------------------------------------------------------------

def _approach_on_axis(call: Call, env, start: np.ndarray, axis: str, surface: float, d: np.ndarray,
                      probe) -> np.ndarray:
    """Position _FA in front of the expected switching point on ``axis`` (measuring-math §1.1)."""
    plane = call.plane
    u = plane.unit(axis)
    expected = surface - float(d @ u) * trigger_radius(probe, d, plane)
    p0 = start + (expected - call.fa * float(d @ u) - float(start @ u)) * u
    call.move(p0, _position_feed(env))
    return p0


def cycle978(call: Call) -> None:
    v = call.variant
    if v in (1000, 1100):
        raise variant_error(call, "the differential measurement (1000/1100) is not supported")
    if v not in (0, 100):
        raise variant_error(call, "CYCLE978 measures 0 (tool offset) or 100 (ZO)")
    ma = call.integer("_MA")
    if ma not in (1, 2, 3):
        raise CycleAlarm(alarms.MEASURING_AXIS, f"_MA = {ma}: the measuring axis is 1, 2 or 3")
    env = call.measuring()
    setup = env.setup()
    plane = call.plane
    axis = plane.axes[ma - 1]
    u = plane.unit(axis)
    start = call.position()
    setval = call.length("_SETVAL")
    sigma = 1.0 if float(start @ u) < setval else -1.0
    target = call.zo_target(setup) if v == 100 else call.tool_target(correct_length=axis == plane.infeed)
    tool = isinstance(target, dict)
    probe = _probe(env)
    _approach_on_axis(call, env, start, axis, setval, sigma * u, probe)
    params = {"axis": axis, "direction": "+" if sigma > 0 else "-", "setpoint": {axis: setval},
              "measurements": call.measurements()}
    spec = TASKS["edge.set"]
    if tool:
        params["tolerance"] = call.tolerance(setval)
    elif v == 100:
        spec = with_finisher(spec, _check_safe_area(call, lambda r: [r["position"][axis] - setval]))
    answer = call.run(env, spec, params, target)
    actual = float((answer.get("result") or {})["position"][axis])
    _tolerance_results(call, answer, setval, tool)
    aop = plane.to_aop(start)
    aop[ma - 1] = setval
    for slot, value in ((1, aop[0]), (2, aop[1]), (3, aop[2]), (4, actual), (16, actual - setval)):
        call.ovr[slot] = call.out(value)
    call.common_results(answer)


# --- CYCLE979 (measuring-math §10) ---------------------------------------------------------------------

def _points_979(call: Call) -> int:
    """``_NPTS`` touches, else the manual's: ``_PRNUM`` 4th digit 0 = 3, 1 = 4 points."""
    return circle_points(call) or (4 if digit_at(call.integer("_PRNUM"), 4) == 1 else 3)


def _setval979(call: Call) -> float:
    setval = call.length("_SETVAL")
    if not setval > 0.0:
        raise CycleAlarm(alarms.NC_VALUE_RANGE, f"_SETVAL = {setval:g}: the diameter/width must be > 0")
    return setval


def _sta1_979(call: Call) -> float:
    """_STA1, the start angle: −360..360° (manual §5.6 parameters)."""
    sta1 = call.real("_STA1")
    if not -360.0 <= sta1 <= 360.0:
        raise CycleAlarm(alarms.NC_VALUE_RANGE, f"_STA1 = {sta1:g}: the start angle lies within −360..360°")
    return sta1


def _results979(call: Call, answer: dict, size_key: str, cp: tuple[float, float], setval: float,
                tool: bool) -> None:
    """_OVR of CYCLE979 (manual §5.6 results, as CYCLE977 measuring-math §8.4): [0] setpoint,
    [1, 2] setpoint centre, [4] actual, [5, 6] actual centre, [16..18] differences, tolerances."""
    a, o = call.plane.first, call.plane.second
    cpa, cpo = cp
    result = answer.get("result") or {}
    centre = result.get("center") or {}
    size = float(result[size_key])
    ca, co = centre.get(a, cpa), centre.get(o, cpo)
    _tolerance_results(call, answer, setval, tool)
    for slot, value in ((1, cpa), (2, cpo), (4, size), (5, ca), (6, co), (16, size - setval), (17, ca - cpa),
                        (18, co - cpo)):
        call.ovr[slot] = call.out(value)
    call.common_results(answer)


def _centre_differences979(cpa: float, cpo: float, a: str, o: str):
    """The ZO variants' differences for _TSA: the centre's on both plane axes (manual §5.6.3)."""
    def differences(result):
        centre = result.get("center") or {}
        return [centre.get(a, cpa) - cpa, centre.get(o, cpo) - cpo]
    return differences


def _run979(call: Call, env, spec, params: dict, target, size_key: str, cp: tuple[float, float],
            setval: float) -> None:
    """Run a CYCLE979 variant: a tool offset with its tolerance, a ZO with the safe area on the
    centre's differences (manual §5.6.3); then its results."""
    tool = isinstance(target, dict)
    if tool:
        params["tolerance"] = call.tolerance(setval)
    elif call.variant > 100:
        spec = with_finisher(spec, _check_safe_area(call, _centre_differences979(*cp, call.plane.first,
                                                                               call.plane.second)))
    answer = call.run(env, spec, params, target)
    _results979(call, answer, size_key, cp, setval, tool)


def _circle979(call: Call, v: int) -> None:
    """Bore (1/101) or shaft (2/102) at an angle (measuring-math §10.1)."""
    bore = v % 100 == 1
    env = call.measuring()
    setup = env.setup()
    plane = call.plane
    a, o = plane.first, plane.second
    cpa, cpo = call.length("_CPA"), call.length("_CPO")
    setval = _setval979(call)
    points = _points_979(call)
    rf = call.real("_RF")
    plan = {"center": (cpa, cpo), "diameter": setval, "start_angle": call.real("_STA1"),
            "increment": call.real("_INCA"), "points": points, "inner": bore,
            "circle_feed": call.ctx.modal.feed_to_mm(rf) if rf > 0.0 else None}
    target = call.zo_target(setup) if v > 100 else call.tool_target()
    spec = with_planner(TASKS["hole.1" if bore else "spigot.1"],
                        lambda params, n, start, ctx, label: angle_circle_program(plan, start, ctx, label))
    params = {"diameter": setval, "setpoint": {a: cpa, o: cpo}, "measurements": call.measurements()}
    if not bore:
        params["infeed"] = 1.0          # the JOG spigot's DZ; CYCLE979 probes at the start height
    _run979(call, env, spec, params, target, "diameter", (cpa, cpo), setval)


def _line979(call: Call, v: int) -> None:
    """Slot (3/103) or web (4/104) at an angle (manual §5.6.1, measuring-math §10.2): the JOG
    task distance 2 edges along the line through (_CPA, _CPO) at _STA1, with the CYCLE979 plan."""
    slot = v % 100 == 3
    sta1 = _sta1_979(call)
    setval = _setval979(call)
    lift = call.length("_ID")
    if not slot and not lift > 0.0:
        raise CycleAlarm(alarms.NC_VALUE_RANGE, f"_ID = {call.real('_ID'):g}: the web is crossed over at the "
                         "measuring height + _ID: _ID > 0")
    env = call.measuring()
    setup = env.setup()
    plane = call.plane
    a, o = plane.first, plane.second
    cpa, cpo = call.length("_CPA"), call.length("_CPO")
    target = call.zo_target(setup) if v > 100 else call.tool_target()
    plan = {"center": (cpa, cpo), "width": setval, "start_angle": sta1, "inner": slot, "lift": lift}
    spec = with_planner(TASKS["edge.distance"],
                        lambda params, n, start, ctx, label: angle_line_program(plan, n, start, ctx, label))
    # directions: the travels' signs along û (slot P1 +û, web P1 −û), read by the evaluation
    params = {"axis": a, "direction": "+" if slot else "-", "direction_p2": "-" if slot else "+",
              "line_angle": sta1, "setpoint": {a: cpa, o: cpo}, "measurements": call.measurements()}
    _run979(call, env, spec, params, target, "distance", (cpa, cpo), setval)


def cycle979(call: Call) -> None:
    v = call.variant
    if v not in (1, 2, 3, 4, 101, 102, 103, 104):
        raise variant_error(call, "CYCLE979 measures 1 bore, 2 shaft, 3 slot or 4 web at an angle (+100 ZO)")
    if v % 100 in (1, 2):
        _circle979(call, v)
    else:
        _line979(call, v)


# --- CYCLE998 (measuring-math §11.1) -------------------------------------------------------------------

def _axes998(call: Call) -> tuple[int, int]:
    """(offset axis, measuring axis) of _MA (1..3 in the plane) for the one-angle variants."""
    v = call.variant
    if v == 1105:
        raise variant_error(call, "the differential measurement (1105) is not supported")
    if v in (106, 100106):
        raise variant_error(call, "the 2-angle measurement (106/100106) is not supported: measure the plane with "
                                  "the JOG task Orient plane")
    if v not in (105, 100105):
        raise variant_error(call, "CYCLE998 measures 105 or 100105 (one angle)")
    ma = call.integer("_MA")
    offset_i, measuring_i = ma // 100, ma % 100
    if (offset_i, measuring_i) not in ((1, 2), (2, 1), (1, 3), (2, 3)):
        definition = alarms.MEASURING_AXIS
        extra = " (301/302: the offset axis along the applicate is not supported)" if offset_i == 3 else ""
        raise CycleAlarm(definition, f"_MA = {ma}: offset·100 + measuring axis: 102, 201, 103, 203{extra}")
    return offset_i, measuring_i


def _angle_correction998(call: Call) -> str:
    """_RA: 0 rotates the ZO, else the channel's rotary axis number _RA takes the angle."""
    ra = call.integer("_RA")
    if ra == 0:
        return "rotation"
    axes = call.ctx.runtime.axes
    if not 1 <= ra <= len(axes) or axes[ra - 1] in ("X", "Y", "Z"):
        raise CycleAlarm(alarms.ROTARY_AXIS, f"_RA = {ra}: channel axis {ra} is not a rotary axis "
                         f"(axes {' '.join(axes)})")
    return axes[ra - 1]


def cycle998(call: Call) -> None:
    v = call.variant
    offset_i, measuring_i = _axes998(call)
    env = call.measuring()
    setup = env.setup()
    plane = call.plane
    axis_m, axis_k = plane.axes[measuring_i - 1], plane.axes[offset_i - 1]
    e_m, e_k = plane.unit(axis_m), plane.unit(axis_k)
    sigma_pair = 1.0 if (measuring_i - offset_i) % 3 == 1 else -1.0       # cyclic (offset, measuring)
    distance = call.length("_ID")
    if not distance > 0.0:
        raise CycleAlarm(alarms.DISTANCE_P1_P2, f"_ID = {call.real('_ID'):g}: the distance P1-P2 must be > 0")
    sta1 = call.real("_STA1")
    if not -45.0 <= sta1 <= 45.0:
        raise CycleAlarm(alarms.NC_VALUE_RANGE, f"_STA1 = {sta1:g}: the setpoint angle lies within −45..45°")
    correction = _angle_correction998(call)
    start = call.position()
    probe = _probe(env)
    tsa = abs(call.real("_TSA"))
    fa = call.fa
    if v == 105:
        # P2 positioned along the setpoint angle; its path covers the cone ±_TSA (measuring-math §11.1)
        setval = call.length("_SETVAL")
        sigma = 1.0 if float(start @ e_m) < setval else -1.0
        p1 = _approach_on_axis(call, env, start, axis_m, setval, sigma * e_m, probe)
        t0 = math.tan(math.radians(sta1))
        cone = distance * max(abs(math.tan(math.radians(sta1 + tsa)) - t0),
                              abs(math.tan(math.radians(sta1 - tsa)) - t0))
        p2 = p1 + distance * e_k + sigma_pair * distance * t0 * e_m - sigma * cone * e_m
    else:
        md = call.integer("_MD")
        if md not in (0, 1):
            raise CycleAlarm(alarms.MEASURING_DIRECTION, f"_MD = {md}: 0 (+) or 1 (−)")
        sigma = 1.0 if md == 0 else -1.0
        p1 = start
        p2 = p1 + distance * e_k
        cone = 0.0
    target = call.zo_target(setup)
    planner = _planner998(sigma * e_m, cone, fa)
    feed = _position_feed(env)

    def before_point(n):
        if n == 2:
            call.move(p2, feed)

    params = {"axis": axis_m, "direction": "+" if sigma > 0 else "-", "reference_axis": axis_k,
              "angle_correction": correction, "setpoint_angle": sta1, "measurements": call.measurements()}
    spec = with_planner(with_finisher(TASKS["edge.align"], _within_safe_area998(sta1, tsa)), planner)
    answer = call.run(env, spec, params, target, before_point=before_point)
    call.move(p1, feed)
    angle = float(answer["result"]["angle"])
    written = target != "measure_only"
    call.ovr.update({0: sta1, 4: angle, 16: angle_wrap(angle - sta1),
                     20: angle_wrap(angle - sta1) if written else 0.0, 28: tsa})
    call.ovi[11] = 1 if written else 0


def _planner998(d, cone: float, fa: float):
    """Edge probings along ``d``; P2's path covers the cone ±_TSA (``cone`` beyond _FA)."""

    def planner(params, n, s, ctx, label):
        if n == 2 and cone > 0.0:
            ctx = dataclasses.replace(ctx, measuring_path=fa + cone)
        return edge_program(d, s, ctx, label)

    return planner


def _within_safe_area998(sta1: float, tsa: float):
    """The finisher's wrapper: an angle further than _TSA from the setpoint _STA1 corrects nothing."""

    def check(original):
        def finish(session, ctx, points):
            answer, commit = original(session, ctx, points)
            delta = angle_wrap(float(answer["result"]["angle"]) - sta1)
            if abs(delta) > tsa:
                raise MeasuringError(alarms.SAFE_AREA, f"angle difference {delta:.4f}° beyond the safe area "
                                     f"_TSA {tsa:g}°: no correction")
            return answer, commit
        return finish

    return check


# --- CYCLE961 (measuring-math §12) ---------------------------------------------------------------------

def _given_corner961(call: Call, start: np.ndarray, inner: bool, feed: float):
    """117/118: the four given points _SETV[0..7] (a, o) at the depth _ID below the start:
    (probing starts, directions, the reference edge's nominal angle, the move before each point)."""
    plane = call.plane
    a_hat, o_hat, p_hat = plane.unit(plane.first), plane.unit(plane.second), plane.infeed_unit
    pts = [call.length("_SETV", (i,)) for i in range(8)]
    ao = [np.array(pts[2 * i:2 * i + 2]) for i in range(4)]
    h = float(start @ p_hat)
    given = [plane.to_xyz(np.array([q[0], q[1], h])) for q in ao]
    depth_shift = call.length("_ID") * p_hat

    def side_dir(p, q, others):
        line = q - p
        normal = np.array([-float(line @ o_hat), float(line @ a_hat)])
        normal = normal[0] * a_hat + normal[1] * o_hat
        toward = float(normal @ (0.5 * (others[0] + others[1]) - p))
        travel = normal * (1.0 if toward > 0 else -1.0) * (-1.0 if inner else 1.0)
        return _paraxial(plane, travel)

    if np.linalg.norm(given[1] - given[0]) < 1e-9 or np.linalg.norm(given[3] - given[2]) < 1e-9:
        raise CycleAlarm(alarms.POINTS_IDENTICAL, "P1 and P2 or P3 and P4 are identical")
    d12 = side_dir(given[0], given[1], given[2:])
    d34 = side_dir(given[2], given[3], given[:2])
    starts = [g + depth_shift for g in given]
    nominal_angle = math.degrees(math.atan2(float((given[1] - given[0]) @ o_hat),
                                            float((given[1] - given[0]) @ a_hat)))

    def before_point(n):
        here = call.position()
        top = here + float((start - here) @ p_hat) * p_hat
        call.move(top, feed)
        above = starts[n - 1] - depth_shift
        call.move(above, feed)
        call.move(starts[n - 1], feed)
    return starts, [d12, d12, d34, d34], nominal_angle, before_point


def _edges_corner961(call: Call, start: np.ndarray, inner: bool, feed: float):
    """105..108: two edges at _STA1 and _STA1 + _INCA, P2/P4 at _SETV[0]/[1] from the start:
    (probing starts, directions, the reference edge's nominal angle, the move before each point)."""
    plane = call.plane
    p_hat = plane.infeed_unit
    sta1, inca = call.real("_STA1"), call.real("_INCA")
    l1, l2 = call.length("_SETV", (0,)), call.length("_SETV", (1,))
    if not (l1 > 0.0 and l2 > 0.0):
        raise CycleAlarm(alarms.NC_VALUE_RANGE, "_SETV[0], _SETV[1]: the distances from the start to P2 and "
                         "P4 must be > 0")
    e1, e2 = _ao_unit(plane, sta1), _ao_unit(plane, sta1 + inca)
    perp1 = np.cross(p_hat, e1)
    perp2 = np.cross(p_hat, e2)
    n1 = perp1 if float(perp1 @ e2) > 0 else -perp1         # towards the second edge's side
    n2 = perp2 if float(perp2 @ e1) > 0 else -perp2
    sign = -1.0 if inner else 1.0                            # outer: into the material
    d1, d2 = _paraxial(plane, sign * n1), _paraxial(plane, sign * n2)
    starts = [start + l1 / 2.0 * e1, start + l1 * e1, start + l2 / 2.0 * e2, start + l2 * e2]
    lift = call.length("_ID")

    def before_point(n):
        if n == 3 and not inner and lift > 0.0:
            here = call.position()
            call.move(here + lift * p_hat, feed)
            call.move(starts[2] + lift * p_hat, feed)
        elif n == 3:
            call.move(start, feed)
        call.move(starts[n - 1], feed)
    return starts, [d1, d1, d2, d2], sta1, before_point


def _corner_setpoint961(call: Call, right: bool) -> dict[str, float]:
    """The corner's setpoint: 0, or for the right-angled corner the zero shifted by _SETV[4]."""
    plane = call.plane
    if not right:
        return {plane.first: 0.0, plane.second: 0.0}
    shift = int(call.real("_SETV", (4,)) or 1)
    if shift not in (1, 2, 3, 4):
        raise CycleAlarm(alarms.NC_VALUE_RANGE, f"_SETV[4] = {shift}: 1 corner, 2/3/4 shifted zero")
    s2, s3 = call.length("_SETV", (2,)), call.length("_SETV", (3,))
    return {plane.first: -s2 if shift in (2, 3) else 0.0, plane.second: -s3 if shift in (3, 4) else 0.0}


def _results961(call: Call, answer: dict, found: dict, depth: float) -> None:
    """_OVR: [4] the angle in the WCS, [5, 6] the corner (WCS), [20] the angle, [21, 22] the corner in the MCS."""
    plane = call.plane
    a_hat, o_hat = plane.unit(plane.first), plane.unit(plane.second)
    corner = (answer.get("result") or {})["corner"]
    k_wcs = plane.to_xyz(np.array([corner[plane.first], corner[plane.second], depth]))
    chain = found["chain"]
    k_mcs = chain.child2parent(k_wcs)
    phi_w = found["angle"]
    d_mcs = chain.dir_child2parent(_ao_unit(plane, phi_w))
    phi_m = math.degrees(math.atan2(float(d_mcs @ o_hat), float(d_mcs @ a_hat)))
    call.ovr.update({4: phi_w, 5: call.out(corner[plane.first]), 6: call.out(corner[plane.second]),
                     20: phi_m, 21: call.out(float(k_mcs @ a_hat)), 22: call.out(float(k_mcs @ o_hat))})


def cycle961(call: Call) -> None:
    v = call.variant
    if v not in (105, 106, 107, 108, 117, 118):
        raise variant_error(call, "CYCLE961 measures 105/106 rectangle corner, 107/108 any corner, 117/118 from "
                                  "4 given points (odd = inside, even = outside)")
    inner = v % 2 == 1
    env = call.measuring(measuring_path=max(call.fa, 20.0))     # internal minimum path 2·20 mm (measuring-math §12.2)
    setup = env.setup()
    plane = call.plane
    p_hat = plane.infeed_unit
    start = call.position()
    feed = _position_feed(env)
    right = v in (105, 106)
    corner_of = _given_corner961 if v in (117, 118) else _edges_corner961
    starts, dirs, nominal_angle, before_point = corner_of(call, start, inner, feed)
    n_points = 3 if right else 4
    starts, dirs = starts[:n_points], dirs[:n_points]
    spec = TASKS["corner.right" if right else "corner.any"]
    spec = with_planner(spec, lambda params, n, s, ctx, label: edge_program(dirs[n - 1], s, ctx, label))
    target = call.zo_target(setup)
    setpoint = _corner_setpoint961(call, right)
    found: dict = {}

    def turn(original):
        """The new abscissa runs along the reference edge P1→P2 (JOG folds an edge's angle into
        (−90°, 90°]): an extra 180° when that direction points the other way (measuring-math §12.2)."""
        def finish(session, ctx, points):
            folded = float(evaluate(session.task, session.params, points, ctx.plane, ctx.probe).values["angle"])
            turns = round((nominal_angle - folded) / 180.0)
            found["angle"] = angle_wrap(folded + 180.0 * turns)
            found["chain"] = ctx.chain().wcs2bcs
            session.params = {**session.params, "setpoint_angle": -180.0 if turns % 2 else 0.0}
            return original(session, ctx, points)
        return finish

    params = {"kind": "inside" if inner else "outside", "position": 1, "setpoint": setpoint,
              "measurements": call.measurements()}
    order = [2, 1, 3] if right else [2, 1, 3, 4]
    answer = call.run(env, with_finisher(spec, turn), params, target, before_point=before_point, order=order)
    # back to the start (the way the probe came: up first from the given points' depth)
    here = call.position()
    if v in (117, 118):
        call.move(here + float((start - here) @ p_hat) * p_hat, feed)
    else:
        call.move(start, feed)
    _results961(call, answer, found, float(starts[0] @ p_hat))
    call.ovi[11] = 1 if target != "measure_only" else 0


CYCLES = {"CYCLE977": cycle977, "CYCLE978": cycle978, "CYCLE979": cycle979, "CYCLE998": cycle998,
          "CYCLE961": cycle961}


def handlers(host) -> dict:
    return {name: (lambda ctx, body=body, number=int(name[5:]): run_cycle(ctx, host, number, body))
            for name, body in CYCLES.items()}

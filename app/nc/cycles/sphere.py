"""CYCLE997: sphere and three spheres (measuring-math §13) as workflow tasks of their own.

JOG has no sphere task, so the cycle brings two task specs with the JOG parts around them: the
workflow session (NC Start per sphere, Calculate for three), the step executor, the commit of
offset + audit + log in one transaction and the activation are the JOG ones; the plan and the
evaluation are ``engine.cycles`` (``sphere_program``, ``evaluate_sphere``, ``cycle119``), the
correction of one sphere is ``engine.correction.correct`` with the three axes determined (the JOG
correction: rotation kept, coarse, fine cleared), that of three spheres ``engine.cycles.reframed``.

_MVAR (7 digits): 1–3 = 109 (measure) or 119 (repeat from the found centre); 4: 0 paraxial /
1 at an angle; 5: 0 one / 1 three spheres; 6: (angle) 0 three / 1 four points; 7: 1 = determine
the diameter. _SETVAL diameter, _SETV[0..8] nominal centres (a, o, p), _KNUM the ZO.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from app.nc.cycles.base import Call, CycleAlarm, run_cycle, variant_error
from app.workflow.context import MEASURE_ONLY, OffsetChange, OffsetOutcome
from app.workflow.finish import _activation as activation
from app.workflow.tasks import Category, Target, TaskSpec
from engine import alarms
from engine.correction import Correction, correct
from engine.cycles import cycle119, evaluate_sphere, reframed, sphere_program
from engine.frames import Frame, parent2bcs_of
from engine.planes import Plane
from engine.tasks import EngineTask, Family
from engine.types import FeatureFix, MeasuringError

AXES = ("X", "Y", "Z")


def _xyz(values) -> dict[str, float]:
    return {a: float(v) for a, v in zip(AXES, values, strict=True)}


def _result(point, plane: Plane, nominal: np.ndarray) -> dict:
    centre, diameter = evaluate_sphere(point, plane)
    return {"center": _xyz(centre), "diameter": float(diameter), "setpoint": _xyz(nominal),
            "difference": _xyz(centre - nominal), "nominal_diameter": float(point.nominal_diameter)}


def _safe_area(tsa: float, differences) -> None:
    worst = max(abs(float(d)) for d in differences)
    if worst > tsa:
        raise MeasuringError(alarms.SAFE_AREA, f"difference {worst:.4f} mm beyond the safe area _TSA {tsa:g} mm: "
                             "no correction")


def _spec(name: str, spheres: list[dict], finish) -> TaskSpec:
    def program(params, n, start, ctx, label):
        return sphere_program(spheres[n - 1], start, ctx, label)

    engine = EngineTask(name, Family.SPIGOT, len(spheres), lambda params, plane: dict(params or {}), program)
    return TaskSpec(engine, Category.WORKPIECE, frozenset({Target.ZERO_OFFSET}), finish, lambda variant, env: [])


def one_sphere_finisher(tsa: float):
    def finish(session, ctx, points):
        (point,) = points
        nominal = np.asarray(session.params["center"], dtype=float)
        result = _result(point, ctx.plane, nominal)
        _safe_area(tsa, result["difference"].values())
        answer: dict = {"result": result, "activated": False, "setup_support": None}
        target = session.target
        if target == MEASURE_ONLY:
            answer["correction"] = {"target": MEASURE_ONLY, "before": None, "after": None}
            return answer, {"offset": None}
        centre = np.array([result["center"][a] for a in AXES])
        setpoints = _xyz(nominal)

        def compute(frames_now: Mapping[str, Frame]) -> OffsetOutcome:
            correction = correct(FeatureFix(position=_xyz(centre), point=centre), setpoints=setpoints,
                                 setpoint_angle=None, target=target, target_frame=frames_now[target],
                                 chain=ctx.chain(), target_parent2bcs=parent2bcs_of(frames_now, target),
                                 plane=ctx.plane)
            return OffsetOutcome(correction.before.to_api(), correction.after.to_api(),
                                 {"task": session.task, "setpoints": setpoints}, activation(correction, target, ctx))

        return answer, {"offset": OffsetChange(target, compute)}
    return finish


def three_spheres_finisher(tsa: float, distortion_limit: float):
    def finish(session, ctx, points):
        nominal = [np.asarray(s["center"], dtype=float) for s in session.params["spheres"]]
        results = [_result(p, ctx.plane, q) for p, q in zip(points, nominal, strict=True)]
        for r in results:
            _safe_area(tsa, r["difference"].values())
        actual = [np.array([r["center"][a] for a in AXES]) for r in results]
        fit = cycle119(nominal, actual)
        target = session.target
        result = {"spheres": results, "distortion": fit.residual,
                  "rotation": [[float(x) for x in row] for row in fit.rotation],
                  "translation": _xyz(fit.translation)}
        answer: dict = {"result": result, "activated": False, "setup_support": None}
        if fit.residual > abs(distortion_limit) and target != MEASURE_ONLY:
            raise MeasuringError(alarms.TRIANGLE_DISTORTION, f"triangle distortion {fit.residual:.4f} mm beyond "
                                 f"_TNVL {abs(distortion_limit):g} mm: no correction")
        if target == MEASURE_ONLY:
            answer["correction"] = {"target": MEASURE_ONLY, "before": None, "after": None}
            return answer, {"offset": None}

        def compute(frames_now: Mapping[str, Frame]) -> OffsetOutcome:
            before = frames_now[target]
            after = reframed(fit, target_frame=before, target_parent2bcs=parent2bcs_of(frames_now, target),
                             meas2bcs=ctx.chain().wcs2bcs)
            correction = Correction(target=target, before=before, after=after)
            return OffsetOutcome(before.to_api(), after.to_api(), {"task": session.task, "cycle119": result},
                                 activation(correction, target, ctx))

        return answer, {"offset": OffsetChange(target, compute)}
    return finish


def _variant997(call: Call) -> tuple[int, bool, bool, bool, bool]:
    """(109 or 119, at an angle, three spheres, four points, determine the diameter) of _MVAR."""
    v = call.variant
    base = v % 1000
    angle, three, four, determine = (v // 1000) % 10, (v // 10_000) % 10, (v // 100_000) % 10, v // 1_000_000
    if base not in (109, 119) or angle > 1 or three > 1 or four > 1 or determine > 1 or (four and not angle):
        raise variant_error(call, "CYCLE997: 109 / 119 (repeat), +1000 at an angle, +10000 three spheres, "
                                  "+100000 four points (at an angle), +1000000 diameter determination")
    return base, bool(angle), bool(three), bool(four), bool(determine)


def _spheres(call: Call, plane: Plane, setval: float, variant: tuple[int, bool, bool, bool, bool]) -> list[dict]:
    """The sphere(s) to probe: nominal centres from _SETV (a, o, p), the probing pattern of _MVAR."""
    base, angle, three, four, determine = variant
    rf = call.real("_RF")
    spheres: list[dict[str, Any]] = []
    for k in range(3 if three else 1):
        q_aop = np.array([call.length("_SETV", (3 * k + i,)) for i in range(3)])
        spheres.append({"center": plane.to_xyz(q_aop), "diameter": setval, "angle": angle,
                        "start_angle": call.real("_STA1"), "increment": call.real("_INCA") or (90.0 if four else 120.0),
                        "points": 4 if four else 3, "determine": determine, "repeat": base == 119,
                        "circle_feed": call.ctx.modal.feed_to_mm(rf) if rf > 0.0 else None})
    return spheres


def _write_results997(call: Call, plane: Plane, setval: float, nominal_centre, per_sphere: list[dict],
                      tsa: float) -> None:
    """_OVR: [0] _SETVAL, [1..3] the first nominal centre; [4] diameter, [5..7] centre, [8] diameter
    difference, [9..11] centre differences (sphere 1); sphere 2: [12], [13..15], [16..19]; sphere 3:
    [20], [21..23], [24..27] (measuring-math §13.2); [28] _TSA."""
    out = call.out
    call.ovr[0] = out(setval)
    for i, value in enumerate(plane.to_aop(nominal_centre)):
        call.ovr[1 + i] = out(value)
    layout = ((4, 5, 8, 9), (12, 13, 16, 17), (20, 21, 24, 25))
    for r, (d_slot, c_slot, dd_slot, cd_slot) in zip(per_sphere, layout, strict=False):
        centre = plane.to_aop([r["center"][a] for a in AXES])
        diff = plane.to_aop([r["difference"][a] for a in AXES])
        call.ovr[d_slot] = out(r["diameter"])
        call.ovr[dd_slot] = out(r["diameter"] - setval)
        for i in range(3):
            call.ovr[c_slot + i] = out(centre[i])
            call.ovr[cd_slot + i] = out(diff[i])
    call.ovr[28] = out(tsa)


def cycle997(call: Call) -> None:
    variant = _variant997(call)
    three = variant[2]
    env = call.measuring()
    setup = env.setup()
    plane = call.plane
    setval = call.length("_SETVAL")
    if not setval > 0.0:
        raise CycleAlarm(alarms.SPHERE_DIAMETER, f"_SETVAL = {call.real('_SETVAL'):g}: the sphere diameter must be > 0")
    spheres = _spheres(call, plane, setval, variant)
    target = call.zo_target(setup)
    tsa = abs(call.length("_TSA"))
    params: dict[str, object]                           # the task's JSON params
    if three:
        spec = _spec("sphere.3", spheres, three_spheres_finisher(tsa, call.length("_TNVL")))
        params = {"spheres": [{"center": [float(x) for x in s["center"]]} for s in spheres]}
    else:
        spec = _spec("sphere.1", spheres, one_sphere_finisher(tsa))
        params = {"center": [float(x) for x in spheres[0]["center"]]}
    params["diameter"] = setval
    params["measurements"] = call.measurements()
    answer = call.run(env, spec, params, target)
    result = answer.get("result") or {}
    _write_results997(call, plane, setval, spheres[0]["center"], result["spheres"] if three else [result], tsa)
    correction = answer.get("correction") or {}
    call.ovi[11] = 1 if correction.get("after") is not None and target != MEASURE_ONLY else 0
    if three:
        call.ovi[12] = 0


def handlers(host) -> dict:
    return {"CYCLE997": lambda ctx: run_cycle(ctx, host, 997, cycle997)}

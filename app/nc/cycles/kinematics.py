"""CYCLE996-like: measure a rotary axis on a calibration sphere in a program (design.md §10.6,
docs/kinematics.md). A product cycle in the style of the SW 6.3 cycles (parameters set before the
call); it runs the JOG task ``kinematics.measure`` through the same workflow (one NC Start per
position, then Calculate).

Parameters: ``_MVAR`` 0 check (report only) / 1 optimise (write the control's kinematic data; the
program's starter needs the ``settings`` level); ``_MA`` the axis 1 = A, 2 = B, 3 = C; ``_SETVAL``
the sphere diameter; ``_SETV[0..2]`` its centre (MCS X, Y, Z, every rotary axis at 0);
``_SETV[3]`` the number of positions n (3..36); ``_STA1`` the first position, ``_INCA`` the step
(deg): positions _STA1 + k·_INCA; ``_FA`` the clearance (mm).

Results: ``_OVR[0..2]`` the measured point on the axis, ``[3..5]`` its direction, ``[6..8]`` the
point's deviation from the machine data, ``[9]`` the axis offset (mm), ``[10]`` the direction error
(µrad), ``[11]`` the circle residual (mm), ``[12]`` the sphere diameter; ``_OVI[11]`` 1 = written.
"""

from __future__ import annotations

from app.nc.cycles.base import Call, CycleAlarm, run_cycle, variant_error
from app.workflow.kinematics_task import partner_of
from app.workflow.tasks import KINEMATICS_SPEC
from engine import alarms

AXES = {1: "A", 2: "B", 3: "C"}


def _params996(call: Call) -> dict:
    """The kinematics task's params from the cycle's: _MA axis, _SETVAL sphere Ø, _SETV[0..2] its
    centre, _SETV[3] positions from _STA1 in steps of _INCA, _MVAR check (0) or optimise (1)."""
    mode = call.variant
    if mode not in (0, 1):
        raise variant_error(call, "CYCLE996: _MVAR 0 (check) or 1 (optimise)")
    axis = AXES.get(call.integer("_MA"))
    if axis is None:
        raise CycleAlarm(alarms.ROTARY_AXIS, f"_MA = {call.integer('_MA')}: the rotary axis 1 (A), 2 (B) or 3 (C)")
    diameter = call.length("_SETVAL")
    if not diameter > 0.0:
        raise CycleAlarm(alarms.SPHERE_DIAMETER, f"_SETVAL = {call.real('_SETVAL'):g}: the sphere diameter must be > 0")
    count = int(round(call.real("_SETV", (3,))))
    if not 3 <= count <= 36:
        raise CycleAlarm(alarms.NC_VALUE_RANGE, f"_SETV[3] = {call.real('_SETV', (3,)):g}: 3..36 positions")
    start, step = call.real("_STA1"), call.real("_INCA")
    return {"sphere": {"center": [call.length("_SETV", (i,)) for i in range(3)], "diameter": diameter},
            "axis": axis, "positions": [start + k * step for k in range(count)],
            "mode": "optimise" if mode == 1 else "check", "clearance": max(0.5, min(50.0, call.fa))}


def cycle996(call: Call) -> None:
    params = _params996(call)
    axis = params["axis"]
    env = call.measuring()
    facts = env.context().extra.get("kinematics") or {}
    points = len(params["positions"]) + (1 if partner_of(params, facts) is not None else 0)  # + the zero reference
    answer = call.run(env, KINEMATICS_SPEC, params, "measure_only", order=range(1, points + 1))
    result = answer.get("result") or {}
    line = (result.get("axes") or {}).get(axis) or {}
    deviation = (result.get("deviation") or {}).get(axis) or {}
    out = call.out
    for i in range(3):
        call.ovr[i] = out(line.get("point", [0.0] * 3)[i])
        call.ovr[3 + i] = float(line.get("direction", [0.0] * 3)[i])
        call.ovr[6 + i] = out(deviation.get("point", [0.0] * 3)[i])
    call.ovr[9] = out(deviation.get("offset", 0.0))
    call.ovr[10] = float(deviation.get("angle_urad", 0.0))
    call.ovr[11] = out(line.get("residual", 0.0))
    call.ovr[12] = out(result.get("sphere_diameter", 0.0))
    call.ovi[11] = 1 if result.get("written") else 0


def handlers(host) -> dict:
    return {"CYCLE996": lambda ctx: run_cycle(ctx, host, 996, cycle996)}

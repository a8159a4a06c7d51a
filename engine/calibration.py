"""Workpiece probe calibration: length on a surface, radius in a ring of unknown centre.

Spec: spec/jog-measuring.md §5.2/§5.3 [I], measuring-math §5.1, §7.2, §7.3, §7.5.

Convention (measuring-math §5.1): the trigger value of travel direction ``dir`` along axis j is
``t_dir = c_switch,j − s_j`` with the ball-centre estimate ``c = rec + e`` (``rec`` = the NC's
reference point at the latch, ``e`` = stored skew at spindle 0°). Measuring then inverts it:
``s_j = c_j − t_dir`` (engine.compensation.make_touch).

Ring calibration, derivation (per plane axis j; D = ring diameter, R = D/2, M = true centre).
Let b = true ball centre at the latch, r the true ball radius, δ(±j) the travel past first
contact before the latch (pre-travel + feed·latency), e the true skew at spindle 0°; SPOS 180°
turns it to −e. Probing through the centre along ±j:

    b(+j) = M_j + (R − r) + δ(+j)          b(−j) = M_j − (R − r) − δ(−j)
    rec_φ(±j) = b(±j) − e_φ,j              e_0 = e, e_180 = −e

Pass mid-points m_φ = (rec_φ(+j) + rec_φ(−j))/2 = M_j + k_j − e_φ,j with k_j = (δ(+j) − δ(−j))/2:

    e_j  = (m180 − m0)/2                    (exact: pre-travel does not turn with the spindle)
    MP_j = (m0 + m180)/2 = M_j + k_j
    t(+j) = rec_0(+j) + e_j − (MP_j + R) = −(r − δ̄_j)      δ̄_j = (δ(+j) + δ(−j))/2
    t(−j) = rec_0(−j) + e_j − (MP_j − R) = +(r − δ̄_j)
    effective diameter d_eff = 2·mean|t| = mean over axes of (t(−j) − t(+j))   (§7.2, §17 Q4)

Measuring later with c = rec + e and s = c − t: an edge at E probed +j gives
s = (E − r + δ(+j)) + (r − δ̄_j) = E + k_j, probed −j gives E + k_j as well; a bore of any
diameter gives centre M' + k and the exact diameter. So everything is exact when the
pre-travel is symmetric per axis (δ(+j) = δ(−j), any value per axis, any latency, any
eccentricity); an asymmetry only shifts all positions on axis j by the same k_j. That shift is
not observable in a ring of unknown centre (rank argument: per axis the 4 latches determine
e, M + δ(+), M − δ(−), never M and δ(±) apart) - only a known-centre reference (§7.2) could.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from engine.frames import Frame
from engine.plan_base import RingCalibrationPoint, RingPass
from engine.planes import Plane, axis_index
from engine.types import EdgePoint, MeasuringError, ProbeRecord

__all__ = ["calibrate_length", "calibrate_length_point", "calibrate_radius", "evaluate_probe_task",
           "probe_values"]


def calibrate_length(rec_infeed: float, setpoint: float, probe: ProbeRecord, length_old: float,
                     plane: Plane) -> tuple[ProbeRecord, dict]:
    """Probe length L1 on a surface at ``setpoint`` (infeed coordinate, WCS), travel −infeed.

    ``rec_infeed``: the NC's reference point on the infeed axis at the latch (nominal ball
    centre, or the ball tip with ``probe.length_to_tip`` = _CBIT[14]=1), computed with
    ``length_old``. r = DP6 = ball_diameter/2 (spec §5.2 [I], measuring-math §7.5 [M]):

        _CBIT[14]=0:  L1_new = L1_old + (rec_p − setpoint − r),   t(−p) = r
        _CBIT[14]=1:  L1_new = L1_old + (rec_p − setpoint),       t(−p) = 0

    Pre-travel and latency are absorbed into L1. Returns the updated record and the numbers
    to display (``length``, ``length_old``, ``difference``, ``trigger``).
    """
    r = probe.ball_diameter / 2.0
    tip = probe.length_to_tip
    length_new = length_old + (rec_infeed - setpoint - (0.0 if tip else r))   # §7.5
    key = f"{plane.infeed}-"
    trigger_new = 0.0 if tip else r                                           # §7.5 _WP[k,5]
    triggers = dict(probe.trigger)
    old_trigger = triggers.get(key)
    triggers[key] = trigger_new
    record = replace(probe, trigger=triggers, calibrated_length=True)
    values = {"length": float(length_new), "length_old": float(length_old),
              "difference": float(length_new - length_old),
              "trigger": {key: float(trigger_new)},
              "trigger_difference": {key: None if old_trigger is None else float(trigger_new - old_trigger)},
              "length_to_tip": bool(tip)}
    return record, values


def calibrate_length_point(point: EdgePoint, setpoint: float, probe: ProbeRecord, length_old: float,
                           plane: Plane) -> tuple[ProbeRecord, dict]:
    """``calibrate_length`` from the stored point of ``probe.length`` (engine.plan raw edge
    program: ``touch.ball_centre`` = rec, + r·p̂ when L1 refers to the tip)."""
    p = plane.infeed_unit
    rec = np.asarray(point.touch.ball_centre, dtype=float)
    if probe.length_to_tip:
        rec = rec - (probe.ball_diameter / 2.0) * p          # back to the tip (§0.1)
    return calibrate_length(float(rec @ p), setpoint, probe, length_old, plane)


def _pass_mid(ring_pass: RingPass, axis: str) -> tuple[float, float, float]:
    j = axis_index(axis)
    try:
        plus = float(np.asarray(ring_pass.rec[f"{axis}+"], dtype=float)[j])
        minus = float(np.asarray(ring_pass.rec[f"{axis}-"], dtype=float)[j])
    except KeyError as missing:
        raise MeasuringError(61301, f"ring pass at {ring_pass.spindle_angle:g}° lacks {missing}") from None
    return 0.5 * (plus + minus), plus, minus


def calibrate_radius(point: RingCalibrationPoint, probe: ProbeRecord, plane: Plane,
                     wcs2bcs: Frame | None = None) -> tuple[ProbeRecord, dict]:
    """Trigger values ±a, ±o, skew and effective diameter from a ring of known diameter and
    unknown centre (spec §5.3 [I], measuring-math §7.3; derivation in the module docstring).

    ``point.passes`` holds the pass at SPOS 180° and the pass at SPOS 0° (raw ``rec`` in the
    measuring WCS, keyed "X+", "X-", ...). ``wcs2bcs``: the measuring WCS -> BCS frame; the skew
    is stored in machine X/Y at spindle 0° (ProbeRecord.skew), so a rotated WCS is turned back.
    Returns the updated record and the numbers to display: ``center`` (ring centre, plane axes),
    ``skew``, ``trigger`` and ``trigger_difference`` per direction, ``effective_diameter`` and
    its ``effective_diameter_difference``.
    """
    by_angle = {round(float(p.spindle_angle) % 360.0, 6): p for p in point.passes}
    if 180.0 not in by_angle or 0.0 not in by_angle:
        raise ValueError("radius calibration needs a pass at SPOS 180° and one at SPOS 0°")
    pass180, pass0 = by_angle[180.0], by_angle[0.0]
    half = point.diameter / 2.0
    if half <= 0.0:
        raise ValueError(f"ring diameter must be > 0, got {point.diameter}")
    centre: dict[str, float] = {}
    skew_wcs = np.zeros(3)
    triggers: dict[str, float] = {}
    for axis in (plane.first, plane.second):
        m180, _, _ = _pass_mid(pass180, axis)
        m0, plus0, minus0 = _pass_mid(pass0, axis)
        e_j = 0.5 * (m180 - m0)                                  # §7.3 e = (m180 − m0)/2
        mp_j = 0.5 * (m0 + m180)                                 # §7.3 MP = (m0 + m180)/2
        centre[axis] = mp_j
        skew_wcs[axis_index(axis)] = e_j
        # §7.2 t = rec + e − S, from the 0° pass only: its chords run through the centre (the
        # search ran at 0°); the 180° pass's chords are 2e off-centre, which biases their ends
        triggers[f"{axis}+"] = plus0 + e_j - (mp_j + half)
        triggers[f"{axis}-"] = minus0 + e_j - (mp_j - half)
    for key, value in triggers.items():
        if (value < 0.0) != key.endswith("+") or value == 0.0:
            raise MeasuringError(61303, f"trigger value {key} = {value:.4f} has the wrong sign: "
                                        "check the ring diameter")
    d_eff = 2.0 * float(np.mean([abs(v) for v in triggers.values()]))   # §7.2, spec §5.3 [I]
    skew_mcs = skew_wcs if wcs2bcs is None else wcs2bcs.dir_child2parent(skew_wcs)
    new_triggers = dict(probe.trigger)
    new_triggers.update(triggers)
    record = replace(probe, trigger=new_triggers, skew=(float(skew_mcs[0]), float(skew_mcs[1])),
                     effective_diameter=d_eff, calibrated_radius=True)
    values = {
        "center": centre,
        "skew": {"X": float(skew_mcs[0]), "Y": float(skew_mcs[1])},
        "trigger": {k: float(v) for k, v in triggers.items()},
        "trigger_difference": {k: (None if k not in probe.trigger else float(v - probe.trigger[k]))
                               for k, v in triggers.items()},
        "effective_diameter": d_eff,
        "effective_diameter_difference": (None if probe.effective_diameter <= 0.0
                                          else d_eff - probe.effective_diameter),
    }
    return record, values


def probe_values(probe: ProbeRecord) -> dict:
    """JSON view of a probe record (the ``probe`` result key of design.md §4)."""
    return {"number": probe.number, "ball_diameter": probe.ball_diameter,
            "effective_diameter": probe.effective_diameter,
            "trigger": {k: float(v) for k, v in probe.trigger.items()},
            "skew": {"X": float(probe.skew[0]), "Y": float(probe.skew[1])},
            "length_to_tip": probe.length_to_tip, "calibrated_radius": probe.calibrated_radius,
            "calibrated_length": probe.calibrated_length}


def evaluate_probe_task(task: str, params: dict, point, probe: ProbeRecord, plane: Plane, *,
                        length_old: float | None = None, wcs2bcs: Frame | None = None
                        ) -> tuple[ProbeRecord, dict]:
    """``probe.length`` / ``probe.radius`` (design.md §4): (new record, result values with the
    ``probe`` key plus the calibration numbers). ``length_old``: the probe's L1 (tool data)."""
    if task == "probe.length":
        if not isinstance(point, EdgePoint):
            raise ValueError(f"probe.length needs an EdgePoint, got {type(point).__name__}")
        if length_old is None:
            raise ValueError("probe.length needs the probe's current L1 (length_old)")
        setpoint = params.get("setpoint", 0.0)
        if isinstance(setpoint, dict):        # validate_params keys it by the infeed axis
            setpoint = setpoint.get(plane.infeed, 0.0)
        record, numbers = calibrate_length_point(point, float(setpoint), probe, length_old, plane)
    elif task == "probe.radius":
        if not isinstance(point, RingCalibrationPoint):
            raise ValueError(f"probe.radius needs a RingCalibrationPoint, got {type(point).__name__}")
        record, numbers = calibrate_radius(point, probe, plane, wcs2bcs)
    else:
        raise ValueError(f"not a probe calibration task: {task!r}")
    return record, {"probe": probe_values(record), **numbers}

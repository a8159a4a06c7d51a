"""Workpiece probe calibration: length on a surface, radius in a ring of unknown centre.

Spec: spec/jog-measuring.md §5.2/jog-measuring §5.3 [I], measuring-math §5.1, measuring-math §7.2, measuring-math §7.3, measuring-math §7.5.

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
    effective diameter d_eff = 2·mean|t| = mean over axes of (t(−j) − t(+j))   (jog-measuring §7.2, measuring-math §17 Q4)

Measuring later with c = rec + e and s = c − t: an edge at E probed +j gives
s = (E − r + δ(+j)) + (r − δ̄_j) = E + k_j, probed −j gives E + k_j as well; a bore of any
diameter gives centre M' + k and the exact diameter. So everything is exact when the
pre-travel is symmetric per axis (δ(+j) = δ(−j), any value per axis, any latency, any
eccentricity); an asymmetry only shifts all positions on axis j by the same k_j. That shift is
not observable in a ring of unknown centre (rank argument: per axis the 4 latches determine
e, M + δ(+), M − δ(−), never M and δ(±) apart) - only a known-centre reference (jog-measuring §7.2) could.
That is the wave-1 model (pre-travel fixed to the machine axes). For the real probe, whose
pre-travel turns with the spindle, and for every touch of every pass: the least-squares
estimator ``estimate_ring`` / ``calibrate_ring`` below (its own derivation; docs/noise-bound.md).
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import numpy.typing as npt

from engine import alarms, checks
from engine.compensation import centre_trigger_value
from engine.frames import Frame, rot_z
from engine.lobing import LobingMap, fit_lobing_map
from engine.plan_base import BoreCalibrationPoint, RingCalibrationPoint, RingPass
from engine.planes import PLANES, Plane, axis_index
from engine.types import EdgePoint, FloatArray, MeasuringError, ProbeRecord

__all__ = ["PRETRAVEL_FRAMES", "FrameDecision", "RingEstimate", "RingTouch", "calibrate_length",
           "calibrate_length_point", "calibrate_radius", "calibrate_surface", "calibrate_ring", "calibration_jacobian",
           "calibration_variances", "choose_pretravel_frame", "estimate_ring", "evaluate_probe_task",
           "ideal_ring_touches", "probe_values", "ring_touches", "setup_noise_bound"]


def calibrate_length(rec_infeed: float, setpoint: float, probe: ProbeRecord, length_old: float,
                     plane: Plane) -> tuple[ProbeRecord, dict[str, Any]]:
    """Probe length L1 on a surface at ``setpoint`` (infeed coordinate, WCS), travel −infeed.

    ``rec_infeed``: the NC's reference point on the infeed axis at the latch (nominal ball
    centre, or the ball tip with ``probe.length_to_tip`` = _CBIT[14]=1), computed with
    ``length_old``. r = DP6 = ball_diameter/2 (jog-measuring §5.2 [I], measuring-math §7.5 [M]):

        _CBIT[14]=0:  L1_new = L1_old + (rec_p − setpoint − r),   t(−p) = r
        _CBIT[14]=1:  L1_new = L1_old + (rec_p − setpoint),       t(−p) = 0

    Pre-travel and latency are absorbed into L1. Returns the updated record and the numbers
    to display (``length``, ``length_old``, ``difference``, ``trigger``).
    """
    r = probe.ball_diameter / 2.0
    tip = probe.length_to_tip
    length_new = length_old + (rec_infeed - setpoint - (0.0 if tip else r))   # measuring-math §7.5
    key = f"{plane.infeed}-"
    trigger_new = 0.0 if tip else r                                           # measuring-math §7.5 _WP[k,5]
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
                           plane: Plane) -> tuple[ProbeRecord, dict[str, Any]]:
    """``calibrate_length`` from the stored point of ``probe.length`` (engine.plan raw edge
    program: ``touch.ball_centre`` = rec, + r·p̂ when L1 refers to the tip)."""
    p = plane.infeed_unit
    rec = np.asarray(point.touch.ball_centre, dtype=float)
    if probe.length_to_tip:
        rec = rec - (probe.ball_diameter / 2.0) * p          # back to the tip (jog-measuring §0.1)
    return calibrate_length(float(rec @ p), setpoint, probe, length_old, plane)


def calibrate_surface(point: EdgePoint, axis: str, setpoint: float, probe: ProbeRecord, *,
                      safe_area: float | None = None) -> tuple[ProbeRecord, dict[str, Any]]:
    """Trigger value of one direction on a surface at ``setpoint`` (CYCLE976 ``_MVAR=0``,
    manual §5.3.3 ``%_N_KALIBRIEREN_IN_Z_MPF``, measuring-math §5.1, measuring-math §7.5).

    ``point``: one touch travelling along ±``axis`` (``touch.ball_centre`` = c = rec + e, the
    ball-centre estimate with the stored skew, + r·p̂ with L1 to the tip). The probe length L1 is
    known and stays; only the travel direction's trigger value changes:

        t_dir = c_axis − _SETVAL          (measuring-math §7.5; ideal probe t(−) = +r, t(+) = −r)

    ``safe_area`` (_TSA): |t_new − t_old| above it refuses with 61303 (the manual's advice for a
    first calibration: program _TSA greater than the ball radius). A trigger value of the wrong
    sign (the surface lies behind the switching point) is 61303 as well.
    """
    touch = point.touch
    d = np.asarray(touch.direction, dtype=float)
    j = axis_index(axis)
    if abs(abs(float(d[j])) - 1.0) > 1e-9:
        raise ValueError(f"the surface touch must travel along {axis}, got direction {d.tolist()}")
    sign = "+" if d[j] > 0.0 else "-"
    key = f"{axis}{sign}"
    trigger = float(np.asarray(touch.ball_centre, dtype=float)[j]) - float(setpoint)   # measuring-math §7.5
    if trigger == 0.0 or (trigger < 0.0) != (sign == "+"):
        raise MeasuringError(alarms.SAFE_AREA, f"trigger value {key} = {trigger:.4f} has the wrong sign: "
                                               f"check _SETVAL = {setpoint:g}")
    old = probe.trigger.get(key)
    difference = None if old is None else trigger - float(old)
    if safe_area is not None and abs(trigger - float(old or 0.0)) > safe_area:
        raise MeasuringError(alarms.SAFE_AREA, f"trigger value {key} = {trigger:.4f} differs by "
                                               f"{abs(trigger - float(old or 0.0)):.4f} mm from the stored "
                                               f"{float(old or 0.0):.4f}: more than _TSA = {safe_area:g}")
    triggers = dict(probe.trigger)
    triggers[key] = trigger
    record = replace(probe, trigger=triggers)
    values = {"trigger": {key: trigger}, "trigger_difference": {key: difference},
              "surface": {axis: float(setpoint)}}
    return record, values


def _pass_mid(ring_pass: RingPass, axis: str) -> tuple[float, float, float]:
    j = axis_index(axis)
    try:
        plus = float(np.asarray(ring_pass.rec[f"{axis}+"], dtype=float)[j])
        minus = float(np.asarray(ring_pass.rec[f"{axis}-"], dtype=float)[j])
    except KeyError as missing:
        raise MeasuringError(alarms.PROBE_NOT_SWITCHED, f"ring pass at {ring_pass.spindle_angle:g}° lacks {missing}") from None
    return 0.5 * (plus + minus), plus, minus


def calibrate_radius(point: RingCalibrationPoint, probe: ProbeRecord, plane: Plane,
                     wcs2bcs: Frame | None = None) -> tuple[ProbeRecord, dict[str, Any]]:
    """Trigger values ±a, ±o, skew and effective diameter from a ring of known diameter and
    unknown centre (jog-measuring §5.3 [I], measuring-math §7.3; derivation in the module docstring).

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
        e_j = 0.5 * (m180 - m0)                                  # jog-measuring §7.3 e = (m180 − m0)/2
        mp_j = 0.5 * (m0 + m180)                                 # jog-measuring §7.3 MP = (m0 + m180)/2
        centre[axis] = mp_j
        skew_wcs[axis_index(axis)] = e_j
        # jog-measuring §7.2 t = rec + e − S, from the 0° pass only: its chords run through the centre (the
        # search ran at 0°); the 180° pass's chords are 2e off-centre, which biases their ends
        triggers[f"{axis}+"] = plus0 + e_j - (mp_j + half)
        triggers[f"{axis}-"] = minus0 + e_j - (mp_j - half)
    for key, value in triggers.items():
        if (value < 0.0) != key.endswith("+") or value == 0.0:
            raise MeasuringError(alarms.SAFE_AREA, f"trigger value {key} = {value:.4f} has the wrong sign: "
                                        "check the ring diameter")
    d_eff = 2.0 * float(np.mean([abs(v) for v in triggers.values()]))   # jog-measuring §7.2, jog-measuring §5.3 [I]
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


def _bore_key(u: FloatArray, nominal: str, plane: Plane) -> str:
    """The stored field of travel direction ``u``: the axis direction closest to it (a tie, at
    45°, keeps the ``nominal`` one: "+1" -> the 1st axis' +), measuring-math §7.4."""
    axes = {f"{a}{s}": (1.0 if s == "+" else -1.0) * plane.unit(a)
            for a in (plane.first, plane.second) for s in ("+", "-")}
    first = {"1": plane.first, "2": plane.second}[nominal[1]]
    best = f"{first}{nominal[0]}"
    top = float(axes[best] @ u)
    for key, v in axes.items():
        if float(v @ u) > top + 1e-9:
            best, top = key, float(v @ u)
    return best


def _bore_skew(point: BoreCalibrationPoint, plane: Plane, old: FloatArray) -> tuple[FloatArray, FloatArray]:
    """(bore centre MP, measured skew e in the WCS plane; components not observed stay ``old``):
    unknown centre MP = (m0 + m180)/2, e = (m180 − m0)/2 (measuring-math §7.3); known centre, per
    pair of opposite directions u: e·u = (MP − (rec(+u) + rec(−u))/2)·u (measuring-math §7.2)."""
    p = plane.infeed_unit
    if point.pass_centres is not None:
        m180, m0 = point.pass_centres
        e = 0.5 * (m180 - m0)
        return 0.5 * (m0 + m180), e - float(e @ p) * p
    assert point.centre is not None
    centre, e = np.asarray(point.centre, float), old.copy()
    rec = dict(zip(point.keys, point.rec, strict=True))
    for axis in ("1", "2"):
        if f"+{axis}" in rec and f"-{axis}" in rec:
            u = point.units[point.keys.index(f"+{axis}")]
            e = e + (float((centre - 0.5 * (rec[f"+{axis}"] + rec[f"-{axis}"])) @ u) - float(e @ u)) * u
    return centre, e


def _checked_trigger(key: str, value: float, probe: ProbeRecord, safe_area: float | None, setval: float) -> float:
    """``value`` of field ``key``, or 61303 for a wrong sign or a change above _TSA."""
    if value == 0.0 or (value < 0.0) != key.endswith("+"):
        raise MeasuringError(alarms.SAFE_AREA, f"trigger value {key} = {value:.4f} has the wrong sign: "
                                               f"check _SETVAL = {setval:g}")
    old = float(probe.trigger.get(key) or 0.0)
    if safe_area is not None and abs(value - old) > safe_area:
        raise MeasuringError(alarms.SAFE_AREA, f"trigger value {key} = {value:.4f} differs by {abs(value - old):.4f} "
                                               f"mm from the stored {old:.4f}: more than _TSA = {safe_area:g}")
    return value


def calibrate_bore(point: BoreCalibrationPoint, probe: ProbeRecord, plane: Plane, *, skew_wcs: npt.ArrayLike,
                   with_skew: bool, with_ball: bool, safe_area: float | None = None,
                   wcs2bcs: Frame | None = None, spindle_angle: float = 0.0) -> tuple[ProbeRecord, dict[str, Any]]:
    """CYCLE976 in a bore along 1, 2 or 4 directions, axis-parallel or at the angle _STA1
    (manual §5.3.1/§5.3.2, measuring-math §7.2–7.4).

    The ball centre of a touch is c = rec + e (e: the measured skew when ``with_skew``, else the
    stored ``skew_wcs``); with v = c − MP, A = v·u, h = v·w (w ⟂ u in the plane) the trigger
    value along u is τ = A + h²/(2A) − D/2 (the chord's sagitta to second order, 0 on a diameter),
    stored in the field of the axis direction closest to u: τ for a + field, −τ for a − field
    (measuring-math §7.4). ``with_ball``: d_eff = mean over opposite pairs of t(−) − t(+).
    ``safe_area`` (_TSA): a change above it refuses with 61303, as a wrong sign does. The skew
    is stored in machine X/Y at spindle 0° (turned back from ``spindle_angle``, the SPOS of the
    touches).
    """
    old = np.asarray(skew_wcs, dtype=float)
    centre, measured = _bore_skew(point, plane, old)
    e = measured if with_skew else old
    p = plane.infeed_unit
    half = point.diameter / 2.0
    triggers: dict[str, float] = {}
    taus: dict[str, float] = {}
    for key, u, rec in zip(point.keys, point.units, point.rec, strict=True):
        v = np.asarray(rec, float) + e - centre
        v = v - float(v @ p) * p
        a = float(v @ u)
        h = float(np.linalg.norm(v - a * u))
        taus[key] = a + h * h / (2.0 * a) - half if a > 0.0 else -half
        field_key = _bore_key(u, key, plane)
        triggers[field_key] = _checked_trigger(field_key, taus[key] if field_key.endswith("+") else -taus[key],
                                               probe, safe_area, point.diameter)
    pairs = [-(taus[f"+{i}"] + taus[f"-{i}"]) for i in ("1", "2") if f"+{i}" in taus and f"-{i}" in taus]
    d_eff = float(np.mean(pairs)) if with_ball and pairs else None
    skew_mcs = rot_z(-spindle_angle) @ (e if wcs2bcs is None else wcs2bcs.dir_child2parent(e))
    record = replace(probe, trigger={**probe.trigger, **triggers},
                     skew=(float(skew_mcs[0]), float(skew_mcs[1])) if with_skew else probe.skew,
                     effective_diameter=d_eff if d_eff is not None else probe.effective_diameter)
    values: dict[str, Any] = {
        "trigger": triggers,
        "trigger_difference": {k: (None if k not in probe.trigger else v - float(probe.trigger[k]))
                               for k, v in triggers.items()},
        "angle": float(point.angle),
        "skew": {"X": float(skew_mcs[0]), "Y": float(skew_mcs[1])} if with_skew else None,
        "effective_diameter": d_eff,
        "effective_diameter_difference": (None if d_eff is None or probe.effective_diameter <= 0.0
                                          else d_eff - probe.effective_diameter),
    }
    if point.pass_centres is not None:
        values["center"] = {plane.first: float(centre @ plane.unit(plane.first)),
                            plane.second: float(centre @ plane.unit(plane.second))}
    return record, values


def probe_values(probe: ProbeRecord) -> dict[str, Any]:
    """JSON view of a probe record (the ``probe`` result key of design.md §4)."""
    return {"number": probe.number, "ball_diameter": probe.ball_diameter,
            "effective_diameter": probe.effective_diameter,
            "trigger": {k: float(v) for k, v in probe.trigger.items()},
            "skew": {"X": float(probe.skew[0]), "Y": float(probe.skew[1])},
            "length_to_tip": probe.length_to_tip, "calibrated_radius": probe.calibrated_radius,
            "calibrated_length": probe.calibrated_length}


def evaluate_probe_task(task: str, params: dict[str, Any], point: object, probe: ProbeRecord, plane: Plane, *,
                        length_old: float | None = None, wcs2bcs: Frame | None = None,
                        pretravel_frame: str | None = None, first_harmonic: str = "convention"
                        ) -> tuple[ProbeRecord, dict[str, Any]]:
    """``probe.length`` / ``probe.radius`` (design.md §4): (new record, result values with the
    ``probe`` key plus the calibration numbers). ``length_old``: the probe's L1 (tool data).
    ``pretravel_frame``: None = calibrate_radius (as before); "probe" / "machine" = the
    least-squares calibrate_ring with that pre-travel model."""
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
        if pretravel_frame is None:
            record, numbers = calibrate_radius(point, probe, plane, wcs2bcs)
        else:
            record, numbers = calibrate_ring(point, probe, plane, wcs2bcs, frame=pretravel_frame,
                                             first_harmonic=first_harmonic)
    else:
        raise ValueError(f"not a probe calibration task: {task!r}")
    return record, {"probe": probe_values(record), **numbers}


# =====================================================================================
# Least-squares ring calibration from every touch (design.md §9.8, issue [probe-physics])
# =====================================================================================
#
# Model (one touch i: NC reference rec_i at the latch, unit travel d_i in the plane, SPOS φ_i).
# The true ball centre is b = rec + E(φ), E(φ) = Rz(φ)·e (eccentricity e at 0°, machine X/Y).
# It first touched the ring (centre M, radius R) with the ball (radius r) at b − δ_i·d_i, δ_i =
# pre-travel + v·τ (+ noise), so |b − δ_i·d_i − M| = R − r. Split b − M into the part along d_i
# and the chord offset h_i across it:
#
#     (rec_i + E_i − M)·d_i = R − ρ_i + s(h_i),   ρ_i = r − δ_i,   s(h) = √((R−r)² − h²) − (R−r)
#     h_i = (rec_i + E_i − M)·d_i⊥                                       (s ≈ −h²/2(R−r) ≤ 0)
#
# ρ_i is the effective radius of the travel direction (the trigger value's magnitude, jog-measuring §5.1);
# it depends on the direction class j(i): the travel angle in the probe's frame θ − φ
# (pretravel_frame "probe": the lobing turns with the spindle) or in the machine frame θ
# ("machine", the wave-1 simulator). E_i·d_i = e·q_i with q_i = Rz(−φ_i)·d_i,mcs (the direction
# seen by the probe). Unknowns: M (2), e (2), ρ_j (one per class) and the ball radius r, which
# enters only s(h): ∂s/∂r = 1 − (R−r)/√((R−r)² − h²) ≈ −h²/2(R−r)². Chords at different offsets
# h within one direction class (the centre search near h = 0, the cal_chords passes at
# h = ±(R − r)/2) observe r; it is then estimated, so a wrong nominal ball (the tool data the
# operator typed) does not bias ρ through the sagitta (a 0.1 mm small ball cost 6.2 µm per
# direction with the nominal in s(h)). Chords near the centre leave r at the nominal, where
# a wrong one costs at most h²Δr/2(R−r)² (sub-nm for h < 0.5 mm).
#
# What is observable (rank of the along-d part; s(h) adds only 2nd-order information):
#  - probe frame: e and a first harmonic of ρ (ρ_j ← ρ_j − v·(cos θ_j, sin θ_j), e ← e + v)
#    leave every e·q_i + ρ_j unchanged — an asymmetric pre-travel k = (δ+ − δ−)/2 turns with the
#    spindle and pushes the ball along d exactly like an eccentricity does, in every direction.
#    They cannot be separated by any set of directions or spindle angles, so the convention
#    Σ_j ρ_j·(cos θ_j, sin θ_j) = 0 puts the first harmonic into the skew: stored skew = e − k
#    (the manual's (m180 − m0)/2 for the 4-direction case), trigger magnitudes per axis equal.
#    The ring centre M *is* observable once two spindle angles differ (it does not turn) — this
#    is how the 180° pass observes k: every later touch is then exact, in every direction.
#  - machine frame: e turns with the spindle, ρ does not, so e is observable (two spindle
#    angles), but M·d_i and a first harmonic of the machine-fixed ρ are the same function of the
#    direction: with an unknown centre the convention puts k into the centre (reported centre =
#    M + k, trigger magnitudes per axis equal; a later touch along ±j is off by k_j) and the
#    result says so (center_observable False). With a known centre all ρ_j are free: X+ ≠ X−.
#  - one spindle angle only: M and e (probe frame) resp. M, e and k (machine frame) are one
#    first harmonic -> NEEDS_SPOS, unless the centre or the skew is given.
#  - the inseparability is exact only along the travel. Across it the two differ: the
#    eccentricity moves the ball sideways, the pre-travel does not. So (a) a later touch at
#    oblique incidence α on a flat face (a part turned by α against the probing axes) keeps a
#    systematic error up to |k|·sin α along the face normal under the convention (0.33 µm for
#    k = 1.5 µm at 12.5°), and (b) chords off the ring centre (oblique incidence on the ring
#    wall, ring_program chord_offset) observe k: ``first_harmonic="estimate"`` then drops the
#    convention, skew = e, centre = M in both frames, X+ ≠ X− (needs chords with |h| of the order
#    of (R − r)/2, else CIRCLE_UNDETERMINED). It relies on the pre-travel acting along the
#    travel at oblique incidence (the simulator's model); a real probe whose trigger follows
#    the contact-force direction must be checked against it first — hence not the default.
# The chord offsets h (start off-centre, the 180° pass 2e off-centre) use the estimated skew and
# centre; under the convention an unobservable k therefore leaks in by at most
# |k|·max|h|/(R − r) (0.03 µm for k = 1.5 µm, h = 0.2 mm, R − r = 10.5 mm). Exact (to rounding)
# when k = 0, or the centre is known (machine frame), or first_harmonic="estimate".
#
# Estimator: Gauss-Newton on Σ_i f_i², f_i = (rec_i − M)·d_i + e·q_i − (R − ρ_j) − s(h_i)
# (residual along d_i), the convention by a null-space parametrisation of the ρ block; starting
# from the linear solution (s = 0). Covariance σ²·T(J_zᵀJ_z)⁻¹Tᵀ, σ a priori (``sigma``) or
# σ̂ = sqrt(Σf²/dof). For the standard JOG program (search, 180°, 0°: 12 touches, probe frame)
# the variance of the correction a later axis-parallel touch inherits, e·q + ρ, is 17/48·σ² =
# 0.354σ² (calibrate_radius: 3/4·σ², it uses the 0° pass only); see docs/noise-bound.md.

PRETRAVEL_FRAMES = ("probe", "machine")
_ANGLE_TOL = 1e-6          # deg: touches whose direction classes differ by less are one class


@dataclass(frozen=True)
class RingTouch:
    """One raw ring touch: NC reference ``rec`` at the latch (WCS, no skew, no trigger values),
    unit travel ``direction`` (WCS, in the working plane) and the SPOS angle it was made at."""

    rec: FloatArray
    direction: FloatArray
    spindle_angle: float = 0.0
    label: str = ""


def _key_direction(key: str, plane: Plane) -> FloatArray:
    axis, sign = key[:-1], key[-1]
    if sign not in "+-" or axis not in (plane.first, plane.second):
        raise ValueError(f"ring pass key {key!r} is no plane-axis direction; give RingPass.directions")
    return (1.0 if sign == "+" else -1.0) * plane.unit(axis)


def ring_touches(point: RingCalibrationPoint, plane: Plane) -> tuple[RingTouch, ...]:
    """Every touch of a ring calibration: the centre search (SPOS 0°) and all passes."""
    passes = [p for p in (point.search, *point.passes) if p is not None]
    out = []
    for ring_pass in passes:
        for key, rec in ring_pass.rec.items():
            d = ring_pass.directions.get(key)
            d = _key_direction(key, plane) if d is None else np.asarray(d, dtype=float)
            out.append(RingTouch(np.asarray(rec, dtype=float), d / np.linalg.norm(d),
                                 float(ring_pass.spindle_angle), f"SPOS {ring_pass.spindle_angle:g} {key}"))
    return tuple(out)


@dataclass(frozen=True)
class RingEstimate:
    """Result of ``estimate_ring`` (the model and its observability: comment block above).

    ``center`` (a, o) in the measuring WCS; ``skew`` machine X/Y at SPOS 0°, the eccentricity
    (``skew_effective`` False) or eccentricity − k (True, probe frame); ``angles``/``radii``:
    the direction classes (deg, in ``frame``; probe frame = machine frame at SPOS 0°) and their
    effective radii ρ_j; ``lobing``: the map through them. ``trigger``/``trigger_std``: the
    record's values for ±1st/±2nd plane axis at SPOS 0° (t(+) = −ρ, t(−) = +ρ, jog-measuring §5.1) and their
    std; ``surface_std``: std of the correction e·q + ρ a later touch in that direction inherits
    (what the set-up error sees). ``residuals``: per touch, along its direction, input order.
    ``covariance`` of ``param_names`` (fixed parameters have zero rows).
    """

    frame: str
    diameter: float
    plane_axes: tuple[str, str]
    center: FloatArray
    center_observable: bool
    skew: FloatArray
    skew_effective: bool
    angles: FloatArray
    radii: FloatArray
    lobing: LobingMap
    trigger: dict[str, float]
    trigger_std: dict[str, float]
    surface_std: dict[str, float]
    effective_diameter: float
    effective_diameter_std: float
    residuals: FloatArray
    form_error: float
    n: int
    dof: int
    sigma: float
    covariance: FloatArray | None
    param_names: tuple[str, ...]
    max_chord_offset: float
    notes: tuple[str, ...]
    ball_diameter: float = 0.0              # the ball diameter the sagittas used: measured or nominal
    ball_diameter_estimated: bool = False   # True: measured from the chords (RADIUS_MIN_LEVER)
    ball_diameter_std: float = 0.0

    @property
    def rms(self) -> float:
        return float(np.sqrt(np.mean(self.residuals ** 2))) if len(self.residuals) else 0.0

    @property
    def sigma_hat(self) -> float:
        return float(np.sqrt(np.sum(self.residuals ** 2) / self.dof)) if self.dof > 0 else float("nan")

    @property
    def std(self) -> dict[str, float]:
        if self.covariance is None:
            return {name: float("nan") for name in self.param_names}
        d = np.sqrt(np.clip(np.diag(self.covariance), 0.0, None))
        return {name: float(v) for name, v in zip(self.param_names, d, strict=True)}

    def values_json(self) -> dict[str, Any]:
        """JSON-ready numbers: the calibrate_radius keys plus quality and observability."""
        std = self.std
        first, second = self.plane_axes
        return {
            "center": {first: float(self.center[0]), second: float(self.center[1])},
            "skew": {"X": float(self.skew[0]), "Y": float(self.skew[1])},
            "trigger": {k: float(v) for k, v in self.trigger.items()},
            "effective_diameter": float(self.effective_diameter),
            "std": {"center": {first: std["center_a"], second: std["center_o"]},
                    "skew": {"X": std["skew_X"], "Y": std["skew_Y"]},
                    "trigger": dict(self.trigger_std), "surface": dict(self.surface_std),
                    "effective_diameter": float(self.effective_diameter_std)},
            "residuals": [float(r) for r in self.residuals],
            "rms": self.rms, "form_error": float(self.form_error), "n": int(self.n),
            "sigma_hat": self.sigma_hat,
            "pretravel_frame": self.frame,
            "observable": {"center": bool(self.center_observable),
                           "skew": "eccentricity - k" if self.skew_effective else "eccentricity"},
            "notes": list(self.notes),
            "lobing": self.lobing.values_json(),
            "ball_diameter": {"value": float(self.ball_diameter), "measured": bool(self.ball_diameter_estimated),
                              "std": float(self.ball_diameter_std)},
        }


def _classes(angles: FloatArray) -> tuple[FloatArray, FloatArray]:
    """(class angle per class, class index per touch), circular clustering within _ANGLE_TOL."""
    centres: list[float] = []
    index = np.empty(len(angles), dtype=int)
    for i, a in enumerate(np.mod(angles, 360.0)):
        for j, c in enumerate(centres):
            if abs((a - c + 180.0) % 360.0 - 180.0) < _ANGLE_TOL:
                index[i] = j
                break
        else:
            centres.append(0.0 if a > 360.0 - _ANGLE_TOL else float(a))
            index[i] = len(centres) - 1
    return np.array(centres), index


def _null_space(c: FloatArray, m: int) -> FloatArray:
    if c.size == 0:
        return np.eye(m)
    _, sv, vt = np.linalg.svd(c)
    rank = int(np.sum(sv > 1e-9 * max(1.0, sv[0])))
    return vt[rank:].T


@dataclass(frozen=True)
class _RingDesign:
    """The touches of a ring calibration in plane coordinates (a, o): latch ``rec``, travel ``d``
    and its normal ``d_perp`` (WCS), the travel as the probe sees it ``q``/``q_perp`` (machine
    X/Y turned back by SPOS), the direction in the pre-travel's frame ``theta`` (deg) and SPOS."""

    rec: FloatArray
    d: FloatArray
    d_perp: FloatArray
    q: FloatArray
    q_perp: FloatArray
    theta: FloatArray
    phis: FloatArray


def _ring_design(touches: Sequence[RingTouch], plane: Plane, frame: str,
                 to_mcs: Callable[[FloatArray], FloatArray]) -> _RingDesign:
    n = len(touches)
    rec, d, q, q_perp = np.empty((n, 2)), np.empty((n, 2)), np.empty((n, 2)), np.empty((n, 2))
    theta, phis = np.empty(n), np.empty(n)
    for i, t in enumerate(touches):
        rec[i] = plane.to_aop(np.asarray(t.rec, dtype=float))[:2]
        d_aop = plane.to_aop(checks.unit_vector(t.direction))
        if abs(d_aop[2]) > 1e-9:
            raise ValueError(f"ring touch {t.label or i} does not travel in the working plane")
        d[i] = checks.unit_vector(d_aop[:2])
        d_mcs = to_mcs(plane.to_xyz([d[i, 0], d[i, 1], 0.0]))
        dp_mcs = to_mcs(plane.to_xyz([-d[i, 1], d[i, 0], 0.0]))
        if abs(d_mcs[2]) > 1e-9:
            raise ValueError("ring touches must be perpendicular to the spindle axis (machine Z)")
        phi = float(t.spindle_angle)
        turn = rot_z(-phi)
        q[i], q_perp[i] = (turn @ d_mcs)[:2], (turn @ dp_mcs)[:2]
        theta_m = float(np.degrees(np.arctan2(d_mcs[1], d_mcs[0])))
        theta[i] = theta_m - phi if frame == "probe" else theta_m
        phis[i] = phi % 360.0
    return _RingDesign(rec, d, np.column_stack([-d[:, 1], d[:, 0]]), q, q_perp, theta, phis)


class _RingModel:
    """Residual along each touch's travel and its Jacobian (the model in the comment block above).

    Parameters x = (M_a, M_o, e_X, e_Y, ρ_1..ρ_m, r): ring centre, skew at SPOS 0°, the effective
    radius of each direction class, and the ball radius r, which enters only the sagitta
    s(h) = √((R − r)² − h²) − (R − r) of a chord h off the centre (∂f/∂r = (R − r)/√(…) − 1)."""

    def __init__(self, design: _RingDesign, classes: FloatArray, m: int, big_r: float):
        self.design, self.big_r, self.m = design, big_r, m
        self.classes = classes
        n = len(classes)
        self.onehot = np.zeros((n, m))
        self.onehot[np.arange(n), classes] = 1.0

    @property
    def n_par(self) -> int:
        return 5 + self.m

    def chord_offsets(self, x: FloatArray) -> FloatArray:
        g = self.design
        return np.asarray(np.sum((g.rec - x[:2]) * g.d_perp, axis=1) + g.q_perp @ x[2:4], dtype=float)

    def residual_jac(self, x: FloatArray, sagitta: bool = True) -> tuple[FloatArray, FloatArray]:
        g = self.design
        mc, e, rho, r = x[:2], x[2:4], x[4:4 + self.m], float(x[4 + self.m])
        a_s = self.big_r - r
        h = self.chord_offsets(x)
        n = len(h)
        if sagitta:
            if np.any(np.abs(h) >= a_s):
                raise MeasuringError(alarms.CIRCLE_UNDETERMINED, "ring touches miss the ring (chord offset)")
            root = np.sqrt(a_s * a_s - h * h)
            s, ds, ds_r = root - a_s, -h / root, a_s / root - 1.0
        else:
            s, ds, ds_r = np.zeros(n), np.zeros(n), np.zeros(n)
        f = np.sum((g.rec - mc) * g.d, axis=1) + g.q @ e - (self.big_r - rho[self.classes]) - s
        jac = np.column_stack([-g.d + ds[:, None] * g.d_perp, g.q - ds[:, None] * g.q_perp, self.onehot, ds_r])
        return f, jac


def _rank_ok(jz: FloatArray) -> bool:
    sv = np.linalg.svd(jz, compute_uv=False)
    return bool(len(sv) == jz.shape[1] and sv[-1] > 1e-9 * max(1.0, sv[0]))


def _gauss_newton(model: _RingModel, x: FloatArray, t_mat: FloatArray) -> FloatArray:
    """Σ f² over the columns of ``t_mat``; the chord term is a small correction: 2–4 steps."""
    for _ in range(30):
        f, jac = model.residual_jac(x)
        step, *_ = np.linalg.lstsq(jac @ t_mat, -f, rcond=None)
        x = x + t_mat @ step
        if np.linalg.norm(step) <= 1e-13 * max(model.big_r, 1.0):
            break
    return x


def _free_columns(n_par: int, m: int, center: object, skew: object, null: FloatArray,
                  radius_free: bool) -> FloatArray:
    """The free directions of the parameter space: centre and skew unless given, the ρ block
    (``null``: its convention), the ball radius when the chords observe it."""
    eye = np.eye(n_par)
    cols = ([eye[:, 0], eye[:, 1]] if center is None else []) + ([eye[:, 2], eye[:, 3]] if skew is None else [])
    cols += [np.concatenate([np.zeros(4), col, [0.0]]) for col in null.T]
    if radius_free:
        cols.append(eye[:, n_par - 1])
    return np.column_stack(cols)


# The ball radius is estimated when the chords observe it to within this many σ of one touch
# (std of r̂ ≤ σ/lever): chords halfway out (h = (R − r)/2, the cal_chords program) give ≈ 3.6σ;
# centre chords (|h| < 1 mm) leave it at the nominal, where a wrong nominal costs ≤ h²Δr/2(R−r)².
RADIUS_MIN_LEVER = 0.1


def _radius_lever(model: _RingModel, x: FloatArray, t_mat: FloatArray) -> float:
    """Norm of the ball-radius column left after the other free columns explain what they can."""
    _f, jac = model.residual_jac(x)
    jz = jac @ t_mat
    col = jac[:, -1]
    coef, *_ = np.linalg.lstsq(jz, col, rcond=None)
    return float(np.linalg.norm(col - jz @ coef))


def _key_triggers(lobing: LobingMap, rho: FloatArray, plane: Plane, to_mcs: Callable[[FloatArray], FloatArray],
                  spread: Callable[[FloatArray], float], n_par: int
                  ) -> tuple[dict[str, float], dict[str, float], dict[str, float]]:
    """The record's trigger values for ±1st/±2nd plane axis at SPOS 0° (t(+) = −ρ, t(−) = +ρ,
    jog-measuring §5.1), their std and the std of the correction e·q + ρ a later touch inherits."""
    m = len(rho)
    trigger: dict[str, float] = {}
    trigger_std: dict[str, float] = {}
    surface_std: dict[str, float] = {}
    for axis in (plane.first, plane.second):
        for sign in (1.0, -1.0):
            key = f"{axis}{'+' if sign > 0 else '-'}"
            d_mcs = to_mcs(sign * plane.unit(axis))
            w = lobing.weights(lobing.frame_angle(d_mcs, 0.0))
            rho_key = float(w @ rho)
            trigger[key] = -rho_key if sign > 0 else rho_key
            c_rho = np.concatenate([np.zeros(4), w, np.zeros(n_par - 4 - m)])
            trigger_std[key] = spread(c_rho)
            c_skew = np.concatenate([[0.0, 0.0], d_mcs[:2], np.zeros(n_par - 4)])
            surface_std[key] = spread(c_rho + c_skew)
    return trigger, trigger_std, surface_std


def _ring_notes(frame: str, first_harmonic: str, skew_effective: bool, center_observable: bool,
                constrained: bool, max_h: float, a_s: float, radius_free: bool, r_nom: float, r_hat: float) -> list[str]:
    notes = []
    if first_harmonic == "estimate":
        notes.append("first harmonic of the pre-travel estimated from the chord offsets (oblique "
                     "incidence): skew is the eccentricity, X+ and X− are stored apart")
    if skew_effective:
        notes.append("skew = eccentricity - k: the first harmonic k of the pre-travel (k = (δ+ − δ−)/2 "
                     "per axis) turns with the spindle and moves the ball along every probing direction "
                     "exactly like an eccentricity; the two cannot be separated, and the stored pair "
                     "(skew, trigger values) is exact for every direction at any spindle angle")
    if not center_observable:
        notes.append("ring centre = M + k (k = (δ+ − δ−)/2 per axis, pre-travel fixed to the machine "
                     "axes): not separable from the centre in a ring of unknown centre; the trigger "
                     "values are the symmetric parts and later positions probed along ±j are off by "
                     "k_j. Calibrate with a known centre (centre=...) to store X+ and X− apart")
    if constrained and max_h > 0.0:
        notes.append(f"chord offsets up to {max_h:.4f} mm: an unobservable k "
                     f"leaks into the sagitta term by at most |k|·{max_h / a_s:.2e}")
    if radius_free:
        notes.append(f"ball diameter {2.0 * r_hat:.4f} mm measured from the chord sagittas "
                     f"(nominal {2.0 * r_nom:.4f} mm)")
    return notes


def _ring_input(diameter: float, probe: ProbeRecord, frame: str, first_harmonic: str,
                ball: str) -> tuple[float, float]:
    """(ring radius R, nominal ball radius r) after the checks of ``estimate_ring``'s options."""
    if frame not in PRETRAVEL_FRAMES:
        raise ValueError(f"frame must be one of {PRETRAVEL_FRAMES}, got {frame!r}")
    if first_harmonic not in ("convention", "estimate"):
        raise ValueError(f"first_harmonic must be 'convention' or 'estimate', got {first_harmonic!r}")
    if ball not in ("auto", "nominal"):
        raise ValueError(f"ball must be 'auto' or 'nominal', got {ball!r}")
    big_r = float(diameter) / 2.0
    if not big_r > 0.0:
        raise ValueError(f"ring diameter must be > 0, got {diameter}")
    r_nom = probe.ball_diameter / 2.0
    if not big_r - r_nom > 0.0:
        raise ValueError(f"ring diameter {diameter} must exceed the ball diameter {probe.ball_diameter}")
    return big_r, r_nom


def _ring_fixed(n_par: int, r_nom: float, plane: Plane, center: npt.ArrayLike | None,
                skew: npt.ArrayLike | None) -> FloatArray:
    """The fixed parameters: a given centre/skew, the nominal ball radius (the start value)."""
    x_fixed = np.zeros(n_par)
    x_fixed[-1] = r_nom
    if center is not None:
        c_arr = np.asarray(center, dtype=float)
        x_fixed[:2] = plane.to_aop(c_arr)[:2] if c_arr.shape == (3,) else c_arr[:2]
    if skew is not None:
        x_fixed[2:4] = np.asarray(skew, dtype=float)[:2]
    return x_fixed


def _solve_ring(model: _RingModel, design: Any, x_fixed: FloatArray, class_angles: Any,
                center: npt.ArrayLike | None, skew: npt.ArrayLike | None, constrained: bool,
                first_harmonic: str, ball: str) -> tuple[FloatArray, FloatArray, bool, bool]:
    """Linear start (s = 0), then Gauss-Newton with the chord offsets; the first harmonic apart
    (``first_harmonic`` "estimate"), the ball radius where the chords observe it.
    -> (x, free columns, still constrained, ball radius estimated)."""
    m = len(class_angles)
    th_rad = np.radians(class_angles)
    null = _null_space(np.vstack([np.cos(th_rad), np.sin(th_rad)]), m) if constrained else np.eye(m)
    t_mat = _free_columns(model.n_par, m, center, skew, null, radius_free=False)
    f0, j0 = model.residual_jac(x_fixed, sagitta=False)
    if not _rank_ok(j0 @ t_mat):
        if len(set(np.round(design.phis, 6))) < 2 and center is None and skew is None:
            raise MeasuringError(alarms.NEEDS_SPOS, "ring centre and skew cannot be told apart at one spindle "
                                 "orientation: calibrate at 0° and 180° (SPOS), or give the centre")
        raise MeasuringError(alarms.CIRCLE_UNDETERMINED, "the ring touches do not determine centre, skew "
                             "and trigger values (directions must span the plane)")
    z, *_ = np.linalg.lstsq(j0 @ t_mat, -f0, rcond=None)
    x = _gauss_newton(model, x_fixed + t_mat @ z, t_mat)
    if constrained and first_harmonic == "estimate":
        # the chord offsets carry the first harmonic apart from skew (probe frame) or centre
        # (machine frame): Gauss-Newton on the full model from the convention's solution
        t_full = _free_columns(model.n_par, m, center, skew, np.eye(m), radius_free=False)
        _f, jac = model.residual_jac(x)
        if not _rank_ok(jac @ t_full):
            raise MeasuringError(alarms.CIRCLE_UNDETERMINED, "skew and the first harmonic of the pre-travel "
                                 "cannot be told apart: probe chords off the ring centre (oblique incidence)")
        t_mat, constrained, null = t_full, False, np.eye(m)
        x = _gauss_newton(model, x, t_mat)
    radius_free = ball == "auto" and _radius_lever(model, x, t_mat) >= RADIUS_MIN_LEVER
    if radius_free:        # the chord sagittas observe the ball: the nominal is only the start value
        t_mat = _free_columns(model.n_par, m, center, skew, null, radius_free=True)
        x = _gauss_newton(model, x, t_mat)
    return x, t_mat, constrained, radius_free


def _ring_covariance(f: FloatArray, jac: FloatArray, t_mat: FloatArray, dof: int,
                     sigma: float | None) -> tuple[float, FloatArray | None]:
    """(σ used: a-priori or σ̂ from the residuals, covariance of all parameters or None)."""
    jz = jac @ t_mat
    s_used = float(sigma) if sigma is not None else (float(np.sqrt(np.sum(f * f) / dof)) if dof > 0 else float("nan"))
    cov = None
    if np.isfinite(s_used):
        cov = t_mat @ (s_used * s_used * np.linalg.inv(jz.T @ jz)) @ t_mat.T
        cov = 0.5 * (cov + cov.T)
    return s_used, cov


def _ring_touches(touches: Sequence[RingTouch]) -> tuple[RingTouch, ...]:
    """The touches, 4 or more (CIRCLE_PARAMETERS)."""
    touches = tuple(touches)
    if len(touches) < 4:
        raise MeasuringError(alarms.CIRCLE_PARAMETERS,
                             f"a ring calibration needs 4 or more touches, got {len(touches)}")
    return touches


def _ring_model(touches: tuple[RingTouch, ...], plane: Plane, frame: str, wcs2bcs: Frame | None, big_r: float
                ) -> tuple[Callable[[FloatArray], FloatArray], _RingDesign, FloatArray, _RingModel]:
    """The direction map WCS -> MCS, the design of the touches, their direction classes' angles
    and the least-squares model."""
    to_mcs: Callable[[FloatArray], FloatArray] = (lambda v: v) if wcs2bcs is None else wcs2bcs.dir_child2parent
    design = _ring_design(touches, plane, frame, to_mcs)
    class_angles, cls = _classes(design.theta)
    return to_mcs, design, class_angles, _RingModel(design, cls, len(class_angles), big_r)


def _ring_observability(frame: str, center: npt.ArrayLike | None, skew: npt.ArrayLike | None,
                        constrained: bool) -> tuple[bool, bool]:
    """(the centre is observable, the skew found is the effective one)."""
    center_observable = not (frame == "machine" and center is None) or not constrained
    skew_effective = frame == "probe" and skew is None and constrained
    return center_observable, skew_effective


def _spread(cov: FloatArray | None, c: FloatArray) -> float:
    """The standard deviation of c·x (nan without a covariance)."""
    return float("nan") if cov is None else float(np.sqrt(max(float(c @ cov @ c), 0.0)))


def estimate_ring(touches: Sequence[RingTouch], diameter: float, probe: ProbeRecord, plane: Plane, *,
                  frame: str = "probe", center: npt.ArrayLike | None = None, skew: npt.ArrayLike | None = None,
                  wcs2bcs: Frame | None = None,
                  sigma: float | None = None, first_harmonic: str = "convention",
                  ball: str = "auto") -> RingEstimate:
    """Ring centre, skew, every direction's effective radius and (when the chords observe it)
    the ball radius from all touches, least squares.

    ``touches``: RingTouch (``ring_touches`` of a RingCalibrationPoint, or any set: n directions
    at any spindle angles). ``diameter``: the ring's known diameter. ``frame``: where the pre-
    travel lives, "probe" (turns with SPOS) or "machine" (wave-1 simulator). ``center``: a known
    ring centre (WCS point or (a, o)), ``skew``: a known skew (machine X/Y at 0°) — both optional,
    they remove the corresponding unknowns. ``wcs2bcs``: measuring WCS -> BCS (= MCS). ``sigma``:
    a-priori σ per touch for the covariance (else σ̂ from the residuals). ``first_harmonic``:
    "convention" (default: the first harmonic of the pre-travel goes into skew resp. centre) or
    "estimate" (separate it through the chord offsets: needs oblique chords). ``ball``: "auto"
    (estimate the ball radius when the chords observe it, RADIUS_MIN_LEVER, else the nominal)
    or "nominal" (``probe.ball_diameter``; the nominal is the start value either way).

    Model, observability, convention and accuracy: the comment block above this class. Failures:
    ValueError for bad input; MeasuringError NEEDS_SPOS when one spindle angle leaves centre and
    skew inseparable, CIRCLE_UNDETERMINED for any other rank defect (e.g. directions on one axis).
    """
    big_r, r_nom = _ring_input(diameter, probe, frame, first_harmonic, ball)
    touches = _ring_touches(touches)
    n = len(touches)
    to_mcs, design, class_angles, model = _ring_model(touches, plane, frame, wcs2bcs, big_r)
    m = len(class_angles)
    names = ("center_a", "center_o", "skew_X", "skew_Y", *[f"rho_{a:g}" for a in class_angles], "ball_radius")

    x_fixed = _ring_fixed(model.n_par, r_nom, plane, center, skew)
    constrained = (frame == "probe" and skew is None) or (frame == "machine" and center is None)
    x, t_mat, constrained, radius_free = _solve_ring(model, design, x_fixed, class_angles, center, skew,
                                                     constrained, first_harmonic, ball)
    f, jac = model.residual_jac(x)
    dof = n - t_mat.shape[1]
    s_used, cov = _ring_covariance(f, jac, t_mat, dof, sigma)

    mc, e, rho, r_hat = x[:2], x[2:4], x[4:4 + m], float(x[-1])
    axial = abs(centre_trigger_value(probe, -plane.infeed_unit, plane))
    lobing = fit_lobing_map(class_angles, rho, frame=frame, skew=e,
                            covariance=None if cov is None else cov[4:4 + m, 4:4 + m],
                            include_first=not constrained, axial_radius=axial)

    spread = functools.partial(_spread, cov)
    trigger, trigger_std, surface_std = _key_triggers(lobing, rho, plane, to_mcs, spread, model.n_par)
    max_h = float(np.max(np.abs(model.chord_offsets(x))))
    center_observable, skew_effective = _ring_observability(frame, center, skew, constrained)
    notes = _ring_notes(frame, first_harmonic, skew_effective, center_observable, constrained, max_h,
                        big_r - r_nom, radius_free, r_nom, r_hat)
    return RingEstimate(
        frame=frame, diameter=float(diameter), plane_axes=(plane.first, plane.second), center=mc.copy(),
        center_observable=center_observable, skew=e.copy(), skew_effective=skew_effective,
        angles=class_angles, radii=rho.copy(), lobing=lobing, trigger=trigger, trigger_std=trigger_std,
        surface_std=surface_std, effective_diameter=2.0 * lobing.mean_radius,
        effective_diameter_std=2.0 * spread(np.concatenate([np.zeros(4), lobing.weights_mean(), [0.0]])),
        residuals=f, form_error=float(f.max() - f.min()), n=n, dof=dof, sigma=s_used, covariance=cov,
        param_names=names, max_chord_offset=max_h, notes=tuple(notes),
        ball_diameter=2.0 * r_hat, ball_diameter_estimated=radius_free,
        ball_diameter_std=2.0 * spread(np.eye(model.n_par)[-1]) if radius_free else 0.0)


def calibrate_ring(point: RingCalibrationPoint, probe: ProbeRecord, plane: Plane,
                   wcs2bcs: Frame | None = None, *, frame: str = "probe", center: npt.ArrayLike | None = None,
                   sigma: float | None = None, first_harmonic: str = "convention") -> tuple[ProbeRecord, dict[str, Any]]:
    """``calibrate_radius`` by least squares from every touch (search + all passes).

    Same inputs and the same result keys (``center``, ``skew``, ``trigger``,
    ``trigger_difference``, ``effective_diameter``, ``effective_diameter_difference``) plus
    ``std``, ``residuals``, ``rms``, ``form_error``, ``n``, ``sigma_hat``, ``pretravel_frame``,
    ``observable``, ``notes``, ``lobing``, ``ball_diameter`` (RingEstimate.values_json) and
    ``pretravel_frame_decision``. ``frame``: "probe" (default: the real probe and the wave-2
    simulator), "machine" (wave-1) or "auto" (choose_pretravel_frame, fallback "probe"). ``center``: a
    known ring centre (WCS), optional. ``first_harmonic``: as estimate_ring ("estimate" with a
    ring_program chord_offset). The record gets the trigger values of ±1st/±2nd axis,
    the skew (machine X/Y at 0°) and the effective diameter 2·c0 (mean over all directions;
    the 4-direction value equals calibrate_radius's 2·mean|t|).
    """
    touches = ring_touches(point, plane)
    decision = None
    if frame == "auto":
        est, decision = choose_pretravel_frame(touches, point.diameter, probe, plane, center=center,
                                               wcs2bcs=wcs2bcs, sigma=sigma, first_harmonic=first_harmonic)
    else:
        est = estimate_ring(touches, point.diameter, probe, plane, frame=frame,
                            center=center, wcs2bcs=wcs2bcs, sigma=sigma, first_harmonic=first_harmonic)
    for key, value in est.trigger.items():
        if (value < 0.0) != key.endswith("+") or value == 0.0:
            raise MeasuringError(alarms.SAFE_AREA, f"trigger value {key} = {value:.4f} has the wrong sign: "
                                 "check the ring diameter")
    new_triggers = dict(probe.trigger)
    new_triggers.update(est.trigger)
    record = replace(probe, trigger=new_triggers, skew=(float(est.skew[0]), float(est.skew[1])),
                     effective_diameter=float(est.effective_diameter), calibrated_radius=True)
    values = est.values_json()
    values["trigger_difference"] = {k: (None if k not in probe.trigger else float(v - probe.trigger[k]))
                                    for k, v in est.trigger.items()}
    values["effective_diameter_difference"] = (None if probe.effective_diameter <= 0.0
                                               else float(est.effective_diameter - probe.effective_diameter))
    values["pretravel_frame_decision"] = (decision.values_json() if decision is not None
                                          else {"frame": frame, "decided": False, "margin": None, "rss": {}})
    return record, values


# --- does the pre-travel turn with the spindle? (issue [probe-health] item 5) ----------------
#
# The two models differ only where a spindle angle other than 0° meets an asymmetric pre-travel:
# in the probe frame the 180° pass sees the lobing turned by 180°, in the machine frame it does
# not. With chords through the centre both explain the latches equally (the first harmonic k goes
# into skew or centre alike: same stored values, nothing to decide); off-centre chords separate
# them, and a wrong choice leaves k in every later position (the 3.3×/6.2× the noise
# bound). So both are fitted and compared by their residuals: Akaike's criterion
# Σf²/σ² + 2p with σ the a-priori noise or the better fit's σ̂ (at least 1 nm, the latch
# resolution), decided when the worse model's criterion is larger by DECISION_MARGIN (≈ 3σ).

DECISION_MARGIN = 9.0
_SIGMA_FLOOR = 1e-6         # mm: below this the residuals are rounding, not evidence


@dataclass(frozen=True)
class FrameDecision:
    """Which pre-travel model the ring data support: ``frame`` (used), ``decided`` (the data
    told; False: they fit both within the noise, or only one could be fitted, and ``frame`` is
    the fallback), ``margin`` (criterion of the other model minus the chosen one), ``rss``."""

    frame: str
    decided: bool
    margin: float
    rss: dict[str, float]

    def values_json(self) -> dict[str, Any]:
        return {"frame": self.frame, "decided": self.decided,
                "margin": None if not np.isfinite(self.margin) else float(self.margin),
                "rss": {k: float(v) for k, v in self.rss.items()}}


def choose_pretravel_frame(touches: Sequence[RingTouch], diameter: float, probe: ProbeRecord, plane: Plane, *,
                           fallback: str = "probe", sigma: float | None = None, **kwargs: Any
                           ) -> tuple[RingEstimate, FrameDecision]:
    """``estimate_ring`` in both pre-travel frames; the estimate of the model the data support
    (comment block above) and the decision. ``fallback``: the frame used when they cannot tell.
    ``kwargs``: the other estimate_ring arguments (center, wcs2bcs, first_harmonic, ...)."""
    if fallback not in PRETRAVEL_FRAMES:
        raise ValueError(f"fallback must be one of {PRETRAVEL_FRAMES}, got {fallback!r}")
    fits: dict[str, RingEstimate] = {}
    failure: MeasuringError | None = None
    for frame in PRETRAVEL_FRAMES:
        try:
            fits[frame] = estimate_ring(touches, diameter, probe, plane, frame=frame, sigma=sigma, **kwargs)
        except MeasuringError as exc:
            failure = exc if frame == fallback or failure is None else failure
    if not fits and failure is not None:
        raise failure
    rss = {f: float(np.sum(est.residuals ** 2)) for f, est in fits.items()}
    if len(fits) == 1:
        (only,) = fits
        return fits[only], FrameDecision(only, False, float("nan"), rss)
    best_dof = {f: est.dof for f, est in fits.items()}
    lowest = min(rss, key=lambda f: rss[f])
    noise = float(sigma) if sigma is not None else (
        np.sqrt(rss[lowest] / best_dof[lowest]) if best_dof[lowest] > 0 else 0.0)
    noise = max(noise, _SIGMA_FLOOR)
    score = {f: rss[f] / noise ** 2 + 2.0 * (est.n - est.dof) for f, est in fits.items()}
    best = min(score, key=lambda f: score[f])
    other = next(f for f in fits if f != best)
    margin = score[other] - score[best]
    if margin > DECISION_MARGIN:
        return fits[best], FrameDecision(best, True, margin, rss)
    return fits[fallback], FrameDecision(fallback, False, margin, rss)


# --- the noise bound of a calibrated set-up (docs/noise-bound.md) ----------------------------

def ideal_ring_touches(n_directions: int = 4, spindle_angles: Sequence[float] = (0.0, 180.0, 0.0), *, diameter: float = 25.0,
                       ball_diameter: float = 4.0, start_deg: float = 0.0) -> tuple[RingTouch, ...]:
    """The linear design of a ring calibration: chords through the centre (0, 0) of an ideal
    ring (G17, no pre-travel, no skew), ``n_directions`` 360°/n apart from ``start_deg`` at
    each of ``spindle_angles``. Default: the JOG program (search at 0°, passes at 180° and 0°)."""
    reach = diameter / 2.0 - ball_diameter / 2.0
    out = []
    for phi in spindle_angles:
        for k in range(int(n_directions)):
            a = np.radians(start_deg + 360.0 * k / n_directions)
            d = np.array([np.cos(a), np.sin(a), 0.0])
            out.append(RingTouch(reach * d, d, float(phi), f"SPOS {phi:g} {np.degrees(a):g}"))
    return tuple(out)


def calibration_variances(touches: Sequence[RingTouch] | None = None, *, frame: str = "probe",
                          diameter: float = 25.0, ball_diameter: float = 4.0,
                          center: npt.ArrayLike | None = None) -> dict[str, dict[str, float] | float]:
    """Variances in units of σ² (σ = the noise of one touch) of what a ring calibration stores:
    ``surface`` (the correction skew·d̂ + ρ a later touch along ±1st/±2nd inherits — what the
    set-up sees), ``trigger``, ``center``, ``skew``, ``effective_diameter``. ``touches``: the
    design (default ``ideal_ring_touches()``: the JOG program, 12 touches); estimator
    ``estimate_ring`` with σ = 1. The JOG program, probe frame: surface 17/48, trigger 1/6,
    centre and skew 3/16 (docs/noise-bound.md jog-measuring §2)."""
    touches = ideal_ring_touches(diameter=diameter, ball_diameter=ball_diameter) if touches is None else touches
    est = estimate_ring(touches, diameter, ProbeRecord(ball_diameter=ball_diameter), PLANES["G17"],
                        frame=frame, center=center, sigma=1.0)
    std = est.std
    return {"surface": {k: v * v for k, v in est.surface_std.items()},
            "trigger": {k: v * v for k, v in est.trigger_std.items()},
            "center": {"X": std["center_a"] ** 2, "Y": std["center_o"] ** 2},
            "skew": {"X": std["skew_X"] ** 2, "Y": std["skew_Y"] ** 2},
            "effective_diameter": est.effective_diameter_std ** 2}


def _ideal_jog_point(diameter: float, ball_diameter: float) -> RingCalibrationPoint:
    """The JOG ring program on an ideal ring: chords through the centre (0, 0), G17."""
    reach = diameter / 2.0 - ball_diameter / 2.0
    recs = {"X+": np.array([reach, 0.0, 0.0]), "X-": np.array([-reach, 0.0, 0.0]),
            "Y+": np.array([0.0, reach, 0.0]), "Y-": np.array([0.0, -reach, 0.0])}
    passes = [RingPass(angle, {k: v.copy() for k, v in recs.items()}) for angle in (0.0, 180.0, 0.0)]
    return RingCalibrationPoint(diameter, passes[0], (passes[1], passes[2]))


def calibration_jacobian(estimator: str = "ls", *, diameter: float = 25.0, ball_diameter: float = 4.0,
                         frame: str = "probe") -> dict[str, Any]:
    """How the stored values respond to the noise of each of the 12 touches of the JOG ring
    program (search, 180°, 0°; rows: skew X, skew Y, then ρ(X+), ρ(X−), ρ(Y+), ρ(Y−) with
    ρ = ∓t; columns: the touches in ring_touches order, a latch 1 mm further along its
    direction). ``estimator``: "ls" (calibrate_ring) or "calibrate_radius". Both are linear
    in the latches here, so this is exact (finite difference on an ideal ring); the stored
    values' covariance is σ²·G·Gᵀ."""
    point = _ideal_jog_point(diameter, ball_diameter)
    probe = ProbeRecord(ball_diameter=ball_diameter)
    keys = ("X+", "X-", "Y+", "Y-")

    def stored(pt: RingCalibrationPoint) -> FloatArray:
        if estimator == "ls":
            record, _ = calibrate_ring(pt, probe, PLANES["G17"], frame=frame)
        elif estimator == "calibrate_radius":
            record, _ = calibrate_radius(pt, probe, PLANES["G17"])
        else:
            raise ValueError(f"estimator must be 'ls' or 'calibrate_radius', got {estimator!r}")
        rho = [-record.trigger[k] if k.endswith("+") else record.trigger[k] for k in keys]
        return np.array([record.skew[0], record.skew[1], *rho])

    base = stored(point)
    eps = 1e-6
    cols = []
    passes = (point.search, *point.passes)
    for n_pass, ring_pass in enumerate(passes):
        for key in keys:
            d = _key_direction(key, PLANES["G17"])
            moved = dict(ring_pass.rec)
            moved[key] = moved[key] + eps * d
            new = [p if i != n_pass else RingPass(p.spindle_angle, moved) for i, p in enumerate(passes)]
            cols.append((stored(RingCalibrationPoint(diameter, new[0], (new[1], new[2]))) - base) / eps)
    return {"matrix": np.column_stack(cols), "rows": ("skew_X", "skew_Y", *[f"rho_{k}" for k in keys])}


def _corner_sensitivities(jac: FloatArray, rot: FloatArray) -> tuple[FloatArray, FloatArray]:
    """ξ = A_cal·ν_cal + A_touch·ν_touch over (12 calibration touches, P1, P2, P3): (A_cal, A_touch)
    of the corner's touches (P1, P2 travel +Y, P3 +X) with the edge normals turned by ``rot``."""
    n1, n2 = rot @ np.array([0.0, 1.0]), rot @ np.array([1.0, 0.0])
    travel = {"Y+": np.array([0.0, 1.0]), "X+": np.array([1.0, 0.0])}
    row = {"X+": 2, "Y+": 4}
    a_cal = np.zeros((3, jac.shape[1]))
    a_touch = np.zeros((3, 3))
    for i, (normal, key) in enumerate(((n1, "Y+"), (n1, "Y+"), (n2, "X+"))):
        cos_t = float(normal @ travel[key])
        a_cal[i] = normal @ jac[0:2] + cos_t * jac[row[key]]
        a_touch[i, i] = cos_t
    return a_cal, a_touch


def _corner_map(t1c: float, t2c: float, u3c: float, rot: FloatArray) -> tuple[FloatArray, FloatArray]:
    """ξ -> (δX, δY, δθ) as (B, M): M gives (δa', δo', δθ) from ξ, B turns (δa', δo') by ``rot``."""
    length = t2c - t1c
    m = np.array([[-u3c / length, u3c / length, 1.0],
                  [t2c / length, -t1c / length, 0.0],
                  [-1.0 / length, 1.0 / length, 0.0]])
    big = np.zeros((3, 3))
    big[:2, :2] = rot
    big[2, 2] = 1.0
    return big, m


def setup_noise_bound(sigma: float, *, t1: float = 30.0, t2: float = 150.0, u3: float = 40.0,
                      rotation_deg: float = 0.0, standoff: float = 0.0, estimator: str = "ls",
                      length_calibration: float = 1.0) -> dict[str, Any]:
    """Best-estimator noise bound of a set-up: ring calibration (JOG program, 12 touches) +
    length calibration + right-angled outside corner, position 1 (3 touches: P1, P2 travel +Y,
    P3 travel +X) + Z edge (1 touch), noise σ per touch along its travel (docs/noise-bound.md).

    Corner frame (origin at the corner, reference edge along +a', part turned by ``rotation_deg``
    against the machine axes): P1, P2 start at a' = t1, t2 and P3 at o' = u3, each ``standoff``
    in front of its edge (the flow tests: t1 = 30, t2 = 150, u3 = 40, standoff 12), so the
    contacts lie at t_i + standoff·tanγ and u3 − standoff·tanγ. ``estimator``: the calibration
    ("ls" = calibrate_ring, "calibrate_radius" = the 0°-pass values). ``length_calibration``:
    variance of L1 in σ² (one touch: 1).

    Per corner touch i with edge normal n̂_i (into the material) and travel d̂_i (cosθ = n̂·d̂):
    the shift of the found edge along n̂_i is ξ_i = n̂_i·Δe + cosθ·(Δρ(d̂_i) + ν_i) (skew error Δe,
    trigger error Δρ from the calibration's linear response, ν_i the touch noise). Then

        δθ = (ξ2 − ξ1)/L,  δo' = (t2·ξ1 − t1·ξ2)/L,  δa' = ξ3 + u3·δθ,  δ(X, Y) = R(γ)·(δa', δo'),
        δZ = ν_Z − ν_L.

    Returns ``std`` and ``mean_abs`` (std·√(2/π): what a mean of |error| over seeds estimates)
    per machine axis in mm, ``rotation_std`` / ``rotation_mean_abs`` in rad, the covariance of
    (X, Y, θ) and the part the calibration contributes.
    """
    if not (np.isfinite(sigma) and sigma >= 0.0):
        raise ValueError(f"sigma must be >= 0, got {sigma}")
    g = np.radians(rotation_deg)
    shift = standoff * np.tan(g)
    t1c, t2c, u3c = t1 + shift, t2 + shift, u3 - shift
    length = float(t2c - t1c)
    if length == 0.0:
        raise ValueError("P1 and P2 must differ (t1 != t2)")
    jac = calibration_jacobian(estimator)["matrix"]          # (6, 12): skew X/Y, ρ X+ X− Y+ Y−
    rot = np.array([[np.cos(g), -np.sin(g)], [np.sin(g), np.cos(g)]])
    a_cal, a_touch = _corner_sensitivities(jac, rot)
    big, m = _corner_map(t1c, t2c, u3c, rot)
    cov_cal = big @ m @ (a_cal @ a_cal.T) @ m.T @ big.T
    cov_touch = big @ m @ (a_touch @ a_touch.T) @ m.T @ big.T
    cov = sigma * sigma * (cov_cal + cov_touch)
    var_z = sigma * sigma * (1.0 + float(length_calibration))
    std = {"X": float(np.sqrt(cov[0, 0])), "Y": float(np.sqrt(cov[1, 1])), "Z": float(np.sqrt(var_z))}
    k = float(np.sqrt(2.0 / np.pi))
    rot_std = float(np.sqrt(cov[2, 2]))
    return {"std": std, "mean_abs": {a: k * v for a, v in std.items()},
            "rotation_std": rot_std, "rotation_mean_abs": k * rot_std,
            "covariance_xy_rotation": cov,
            "calibration_part": {"X": float(sigma * sigma * cov_cal[0, 0]), "Y": float(sigma * sigma * cov_cal[1, 1])},
            "estimator": estimator, "sigma": float(sigma),
            "layout": {"t1": float(t1c), "t2": float(t2c), "u3": float(u3c), "rotation_deg": float(rotation_deg)}}

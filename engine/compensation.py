"""Probe compensation: skew, trigger values, ball centre and surface points (measuring-math §5).

Trigger-value convention (measuring-math §5.1, manual §5.3.4): ``t_dir`` is the coordinate of
the probe *reference point* at switching (``rec + skew``; ``rec`` = nominal ball centre, or
the ball tip with _CBIT[14]=1) minus the surface coordinate along that axis. So with
``length_to_tip`` the calibrated −infeed value is ≈ 0 (the manual stores 0 there) and the
ball-centre-relative value is ``t + r`` on the infeed axis. ``Touch.ball_centre`` is always
the ball centre (fits use it), the surface point is the same either way.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from engine import checks
from engine.frames import Frame, rot_z
from engine.planes import PLANES, Plane
from engine.types import FloatArray, ProbeRecord, Touch

if TYPE_CHECKING:                      # engine.lobing needs nothing from here at run time
    from engine.lobing import LobingMap

_AXES = ("X", "Y", "Z")
_PARALLEL_TOL = 1e-9


def parallel_axis(direction_wcs: npt.ArrayLike) -> tuple[int, float] | None:
    """(axis index j, sign σ) when ``direction_wcs`` is axis-parallel within 1e-9, else None."""
    x, y, z = checks.unit_vector(direction_wcs, dim=3).tolist()
    ax, ay, az = abs(x), abs(y), abs(z)
    j = 0 if ax >= ay and ax >= az else (1 if ay >= az else 2)     # np.argmax: the first largest
    o1, o2 = (y, z) if j == 0 else ((x, z) if j == 1 else (x, y))
    if math.sqrt(o1 * o1 + o2 * o2) > _PARALLEL_TOL:
        return None
    return j, (1.0 if (x, y, z)[j] > 0 else -1.0)


def trigger_key(j: int, sign: float) -> str:
    """"X+", "Y-", ...: the WCS axis letter and the travel direction (measuring-math §0.1)."""
    return f"{_AXES[j]}{'+' if sign > 0 else '-'}"


def effective_radius(probe: ProbeRecord) -> float:
    """ρ = _WP[k,0]/2, the nominal ball radius while uncalibrated (measuring-math §5.3)."""
    if probe.effective_diameter > 0.0:
        return probe.effective_diameter / 2.0
    return probe.ball_diameter / 2.0


def centre_trigger_value(probe: ProbeRecord, direction_wcs: npt.ArrayLike, plane: Plane | None = None) -> float:
    """Axis-parallel trigger value relative to the ball centre: c_j − s_j (measuring-math §5.1).

    Stored values refer to the reference point; with ``length_to_tip`` the centre lies r above
    it along p̂ (measuring-math §0.1), hence + r·p̂_j. Uncalibrated: ideal ball, t(−)=+r, t(+)=−r.
    """
    axis = parallel_axis(direction_wcs)
    if axis is None:
        raise ValueError("trigger values exist only for axis-parallel directions")
    return _trigger_value_along(probe, axis, plane)


def _trigger_value_along(probe: ProbeRecord, axis: tuple[int, float], plane: Plane | None) -> float:
    """``centre_trigger_value`` for the axis and sign ``parallel_axis`` found (make_touch has them)."""
    j, sign = axis
    key = trigger_key(j, sign)
    r_nominal = probe.ball_diameter / 2.0
    if key not in probe.trigger:
        return -sign * r_nominal              # measuring-math §5.1 ideal probe
    shift = 0.0
    if probe.length_to_tip:
        infeed_unit = (plane or PLANES["G17"]).infeed_unit
        shift = r_nominal * float(infeed_unit[j])
    return float(probe.trigger[key]) + shift


def trigger_radius(probe: ProbeRecord, direction_wcs: npt.ArrayLike, plane: Plane | None = None) -> float:
    """|t(dir)| (ball-centre relative) for axis-parallel directions, ρ otherwise (measuring-math §5.3 line shift)."""
    if parallel_axis(direction_wcs) is None:
        return effective_radius(probe)
    return abs(centre_trigger_value(probe, direction_wcs, plane))


def skew_in_wcs(probe: ProbeRecord, wcs2bcs: Frame, spindle_angle_deg: float = 0.0) -> FloatArray:
    """Skew e (ball centre − spindle axis) as a WCS vector (measuring-math §5.2, measuring-math §1.7).

    Machine X/Y skew at spindle 0°, turned with SPOS about the tool axis Z: e(φ) = Rz(φ)·e,
    then into the WCS as a direction (BCS = MCS, no kinematic transformation).
    """
    e_mcs = np.array([float(probe.skew[0]), float(probe.skew[1]), 0.0])
    return wcs2bcs.dir_parent2child(rot_z(spindle_angle_deg) @ e_mcs)


def make_touch(rec_wcs: npt.ArrayLike, direction_wcs: npt.ArrayLike, probe: ProbeRecord, plane: Plane,
               skew_wcs: npt.ArrayLike | None = None, latched_mcs: npt.ArrayLike | None = None, *, lobing: LobingMap | None = None, spindle_angle: float = 0.0,
               wcs2bcs: Frame | None = None) -> Touch:
    """One compensated probing (measuring-math §5.2, measuring-math §5.3).

    ball centre c = rec (+ r·p̂ when length_to_tip, measuring-math §0.1) + e;
    axis-parallel along j, sign σ: s = c with s_j = c_j − t_centre(σ, j)  (measuring-math §5.3);
    otherwise s = c + ρ·d̂  (measuring-math §5.3, point-wise).

    ``lobing`` (engine.lobing.LobingMap, optional): the direction-dependent effective radius of
    an n-direction calibration; then every direction uses s = c + ρ(θ)·d̂ with θ the travel
    direction in the map's frame at SPOS ``spindle_angle`` (``wcs2bcs``: measuring WCS -> BCS;
    the infeed part blends with the record's current |t(−p)|). ``skew_wcs`` must then be the
    map's skew at that spindle angle (skew_in_wcs of the record it was stored with). Without
    ``lobing`` the result is exactly the record-based one above; ``probe.lobing`` is the
    default (the map stored with the record).
    """
    rec = np.asarray(rec_wcs, dtype=float)
    if rec.shape != (3,):
        raise ValueError(f"rec_wcs must have shape (3,), got {rec.shape}")
    if lobing is None:
        lobing = probe.lobing
    d_hat = checks.unit_vector(direction_wcs, dim=3)
    skew = np.zeros(3) if skew_wcs is None else np.asarray(skew_wcs, dtype=float)
    centre = rec + skew
    if probe.length_to_tip:
        centre = centre + (probe.ball_diameter / 2.0) * plane.infeed_unit   # measuring-math §0.1 tip -> centre
    axis = parallel_axis(d_hat)
    if lobing is not None:
        axial = abs(centre_trigger_value(probe, -plane.infeed_unit, plane))
        rho = lobing.radius_for(d_hat, spindle_angle, wcs2bcs, axial_radius=axial)
        surface = centre + rho * d_hat                                       # engine.lobing
    elif axis is not None:
        j, _sign = axis
        surface = centre.copy()
        surface[j] = centre[j] - _trigger_value_along(probe, axis, plane)   # measuring-math §5.3 s_j = c_j − t
    else:
        surface = centre + effective_radius(probe) * d_hat                  # measuring-math §5.3 s = c + ρ·d̂
    latched = None if latched_mcs is None else np.asarray(latched_mcs, dtype=float)
    return Touch(ball_centre=centre, direction=d_hat, surface=surface, latched_mcs=latched)

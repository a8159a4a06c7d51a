"""Zero-offset correction: write a measured feature into a target frame (jog-measuring §2, jog-measuring §4).

Systems: measuring WCS --chain--> BCS <--target_parent2bcs-- target parent <--target frame--
target child. Setpoints and the setpoint angle are read in the target's child system (= the
new WCS when the target is the active settable frame; for a basic/system frame: the WCS after
activating that frame alone, e.g. under G500).

Rules (the product's decisions, see the module's report):
- Rotation first (coordinate rotation about the angle axis, or orient plane), then translation
  ``T_new = T_old + R_new·d`` with d non-zero only on the determined axes (measuring-math §2.2,
  jog-measuring §2.5.1 [I]); so undetermined translation components (in the new child axes)
  stay, and a pure rotation turns about the child origin (translation kept, jog-measuring §2.9).
- A translation goes into the coarse offset, fine cleared (jog-measuring §1.7, jog-measuring §4.4; measuring-math §2.1).
- Rotary-axis angle correction: offset_new = offset_old + (measured − setpoint) (jog-measuring §11 Q8,
  s = +1). DIN 66217: a rotary *table* turning + rotates the part clockwise seen from +axis
  (the tool's motion relative to the part is right-handed), so turning the table by
  +(measured − setpoint) brings the edge from the measured to the setpoint angle.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from engine import alarms
from engine.frames import Frame, FrameChain, rot_axis, rot_x, rot_y, rot_z, rpy_from_matrix
from engine.planes import Plane, axis_index
from engine.types import FeatureFix, FloatArray, MeasuringError

GLOBAL_BASIC_PREFIX = "NCBASIC"


@dataclass(frozen=True)
class Correction:
    target: str                       # "measure_only", "G54".., "BASIC_REF", "BASIC_0"..
    before: Frame
    after: Frame
    rotary_axis: str | None = None    # when the angle correction went into a rotary axis offset
    rotary_move: float | None = None  # deg the rotary axis must turn to align the part

    def tilts_infeed(self, plane: Plane, tol_deg: float = 1e-7) -> bool:
        """True when the infeed axis direction changed: probe re-alignment needed (jog-measuring §6.2 cond. 2)."""
        p = plane.infeed_unit
        old, new = self.before.rotation @ p, self.after.rotation @ p
        angle = np.degrees(np.arctan2(np.linalg.norm(np.cross(old, new)), old @ new))
        return bool(angle > tol_deg)


def _wrap180(deg: float) -> float:
    """Angle in (−180, 180]."""
    wrapped = (deg + 180.0) % 360.0 - 180.0
    return 180.0 if wrapped == -180.0 else wrapped


def _signed_axis(name: str) -> tuple[str, float]:
    """"Z" -> ("Z", +1), "-Z" -> ("Z", −1)."""
    name = name.strip()
    if name.startswith("-"):
        return name[1:], -1.0
    return name.lstrip("+"), 1.0


def alpha_beta_from_normal(normal: npt.ArrayLike, plane: Plane) -> tuple[float, float]:
    """(alpha about a, beta about o) in deg with Rot_o(beta)·Rot_a(alpha)·ê_p = n̂ (jog-measuring §2.9).

    G17: alpha = asin(−n_y), beta = atan2(n_x, n_z); G18/G19 with (a, o, p) permuted.
    """
    n = np.asarray(normal, dtype=float)
    norm = float(np.linalg.norm(n))
    if n.shape != (3,) or not np.isfinite(norm) or norm == 0.0:
        raise ValueError(f"normal must be a finite non-zero 3-vector, got {normal!r}")
    n_a, n_o, n_p = plane.to_aop(n / norm)
    alpha = np.degrees(np.arcsin(np.clip(-n_o, -1.0, 1.0)))   # jog-measuring §2.9
    beta = np.degrees(np.arctan2(n_a, n_p))                     # jog-measuring §2.9
    return float(alpha), float(beta)


def _orient_rotation(rotation_old: FloatArray, normal_in_parent: FloatArray, plane: Plane) -> FloatArray:
    """New child2parent rotation whose +p axis is the normal, keeping the rotation about p.

    In (a, o, p) coordinates R = Rot_p(gamma)·Rot_o(beta)·Rot_a(alpha) (Siemens RPY order,
    measuring-math §0.2, permuted per jog-measuring §2.9); gamma is taken from the old frame and kept.
    """
    m = plane.aop2xyz
    rot_old_aop = m.T @ rotation_old @ m
    gamma = float(np.degrees(np.arctan2(rot_old_aop[1, 0], rot_old_aop[0, 0])))  # measuring-math §0.2 extraction
    n_aop = m.T @ normal_in_parent
    n_unrotated = rot_z(-gamma) @ n_aop
    alpha, beta = alpha_beta_from_normal(plane.to_xyz(n_unrotated), plane)
    rot_new_aop = rot_z(gamma) @ rot_y(beta) @ rot_x(alpha)
    return m @ rot_new_aop @ m.T


def correct(fix: FeatureFix, *, setpoints: dict[str, float], setpoint_angle: float | None,
            target: str, target_frame: Frame, chain: FrameChain, target_parent2bcs: Frame,
            plane: Plane, angle_correction: str = "rotation", translate: bool = True) -> Correction:
    """New target frame so the feature reads its setpoints in the target's child system.

    ``chain``: FrameChain active while measuring (measuring WCS -> BCS). ``angle_correction``:
    "rotation", "none" or a rotary-axis name (e.g. "C"). See the module docstring.
    """
    if target == "measure_only":
        return Correction(target=target, before=target_frame, after=target_frame)
    if fix.normal is not None and fix.angle is not None:
        raise MeasuringError(alarms.FRAME_INTERNAL, "a feature fix cannot carry both a plane normal and an angle")
    meas2parent = _Meas2Parent(chain.wcs2bcs, target_parent2bcs)
    turn = _Turn(target_frame.rotation, dict(target_frame.rotary))
    if angle_correction not in (None, "none") and (fix.normal is not None or fix.angle is not None):
        if target.upper().startswith(GLOBAL_BASIC_PREFIX):
            raise MeasuringError(alarms.ZO_NUMBER, f"{target}: a global basic frame cannot take "
                                 + ("a rotation (jog-measuring §4.2)" if fix.normal is not None else
                                    "an angle correction (jog-measuring §4.2, jog-measuring §11 Q21)"))
        if fix.normal is not None:
            normal_in_parent = meas2parent.direction(fix.normal)
            normal_in_parent = normal_in_parent / np.linalg.norm(normal_in_parent)
            turn.rotate(_orient_rotation(turn.rotation, normal_in_parent, plane))   # jog-measuring §2.9
        else:
            _correct_angle(turn, fix, plane, meas2parent, setpoint_angle, str(angle_correction))
    coarse, fine = target_frame.coarse, target_frame.fine
    if translate and fix.position:
        coarse = _translation(fix, setpoints, turn.rotation, target_frame.translation, meas2parent)
        fine = np.zeros(3)                                 # jog-measuring §4.4: coarse, fine cleared
    rot = rpy_from_matrix(turn.rotation) if turn.changed else target_frame.rot
    after = Frame(coarse=coarse, fine=fine, rot=rot, rotary=tuple(turn.rotary.items()))
    return Correction(target=target, before=target_frame, after=after,
                      rotary_axis=turn.rotary_axis, rotary_move=turn.rotary_move)


@dataclass(frozen=True)
class _Meas2Parent:
    """From the measuring WCS to the target's parent system (through the BCS)."""

    meas2bcs: Frame
    parent2bcs: Frame

    def direction(self, d_in_meas: npt.ArrayLike) -> FloatArray:
        return self.parent2bcs.dir_parent2child(self.meas2bcs.dir_child2parent(d_in_meas))

    def point(self, p_in_meas: npt.ArrayLike) -> FloatArray:
        return self.parent2bcs.parent2child(self.meas2bcs.child2parent(p_in_meas))


@dataclass
class _Turn:
    """The target's rotation and rotary offsets as the correction changes them."""

    rotation: FloatArray
    rotary: dict[str, float]
    changed: bool = False
    rotary_axis: str | None = None
    rotary_move: float | None = None

    def rotate(self, rotation: FloatArray) -> None:
        self.rotation, self.changed = rotation, True


def _correct_angle(turn: _Turn, fix: FeatureFix, plane: Plane, meas2parent: _Meas2Parent,
                   setpoint_angle: float | None, angle_correction: str) -> None:
    """An edge/angle fix: D = actual − setpoint (measuring-math §0.1) into the rotation about the
    angle axis (measuring-math §2.2: R_new = R_old·Rot_k(Δθ)) or onto a rotary axis (jog-measuring §2.5.2)."""
    assert fix.angle is not None
    k_name, k_sign = _signed_axis(fix.angle_axis or plane.infeed)
    r_name = fix.reference_axis or plane.first
    e_k = np.zeros(3)
    e_k[axis_index(k_name)] = k_sign
    e_r = np.zeros(3)
    e_r[axis_index(r_name)] = 1.0
    if abs(e_k @ e_r) > 0.0:
        raise ValueError(f"reference axis {r_name} must differ from the angle axis {k_name}")
    e_90 = np.cross(e_k, e_r)                 # +90° from the reference axis about k (measuring-math §0.1)
    theta = np.radians(fix.angle)
    u_meas = np.cos(theta) * e_r + np.sin(theta) * e_90
    u_child = turn.rotation.T @ meas2parent.direction(u_meas)   # measured direction, old child system
    theta_child = float(np.degrees(np.arctan2(u_child @ e_90, u_child @ e_r)))
    delta = _wrap180(theta_child - (setpoint_angle or 0.0))   # D = actual − setpoint (measuring-math §0.1)
    if angle_correction == "rotation":
        turn.rotate(turn.rotation @ rot_axis(k_name, k_sign * delta))
        return
    if angle_correction.upper() in ("X", "Y", "Z"):
        raise ValueError(f"angle correction axis must be a rotary axis, got {angle_correction!r}")
    turn.rotary[angle_correction] = turn.rotary.get(angle_correction, 0.0) + delta   # jog-measuring §11 Q8 (s = +1)
    turn.rotary_axis, turn.rotary_move = angle_correction, delta


def _translation(fix: FeatureFix, setpoints: dict[str, float], rotation_new: FloatArray,
                 translation_old: FloatArray, meas2parent: _Meas2Parent) -> FloatArray:
    """T_new = T + R·d (measuring-math §2.2), d = c_a − s per determined axis (jog-measuring §2.5.1)."""
    point_meas = np.zeros(3) if fix.point is None else np.array(fix.point, dtype=float)
    for axis in fix.position:
        point_meas[axis_index(axis)] = float(fix.position[axis])
    point_child = rotation_new.T @ (meas2parent.point(point_meas) - translation_old)   # after the rotation
    d = np.zeros(3)
    for axis in fix.position:
        j = axis_index(axis)
        d[j] = point_child[j] - float(setpoints.get(axis, 0.0))
    return translation_old + rotation_new @ d

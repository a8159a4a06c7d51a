"""Frames and the frame chain (design.md §3, measuring-math §0.2).

A frame maps the coordinate system above it (child, nearer the WCS) to the one below it
(parent, nearer the MCS): ``p_parent = R @ p_child + T``. Names carry the direction:
``child2parent``, ``wcs2bcs``, ``p_in_wcs``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

GEOMETRY_AXES = ("X", "Y", "Z")


def _vec3(value, name: str) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if arr.shape != (3,):
        raise ValueError(f"{name} must have shape (3,), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite, got {arr}")
    return arr


def rot_x(deg: float) -> np.ndarray:
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y(deg: float) -> np.ndarray:
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(deg: float) -> np.ndarray:
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rot_axis(axis: str, deg: float) -> np.ndarray:
    """Right-hand rotation about the geometry axis ``axis`` ("X", "Y", "Z") (measuring-math §0.1)."""
    try:
        return {"X": rot_x, "Y": rot_y, "Z": rot_z}[axis](deg)
    except KeyError:
        raise ValueError(f"axis must be X, Y or Z, got {axis!r}") from None


def matrix_from_rpy(rot_deg) -> np.ndarray:
    """R = Rz(c)·Ry(b)·Rx(a) for rot_deg = (a about X, b about Y, c about Z) (design.md §3 RPY)."""
    a, b, c = _vec3(rot_deg, "rot_deg")
    return rot_z(c) @ rot_y(b) @ rot_x(a)


def rpy_from_matrix(matrix) -> np.ndarray:
    """(a, b, c) in degrees with R = Rz(c)·Ry(b)·Rx(a) (measuring-math §0.2 extraction)."""
    r = np.asarray(matrix, dtype=float)
    if r.shape != (3, 3):
        raise ValueError(f"rotation matrix must have shape (3, 3), got {r.shape}")
    b = np.arcsin(np.clip(-r[2, 0], -1.0, 1.0))
    if abs(r[2, 0]) > 1.0 - 1e-12:
        # gimbal lock (b = ±90°): only a ∓ c is defined; choose c = 0
        # (Rz(0)·Ry(±90)·Rx(a) has R[0,1] = ±sin a, R[1,1] = cos a)
        a = np.arctan2(np.sign(-r[2, 0]) * r[0, 1], r[1, 1])
        c = 0.0
    else:
        a = np.arctan2(r[2, 1], r[2, 2])
        c = np.arctan2(r[1, 0], r[0, 0])
    return np.degrees(np.array([a, b, c]))


@dataclass(frozen=True, eq=False)
class Frame:
    """One frame: coarse + fine translation, RPY rotation (deg), rotary-axis offsets (deg).

    Scaling and mirroring are not modelled (alarm 61310 territory, spec §1.7).
    """

    coarse: np.ndarray = field(default_factory=lambda: np.zeros(3))
    fine: np.ndarray = field(default_factory=lambda: np.zeros(3))
    rot: np.ndarray = field(default_factory=lambda: np.zeros(3))
    rotary: tuple[tuple[str, float], ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "coarse", _vec3(self.coarse, "coarse"))
        object.__setattr__(self, "fine", _vec3(self.fine, "fine"))
        object.__setattr__(self, "rot", _vec3(self.rot, "rot"))
        rotary = tuple(sorted((str(k), float(v)) for k, v in dict(self.rotary).items()))
        object.__setattr__(self, "rotary", rotary)
        # the matrix is needed on every point mapping: computed once (frozen), read-only
        rotation = matrix_from_rpy(self.rot)
        rotation.flags.writeable = False
        object.__setattr__(self, "_rotation", rotation)

    # --- construction -------------------------------------------------------------------
    @classmethod
    def identity(cls) -> Frame:
        return cls()

    @classmethod
    def from_matrix(cls, rotation, translation, rotary: Mapping[str, float] | None = None) -> Frame:
        """Frame with coarse translation ``translation`` and rotation ``rotation`` (3x3)."""
        return cls(coarse=_vec3(translation, "translation"), rot=rpy_from_matrix(rotation),
                   rotary=tuple((rotary or {}).items()))

    def replace(self, **changes) -> Frame:
        values = {"coarse": self.coarse, "fine": self.fine, "rot": self.rot, "rotary": self.rotary}
        values.update(changes)
        return Frame(**values)

    # --- values -------------------------------------------------------------------------
    @property
    def translation(self) -> np.ndarray:
        """Total translation T = coarse + fine."""
        return self.coarse + self.fine

    @property
    def rotation(self) -> np.ndarray:
        return self._rotation

    def rotary_offset(self, axis: str) -> float:
        return dict(self.rotary).get(axis, 0.0)

    def with_rotary(self, axis: str, value: float) -> Frame:
        """Copy with the rotary-axis offset ``axis`` set to ``value`` (deg)."""
        rotary = dict(self.rotary)
        rotary[axis] = float(value)
        return self.replace(rotary=tuple(rotary.items()))

    # --- comparison (numpy fields: the generated dataclass __eq__ would raise) ----------
    def _key(self) -> tuple:
        return (tuple(self.coarse), tuple(self.fine), tuple(self.rot), self.rotary)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Frame):
            return NotImplemented
        return self._key() == other._key()

    def __hash__(self) -> int:
        return hash(self._key())

    def isclose(self, other: Frame, tol: float = 1e-9) -> bool:
        """Same mapping and bookkeeping within ``tol`` (mm for translations, deg for angles)."""
        keys = {k for k, _ in self.rotary} | {k for k, _ in other.rotary}
        return bool(np.allclose(self.coarse, other.coarse, rtol=0.0, atol=tol)
                    and np.allclose(self.fine, other.fine, rtol=0.0, atol=tol)
                    and np.allclose(self.rotation, other.rotation, rtol=0.0, atol=tol)
                    and all(abs(self.rotary_offset(k) - other.rotary_offset(k)) <= tol for k in keys))

    def as_matrix(self) -> np.ndarray:
        """4x4 homogeneous child2parent matrix."""
        m = np.eye(4)
        m[:3, :3] = self.rotation
        m[:3, 3] = self.translation
        return m

    # --- mapping points and directions --------------------------------------------------
    def child2parent(self, p_in_child) -> np.ndarray:
        p = np.asarray(p_in_child, dtype=float)
        return p @ self.rotation.T + self.translation

    def parent2child(self, p_in_parent) -> np.ndarray:
        p = np.asarray(p_in_parent, dtype=float)
        return (p - self.translation) @ self.rotation

    def dir_child2parent(self, d_in_child) -> np.ndarray:
        return np.asarray(d_in_child, dtype=float) @ self.rotation.T

    def dir_parent2child(self, d_in_parent) -> np.ndarray:
        return np.asarray(d_in_parent, dtype=float) @ self.rotation

    # --- algebra ------------------------------------------------------------------------
    def compose(self, inner: Frame) -> Frame:
        """self ∘ inner: p_parent = self(inner(p)); ``inner`` is nearer the WCS.

        Rotary offsets add up. The result carries all translation in ``coarse``.
        """
        rotation = self.rotation @ inner.rotation
        translation = self.rotation @ inner.translation + self.translation
        rotary = dict(self.rotary)
        for axis, value in inner.rotary:
            rotary[axis] = rotary.get(axis, 0.0) + value
        return Frame.from_matrix(rotation, translation, rotary)

    def inverse(self) -> Frame:
        rotation = self.rotation.T
        return Frame.from_matrix(rotation, -(rotation @ self.translation),
                                 {k: -v for k, v in self.rotary})

    # --- API representation -------------------------------------------------------------
    def to_api(self) -> dict:
        """``{"trans": {X,Y,Z,<rotary>}, "fine": {X,Y,Z}, "rot": {X,Y,Z}}`` (design.md §4)."""
        trans = {a: float(v) for a, v in zip(GEOMETRY_AXES, self.coarse, strict=True)}
        trans.update({k: float(v) for k, v in self.rotary})
        return {
            "trans": trans,
            "fine": {a: float(v) for a, v in zip(GEOMETRY_AXES, self.fine, strict=True)},
            "rot": {a: float(v) for a, v in zip(GEOMETRY_AXES, self.rot, strict=True)},
        }

    @classmethod
    def from_api(cls, data: Mapping) -> Frame:
        trans = dict(data.get("trans") or {})
        fine = dict(data.get("fine") or {})
        rot = dict(data.get("rot") or {})
        coarse = [float(trans.pop(a, 0.0)) for a in GEOMETRY_AXES]
        return cls(coarse=coarse,
                   fine=[float(fine.get(a, 0.0)) for a in GEOMETRY_AXES],
                   rot=[float(rot.get(a, 0.0)) for a in GEOMETRY_AXES],
                   rotary=tuple((k, float(v)) for k, v in trans.items()))


def compose_chain(frames_outside_in: Sequence[Frame]) -> Frame:
    """Compose a chain listed from the MCS side inwards: F0 ∘ F1 ∘ ... (WCS -> MCS)."""
    total = Frame.identity()
    for frame in frames_outside_in:
        total = total.compose(frame)
    return total


@dataclass(frozen=True)
class FrameChain:
    """WCS -> BCS = SETFRAME ∘ BASIC_0 ∘ BASIC_1 ∘ ... ∘ SETTABLE (design.md §3).

    ``settable`` is the active settable frame (identity under G500).
    """

    setframe: Frame = field(default_factory=Frame.identity)
    basic: tuple[Frame, ...] = ()
    settable: Frame = field(default_factory=Frame.identity)

    @cached_property
    def below_settable(self) -> Frame:
        """Parent of the settable frame -> BCS (everything outside G54..); composed once."""
        return compose_chain([self.setframe, *self.basic])

    @cached_property
    def wcs2bcs(self) -> Frame:
        """Composed once per chain value (the chain is immutable)."""
        return self.below_settable.compose(self.settable)

    def p_in_bcs(self, p_in_wcs) -> np.ndarray:
        return self.wcs2bcs.child2parent(p_in_wcs)

    def p_in_wcs(self, p_in_bcs) -> np.ndarray:
        return self.wcs2bcs.parent2child(p_in_bcs)

    def dir_in_bcs(self, d_in_wcs) -> np.ndarray:
        return self.wcs2bcs.dir_child2parent(d_in_wcs)

    def parent2bcs_of_basic(self, index: int) -> Frame:
        """Frames outside basic frame ``index`` (SETFRAME ∘ BASIC_0 ∘ … ∘ BASIC_{index-1})."""
        if not 0 <= index < len(self.basic):
            raise ValueError(f"basic frame {index} does not exist (have {len(self.basic)})")
        return compose_chain([self.setframe, *self.basic[:index]])

    def replace(self, **changes) -> FrameChain:
        values = {"setframe": self.setframe, "basic": self.basic, "settable": self.settable}
        values.update(changes)
        values["basic"] = tuple(values["basic"])
        return FrameChain(**values)

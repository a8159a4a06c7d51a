"""Frames and the frame chain (design.md §3, measuring-math §0.2).

A frame maps the coordinate system above it (child, nearer the WCS) to the one below it
(parent, nearer the MCS): ``p_parent = R @ p_child + T``. Names carry the direction:
``child2parent``, ``wcs2bcs``, ``p_in_wcs``.
"""

from __future__ import annotations

import functools
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np
import numpy.typing as npt

from engine import checks
from engine.types import FloatArray

GEOMETRY_AXES = ("X", "Y", "Z")


def rot_x(deg: float) -> FloatArray:
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y(deg: float) -> FloatArray:
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(deg: float) -> FloatArray:
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rot_axis(axis: str, deg: float) -> FloatArray:
    """Right-hand rotation about the geometry axis ``axis`` ("X", "Y", "Z") (measuring-math §0.1)."""
    try:
        return {"X": rot_x, "Y": rot_y, "Z": rot_z}[axis](deg)
    except KeyError:
        raise ValueError(f"axis must be X, Y or Z, got {axis!r}") from None


def matrix_from_rpy(rot_deg: npt.ArrayLike) -> FloatArray:
    """R = Rz(c)·Ry(b)·Rx(a) for rot_deg = (a about X, b about Y, c about Z) (design.md §3 RPY)."""
    a, b, c = checks.vector(rot_deg, "rot_deg")
    return rot_z(c) @ rot_y(b) @ rot_x(a)


def rpy_from_matrix(matrix: npt.ArrayLike) -> FloatArray:
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
    rpy: FloatArray = np.degrees(np.array([a, b, c], dtype=float))
    return rpy


@dataclass(frozen=True, eq=False)
class Frame:
    """One frame: coarse + fine translation, RPY rotation (deg), rotary-axis offsets (deg).

    Scaling and mirroring are not modelled (alarm 61310 territory, jog-measuring §1.7).
    """

    coarse: FloatArray = field(default_factory=lambda: np.zeros(3))
    fine: FloatArray = field(default_factory=lambda: np.zeros(3))
    rot: FloatArray = field(default_factory=lambda: np.zeros(3))
    rotary: tuple[tuple[str, float], ...] = ()

    def __post_init__(self) -> None:
        for name in ("coarse", "fine", "rot"):
            value = checks.vector(getattr(self, name), name)
            value.flags.writeable = False            # a value object (frames are shared, see _frame_of)
            object.__setattr__(self, name, value)
        rotary = tuple(sorted((str(k), float(v)) for k, v in dict(self.rotary).items()))
        object.__setattr__(self, "rotary", rotary)
        # the matrix is needed on every point mapping: computed once (frozen), read-only
        rotation = matrix_from_rpy(self.rot)
        rotation.flags.writeable = False
        object.__setattr__(self, "_rotation", rotation)

    # --- construction -------------------------------------------------------------------
    @classmethod
    def identity(cls) -> Frame:
        # one shared value (frames are immutable): compositions with it are found in _composed
        return _IDENTITY if cls is Frame else cls()

    @classmethod
    def from_matrix(cls, rotation: npt.ArrayLike, translation: npt.ArrayLike,
                    rotary: Mapping[str, float] | None = None) -> Frame:
        """Frame with coarse translation ``translation`` and rotation ``rotation`` (3x3)."""
        return cls(coarse=checks.vector(translation, "translation"), rot=rpy_from_matrix(rotation),
                   rotary=tuple((rotary or {}).items()))

    def replace(self, **changes: Any) -> Frame:
        values: dict[str, Any] = {"coarse": self.coarse, "fine": self.fine, "rot": self.rot, "rotary": self.rotary}
        values.update(changes)
        return Frame(**values)

    # --- values -------------------------------------------------------------------------
    @property
    def translation(self) -> FloatArray:
        """Total translation T = coarse + fine."""
        return self.coarse + self.fine

    @property
    def rotation(self) -> FloatArray:
        rotation: FloatArray = self.__dict__["_rotation"]   # set in __post_init__, not a field
        return rotation

    def rotary_offset(self, axis: str) -> float:
        return dict(self.rotary).get(axis, 0.0)

    def with_rotary(self, axis: str, value: float) -> Frame:
        """Copy with the rotary-axis offset ``axis`` set to ``value`` (deg)."""
        rotary = dict(self.rotary)
        rotary[axis] = float(value)
        return self.replace(rotary=tuple(rotary.items()))

    # --- comparison (numpy fields: the generated dataclass __eq__ would raise) ----------
    def _key(self) -> tuple[object, ...]:
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

    def as_matrix(self) -> FloatArray:
        """4x4 homogeneous child2parent matrix."""
        m = np.eye(4)
        m[:3, :3] = self.rotation
        m[:3, 3] = self.translation
        return m

    # --- mapping points and directions --------------------------------------------------
    def child2parent(self, p_in_child: npt.ArrayLike) -> FloatArray:
        p = np.asarray(p_in_child, dtype=float)
        return p @ self.rotation.T + self.translation

    def parent2child(self, p_in_parent: npt.ArrayLike) -> FloatArray:
        p = np.asarray(p_in_parent, dtype=float)
        return (p - self.translation) @ self.rotation

    def dir_child2parent(self, d_in_child: npt.ArrayLike) -> FloatArray:
        return np.asarray(d_in_child, dtype=float) @ self.rotation.T

    def dir_parent2child(self, d_in_parent: npt.ArrayLike) -> FloatArray:
        return np.asarray(d_in_parent, dtype=float) @ self.rotation

    # --- algebra ------------------------------------------------------------------------
    def compose(self, inner: Frame) -> Frame:
        """self ∘ inner: p_parent = self(inner(p)); ``inner`` is nearer the WCS.

        Rotary offsets add up. The result carries all translation in ``coarse``.
        """
        return _composed(self, inner)

    def _compose(self, inner: Frame) -> Frame:
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
    def to_api(self) -> dict[str, Any]:
        """``{"trans": {X,Y,Z,<rotary>}, "fine": {X,Y,Z}, "rot": {X,Y,Z}}`` (design.md §4)."""
        trans = {a: float(v) for a, v in zip(GEOMETRY_AXES, self.coarse, strict=True)}
        trans.update({k: float(v) for k, v in self.rotary})
        return {
            "trans": trans,
            "fine": {a: float(v) for a, v in zip(GEOMETRY_AXES, self.fine, strict=True)},
            "rot": {a: float(v) for a, v in zip(GEOMETRY_AXES, self.rot, strict=True)},
        }

    @classmethod
    def from_api(cls, data: Mapping[str, Any]) -> Frame:
        trans = dict(data.get("trans") or {})
        fine = dict(data.get("fine") or {})
        rot = dict(data.get("rot") or {})
        coarse = tuple(float(trans.pop(a, 0.0)) for a in GEOMETRY_AXES)
        return _frame_of(coarse, tuple(float(fine.get(a, 0.0)) for a in GEOMETRY_AXES),
                         tuple(float(rot.get(a, 0.0)) for a in GEOMETRY_AXES),
                         tuple(sorted((str(k), float(v)) for k, v in trans.items())))


_IDENTITY = Frame()


@functools.lru_cache(maxsize=1024)
def _composed(outer: Frame, inner: Frame) -> Frame:
    # by identity (frames are immutable values, eq=False): every measuring context composes the
    # same stored frames (the chain BASIC_REF ∘ BASIC_0 ∘ … ∘ G54) again; the same result, once
    return outer._compose(inner)


@functools.lru_cache(maxsize=512)
def _frame_of(coarse: tuple[float, ...], fine: tuple[float, ...], rot: tuple[float, ...],
              rotary: tuple[tuple[str, float], ...]) -> Frame:
    # frames are immutable values: the same stored numbers give the same (shared) Frame; every
    # measurement reads all stored frames, and building one validates and makes its matrix
    return Frame(coarse=np.array(coarse), fine=np.array(fine), rot=np.array(rot), rotary=rotary)


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

    def p_in_bcs(self, p_in_wcs: npt.ArrayLike) -> FloatArray:
        return self.wcs2bcs.child2parent(p_in_wcs)

    def p_in_wcs(self, p_in_bcs: npt.ArrayLike) -> FloatArray:
        return self.wcs2bcs.parent2child(p_in_bcs)

    def dir_in_bcs(self, d_in_wcs: npt.ArrayLike) -> FloatArray:
        return self.wcs2bcs.dir_child2parent(d_in_wcs)

    def parent2bcs_of_basic(self, index: int) -> Frame:
        """Frames outside basic frame ``index`` (SETFRAME ∘ BASIC_0 ∘ … ∘ BASIC_{index-1})."""
        if not 0 <= index < len(self.basic):
            raise ValueError(f"basic frame {index} does not exist (have {len(self.basic)})")
        return compose_chain([self.setframe, *self.basic[:index]])

    def replace(self, **changes: Any) -> FrameChain:
        values: dict[str, Any] = {"setframe": self.setframe, "basic": self.basic, "settable": self.settable}
        values.update(changes)
        values["basic"] = tuple(values["basic"])
        return FrameChain(**values)


# --- the named frames of design.md §3/§4 ---------------------------------------------------------

G500 = "G500"                  # no settable frame active
SETFRAME = "BASIC_REF"         # the system frame outside the basic frames


def basic_frame_names(names: Iterable[str]) -> tuple[str, ...]:
    """BASIC_0, BASIC_1, … in chain order (BASIC_REF is the SETFRAME, outside all of them)."""
    return tuple(sorted((n for n in names if n.startswith("BASIC_") and n != SETFRAME),
                        key=lambda n: int(n.split("_")[1])))


def chain_of(frames: Mapping[str, Frame], active: str) -> FrameChain:
    """WCS->BCS = BASIC_REF ∘ BASIC_0 ∘ BASIC_1 ∘ … ∘ ``active`` (identity under G500)."""
    return FrameChain(setframe=frames.get(SETFRAME, Frame.identity()),
                      basic=tuple(frames[n] for n in basic_frame_names(frames)),
                      settable=Frame.identity() if active == G500 else frames[active])


def is_basic(name: str) -> bool:
    """A basic frame (BASIC_REF, BASIC_n): always part of the active chain, unlike a settable WO."""
    return name.startswith("BASIC")


def parent2bcs_of(frames: Mapping[str, Frame], target: str) -> Frame:
    """Composition of the frames outside ``target`` (MCS side first), from ``frames`` as given."""
    chain = chain_of(frames, G500)
    names = basic_frame_names(frames)
    if target in names:
        return chain.parent2bcs_of_basic(names.index(target))
    if is_basic(target):            # BASIC_REF, the SETFRAME: nothing outside it
        return Frame.identity()
    return chain.below_settable

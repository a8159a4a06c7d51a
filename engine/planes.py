"""Working planes G17/G18/G19 (measuring-math §0.1, spec/jog-measuring.md §9.2).

(a, o, p) = abscissa, ordinate, applicate (infeed axis); right-handed in every plane.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import numpy as np
import numpy.typing as npt

from engine.types import FloatArray

_AXIS_INDEX = {"X": 0, "Y": 1, "Z": 2}


@dataclass(frozen=True)
class Plane:
    name: str          # "G17" | "G18" | "G19"
    axes: tuple[str, str, str]  # (abscissa, ordinate, applicate)

    @property
    def first(self) -> str:
        return self.axes[0]

    @property
    def second(self) -> str:
        return self.axes[1]

    @property
    def infeed(self) -> str:
        return self.axes[2]

    @property
    def index(self) -> tuple[int, int, int]:
        return _index_of(self.axes)

    @property
    def aop2xyz(self) -> FloatArray:
        """3x3 matrix whose columns are the unit vectors of a, o, p in XYZ: p_xyz = M @ p_aop."""
        return _aop2xyz_of(self.axes).copy()

    def to_aop(self, p_xyz: npt.ArrayLike) -> FloatArray:
        return np.asarray(p_xyz, dtype=float) @ _aop2xyz_of(self.axes)

    def to_xyz(self, p_aop: npt.ArrayLike) -> FloatArray:
        return np.asarray(p_aop, dtype=float) @ _aop2xyz_of(self.axes).T

    def unit(self, axis: str) -> FloatArray:
        e = np.zeros(3)
        e[_AXIS_INDEX[axis]] = 1.0
        return e

    @property
    def infeed_unit(self) -> FloatArray:
        """Unit vector of the applicate (tool axis, pointing from tip to spindle)."""
        return self.unit(self.infeed)


@cache
def _index_of(axes: tuple[str, str, str]) -> tuple[int, int, int]:
    return tuple(_AXIS_INDEX[a] for a in axes)  # type: ignore[return-value]


@cache
def _aop2xyz_of(axes: tuple[str, str, str]) -> FloatArray:
    """``Plane.aop2xyz`` built once per plane (issue 30: to_aop/to_xyz run some hundred times per
    NC Start); read-only, the property hands out a copy."""
    m = np.zeros((3, 3))
    for col, idx in enumerate(_index_of(axes)):
        m[idx, col] = 1.0
    m.setflags(write=False)
    return m


PLANES = {
    "G17": Plane("G17", ("X", "Y", "Z")),
    "G18": Plane("G18", ("Z", "X", "Y")),
    "G19": Plane("G19", ("Y", "Z", "X")),
}


def plane(name: str) -> Plane:
    try:
        return PLANES[name]
    except KeyError:
        raise ValueError(f"plane must be one of G17, G18, G19, got {name!r}") from None


def axis_index(axis: str) -> int:
    try:
        return _AXIS_INDEX[axis]
    except KeyError:
        raise ValueError(f"axis must be X, Y or Z, got {axis!r}") from None

"""Measuring offsets G100 / G101 / G102 (spec/measuring-math.md §16, seed 003).

- G100 ``<axis><target>`` records, per axis, ``Δ = switching position − target`` (absolute
  coordinates: the WCS of the active frames, without included measuring offsets).
- G101 ``<axis><factor> ...`` includes ``k·Δ`` per listed axis in an additional offset between
  programmed and absolute coordinates: ``abs = prog + k·Δ``. Error if a listed axis has no
  measured value. A second G101 on an axis replaces (does not add to) its included offset.
- G102 ``{<axis><n>}`` extracts what G101 included: the listed axes, or all without axes. Error if
  a listed axis has nothing included; G102 without axes and nothing included is a no-op. What is
  extracted is always exactly what G101 included (a later G100 does not change it).

All operations are all-or-nothing: ``G101 X1 Z1`` without a Z measurement includes nothing.
The values are immutable; the interpreter keeps them in its modal state.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType


class MeasuringOffsetError(Exception):
    """G101 without a measured value / G102 without an included offset for ``axis``."""

    def __init__(self, axis: str, message: str):
        super().__init__(message)
        self.axis = axis
        self.message = message


class NoMeasuredValue(MeasuringOffsetError):
    pass


class NothingIncluded(MeasuringOffsetError):
    pass


def _frozen(mapping: Mapping[str, float]) -> Mapping[str, float]:
    return MappingProxyType({str(k): float(v) for k, v in mapping.items()})


@dataclass(frozen=True, eq=False)
class MeasuringOffsets:
    """``measured``: Δ per axis from the last G100 on it; ``included``: k·Δ per axis (G101)."""

    measured: Mapping[str, float] = field(default_factory=dict)
    included: Mapping[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "measured", _frozen(self.measured))
        object.__setattr__(self, "included", _frozen(self.included))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, MeasuringOffsets):
            return NotImplemented
        return dict(self.measured) == dict(other.measured) and dict(self.included) == dict(other.included)

    def __hash__(self) -> int:
        return hash((tuple(sorted(self.measured.items())), tuple(sorted(self.included.items()))))

    def offset(self, axis: str) -> float:
        """The included offset of ``axis`` (0 when none): ``abs = prog + offset``."""
        return self.included.get(axis, 0.0)

    def record(self, axis: str, delta: float) -> MeasuringOffsets:
        """G100: the measured value of ``axis`` (replaces an older one; ``included`` unchanged)."""
        return MeasuringOffsets({**self.measured, axis: delta}, self.included)

    def include(self, factors: Mapping[str, float]) -> MeasuringOffsets:
        """G101: ``included[axis] = factor·Δ[axis]`` for every listed axis, or an error for none."""
        for axis in factors:
            if axis not in self.measured:
                raise NoMeasuredValue(axis, f"G101 {axis}: no measured value for axis {axis}; "
                                            f"measure it with G100 {axis}... first")
        included = dict(self.included)
        for axis, factor in factors.items():
            included[axis] = float(factor) * self.measured[axis]
        return MeasuringOffsets(self.measured, included)

    def extract(self, axes: Iterable[str] | None = None) -> MeasuringOffsets:
        """G102: remove the included offsets of ``axes`` (all when None or empty)."""
        axes = list(axes or ())
        if not axes:
            return MeasuringOffsets(self.measured, {})
        for axis in axes:
            if axis not in self.included:
                raise NothingIncluded(axis, f"G102 {axis}: no measuring offset is included for axis {axis}")
        return MeasuringOffsets(self.measured, {a: v for a, v in self.included.items() if a not in axes})

    def to_dict(self) -> dict:
        return {"measured": dict(self.measured), "included": dict(self.included)}

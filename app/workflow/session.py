"""One measuring session per task screen: P1..Pn stored/invalid (spec/jog-measuring.md §3.1)."""

from __future__ import annotations

import dataclasses
import uuid
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from engine.types import CirclePoint, EdgePoint, RectPoint, StoredPoint


def _axes_dict(vec: np.ndarray) -> dict[str, float]:
    return {a: float(v) for a, v in zip(("X", "Y", "Z"), vec, strict=True)}


def stored_point_to_api(point) -> dict | None:
    """JSON view of a stored point (surface point or centre, in the measuring WCS; tool points in MCS)."""
    if point is None:
        return None
    if isinstance(point, EdgePoint):
        return {"surface": _axes_dict(point.touch.surface),
                "ball_centre": _axes_dict(point.touch.ball_centre),
                "direction": _axes_dict(point.touch.direction)}
    if isinstance(point, CirclePoint):
        return {"center": _axes_dict(point.center), "diameter": float(point.diameter)}
    if isinstance(point, RectPoint):
        return {"center": _axes_dict(point.center), "length": float(point.length),
                "width": float(point.width)}
    return {"type": type(point).__name__, **_plain(point)}   # tool / calibration points: all fields


def _plain(value):
    """JSON view of an engine point: dataclasses as objects, arrays and tuples as lists."""
    if dataclasses.is_dataclass(value):
        return {f.name: _plain(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple | np.ndarray):
        return [_plain(v) for v in value]
    return value.item() if isinstance(value, np.generic) else value


@dataclass
class PointSlot:
    n: int
    point: StoredPoint | None = None
    raw: list[dict] = field(default_factory=list)   # raw latches of the probing moves, for the log
    context: Any = None     # the MeasuringContext the point was taken in (design.md §9.1)

    @property
    def stored(self) -> bool:
        return self.point is not None

    def to_api(self) -> dict:
        return {"n": self.n, "stored": self.stored, "value": stored_point_to_api(self.point)}


@dataclass
class MeasureSession:
    task: str
    params: dict
    target: str | dict                  # a WO name, or a tool offset (design.md §9.3)
    measuring_wo: str
    slots: list[PointSlot]
    id: str = field(default_factory=lambda: uuid.uuid4().hex[:12])
    running: bool = False
    last: dict | None = None            # last calculate answer
    last_alarm: dict | None = None
    warnings: list[str] = field(default_factory=list)
    progress: dict | None = None        # {"point", "step", "steps", "label"} while NC Start runs
    notice: str | None = None           # why stored points were discarded (tool change, scenario)
    repetitions: int = 0                # repetitions made under the repeat rule (_CBIT[0], measuring-math §3.6)
    guard: bool = True                  # the start guard checks each point's path (params.guard: false skips it)

    @classmethod
    def create(cls, task: str, params: dict, target: str | dict, measuring_wo: str, n_points: int
               ) -> MeasureSession:
        return cls(task=task, params=params, target=target, measuring_wo=measuring_wo,
                   slots=[PointSlot(n) for n in range(1, n_points + 1)])

    @property
    def n_points(self) -> int:
        return len(self.slots)

    @property
    def single_point(self) -> bool:
        return self.n_points == 1

    @property
    def can_calculate(self) -> bool:
        return not self.single_point and all(s.stored for s in self.slots)

    def next_point(self) -> int | None:
        """The lowest-numbered point not stored (jog-measuring §3.1 [I])."""
        for slot in self.slots:
            if not slot.stored:
                return slot.n
        return None

    def slot(self, n: int) -> PointSlot:
        if not 1 <= n <= self.n_points:
            raise KeyError(n)
        return self.slots[n - 1]

    def invalidate(self, n: int) -> None:
        slot = self.slot(n)
        slot.point, slot.raw, slot.context = None, [], None

    def clear_points(self) -> None:
        for slot in self.slots:
            slot.point, slot.raw, slot.context = None, [], None

    def plc_byte(self) -> int:
        """DB19.DBB43 bits 4..7: point n measured and stored (jog-measuring §3.2)."""
        return sum(1 << (3 + s.n) for s in self.slots if s.stored)

    def to_api(self) -> dict:
        return {
            "id": self.id,
            "task": self.task,
            "params": self.params,
            "target": self.target,
            "measuring_wo": self.measuring_wo,
            "points": [s.to_api() for s in self.slots],
            "next_point": self.next_point(),
            "can_calculate": self.can_calculate,
            "busy": self.running,
            "running": self.running,
            "progress": dict(self.progress) if self.progress else None,
            "answer": self.last,
            "notice": self.notice,
            "plc_dbb43": self.plc_byte(),
            "warnings": list(self.warnings),
            "alarm": self.last_alarm,
        }

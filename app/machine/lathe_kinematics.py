"""Kinematics of the simulated lathe: axes, limits, where the true tool tip and ball centre are.

Pure geometry, no state. A position is the array (X, Y, Z) of the turret reference point F
(MCS; X = its radius from the spindle axis, Z along it); Y is always present and stays 0 on a
lathe without a Y axis (``axes`` then names X and Z only, so it cannot be jogged or commanded).

The tool truth (turning.md §0.4, turning §0.5, turning §11; the simulator's own table, not the engine's):
``P = F − (L1·x̂ + L2·ẑ)`` is the theoretical tip (the ball centre for the probe), the nose
centre ``S = P − R·s(SL)`` with s(SL) the direction from S to P. The nose is a ball of radius R
about S (in the XZ plane of motion it is the nose circle; every face it touches is parallel to
Y, so the ball and the circle touch alike).
"""

from __future__ import annotations

import numpy as np

from engine import alarms

from .lathe_scenario import LatheScenario, LatheTool
from .protocol import Alarm

AXIS_INDEX = {"X": 0, "Y": 1, "Z": 2}
LIMIT_EPS = 1e-9

# s(SL) = (s_X, s_Z): direction from the nose centre S to the tip P (turning.md §0.5, view X up, Z right)
SL_DIRECTION = {1: (1, 1), 2: (1, -1), 3: (-1, -1), 4: (-1, 1), 5: (0, 1), 6: (1, 0), 7: (0, -1), 8: (-1, 0),
                9: (0, 0)}


def sl_unit(sl: int) -> np.ndarray:
    sx, sz = SL_DIRECTION[int(sl)]
    return np.array([float(sx), 0.0, float(sz)])


class LatheKinematics:
    """The lathe of one scenario: its axes, their limits, the true tool and probe points."""

    def __init__(self, scenario: LatheScenario) -> None:
        self._scenario = scenario
        self.axes: tuple[str, ...] = scenario.axes
        self.limits: dict[str, tuple[float, float]] = scenario.limits()

    def index(self, axis: str) -> int:
        if axis not in self.axes:
            raise ValueError(f"unknown axis {axis!r}; the lathe has {list(self.axes)}")
        return AXIS_INDEX[axis]

    @staticmethod
    def as_dict(position: np.ndarray) -> dict[str, float]:
        return {"X": float(position[0]), "Y": float(position[1]), "Z": float(position[2])}

    def start_position(self) -> np.ndarray:
        start = self._scenario.start_position()
        return np.array([start["X"], start["Y"], start["Z"]], dtype=float)

    @staticmethod
    def along(start: np.ndarray, d: np.ndarray, s: float) -> np.ndarray:
        return np.asarray(start, dtype=float) + float(s) * np.asarray(d, dtype=float)

    def limit_alarm(self, target: np.ndarray) -> Alarm | None:
        for axis in ("X", "Y", "Z"):
            value = float(target[AXIS_INDEX[axis]])
            lo, hi = self.limits[axis]
            if not lo - LIMIT_EPS <= value <= hi + LIMIT_EPS:
                name = axis if axis in self.axes else f"{axis} (no such axis on this lathe)"
                return Alarm.of(alarms.SOFTWARE_LIMIT, f"Software limit switch {name}: {value:.3f} outside "
                                f"[{lo:g}, {hi:g}]")
        return None

    # --- the true points ------------------------------------------------------------------------
    @staticmethod
    def reference(position: np.ndarray, l1: float, l2: float) -> np.ndarray:
        """F − (l1·x̂ + l2·ẑ): the tip / ball centre for lengths l1 (X) and l2 (Z)."""
        p = np.asarray(position, dtype=float)
        return np.array([p[0] - l1, p[1], p[2] - l2])

    def ball_centre(self, position: np.ndarray) -> np.ndarray:
        probe = self._scenario.probe
        return self.reference(position, probe.l1, probe.l2)

    def tool_tip(self, position: np.ndarray, tool: LatheTool, worn: tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
        return self.reference(position, tool.l1 - worn[0], tool.l2 - worn[1])

    def nose_centre(self, position: np.ndarray, tool: LatheTool, worn: tuple[float, float] = (0.0, 0.0)
                    ) -> np.ndarray:
        return self.tool_tip(position, tool, worn) - tool.radius * sl_unit(tool.sl)

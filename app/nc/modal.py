"""Modal state of the channel and the G/M function tables of the language.

``ModalState`` is immutable: a block computes the state after it as a new value and the
interpreter commits it only when the block has executed completely (design: "a half-executed block
does not leave G91 active").
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field, replace

import numpy as np

from .offsets import MeasuringOffsets

GEOMETRY_AXES = ("X", "Y", "Z")
ROTARY_AXES = ("A", "B", "C")
AXIS_LETTERS = GEOMETRY_AXES + ROTARY_AXES

# --- G functions: group of each (design.md §9.4; 840D group names in brackets) -------------------
MOTION = "motion"             # G0 G1                   [group 1]
PLANE = "plane"               # G17 G18 G19             [group 6]
OFFSET = "offset"             # G500 G54..G57 G505..G599 [group 8]
FRAME_SUPPRESS = "suppress"   # G53, non-modal          [group 9]
UNITS = "units"               # G70 G71 G700 G710       [group 13]
DISTANCE = "distance"         # G90 G91                 [group 14]
FEED_TYPE = "feed_type"       # G94 mm/min, G95 mm/rev  [group 15]
MEASURING = "measuring"       # G100 G101 G102, non-modal (seed 003; another control's functions)

_FIXED_GROUPS = {
    0: MOTION, 1: MOTION,
    17: PLANE, 18: PLANE, 19: PLANE,
    53: FRAME_SUPPRESS,
    54: OFFSET, 55: OFFSET, 56: OFFSET, 57: OFFSET, 500: OFFSET,
    70: UNITS, 71: UNITS, 700: UNITS, 710: UNITS,
    90: DISTANCE, 91: DISTANCE,
    94: FEED_TYPE, 95: FEED_TYPE,
    100: MEASURING, 101: MEASURING, 102: MEASURING,
}

#: M functions of the language: program stop/end, spindle, tool change
M_STOP, M_END, M_SUB_END, M_END_RESET = 0, 2, 17, 30
M_SPINDLE = {3: 1, 4: -1, 5: 0}          # M3 clockwise, M4 counter-clockwise, M5 stop
M_TOOL_CHANGE = 6
KNOWN_M = {M_STOP, M_END, M_SUB_END, M_END_RESET, M_TOOL_CHANGE, *M_SPINDLE}

PLANE_AXES = {"G17": ("X", "Y", "Z"), "G18": ("Z", "X", "Y"), "G19": ("Y", "Z", "X")}
SETTABLE_OFFSET = re.compile(r"^G(500|5[4-7]|5(0[5-9]|[1-9][0-9]))$")


def g_group(number: int) -> str | None:
    """The group of G``number``, or None when the language does not know it."""
    if number in _FIXED_GROUPS:
        return _FIXED_GROUPS[number]
    if 505 <= number <= 599:
        return OFFSET
    return None


def infeed_axis(plane: str) -> str:
    """The applicate (tool axis) of the plane: G17 Z, G18 Y, G19 X (measuring-math §0.1)."""
    return PLANE_AXES[plane][2]


def infeed_unit(plane: str) -> np.ndarray:
    """MCS unit vector along which the tool length acts in ``plane`` (like app/workflow/executor)."""
    unit = np.zeros(3)
    unit[GEOMETRY_AXES.index(infeed_axis(plane))] = 1.0
    return unit


INCH = 25.4


@dataclass(frozen=True)
class ModalState:
    """What the channel remembers from block to block.

    Units: ``feed`` mm/min, ``spindle_speed`` rev/min (always the basic system, whatever G70/G700).
    ``tool``/``edge`` = the tool in the spindle and its active D; ``preselected`` = T programmed,
    changed in by M6.
    """

    motion: str = "G1"
    plane: str = "G17"
    distance: str = "G90"
    units: str = "G71"
    offset: str = "G500"
    feed: float | None = None             # as programmed: mm/min (G94) or mm/rev (G95)
    feed_type: str = "G94"
    spindle_direction: int = 0            # +1 M3, -1 M4, 0 M5
    spindle_speed: float = 0.0
    tool: int | None = None
    edge: int = 0
    preselected: int | None = None
    measuring: MeasuringOffsets = field(default_factory=MeasuringOffsets)
    diamon: bool = False                  # DIAMON: X words (and the lathe cycles' X values) are diameters

    def replace(self, **changes) -> ModalState:
        return replace(self, **changes)

    @property
    def inch(self) -> bool:
        """Geometric data in inch (G70/G700)."""
        return self.units in ("G70", "G700")

    @property
    def inch_feed(self) -> bool:
        """Feeds in inch/min: only G700 (840D: G70 converts geometry, G700 also technology data)."""
        return self.units == "G700"

    def path_feed(self) -> float | None:
        """The path feed in mm/min: F itself (G94), or F times the spindle speed (G95, feed per
        revolution: None while the spindle stands)."""
        if self.feed is None or self.feed_type == "G94":
            return self.feed
        turning = self.spindle_direction != 0 and self.spindle_speed > 0.0
        return self.feed * self.spindle_speed if turning else None

    def length_to_mm(self, value: float) -> float:
        return value * INCH if self.inch else value

    def feed_to_mm(self, value: float) -> float:
        return value * INCH if self.inch_feed else value

    def to_dict(self) -> dict:
        """JSON-ready, for the screens and the API."""
        return {
            "motion": self.motion, "plane": self.plane, "distance": self.distance,
            "units": self.units, "offset": self.offset, "feed": self.feed, "feed_type": self.feed_type,
            "spindle": {1: "M3", -1: "M4", 0: "M5"}[self.spindle_direction],
            "spindle_speed": self.spindle_speed, "tool": self.tool, "edge": self.edge,
            "preselected": self.preselected, "measuring_offsets": self.measuring.to_dict(),
            "diamon": self.diamon,
        }

"""The machine as the HMI sees it. A real controller would implement the same Protocol.

The machine knows only axis positions (MCS), the tool in the spindle and its offset length
as the NC holds it, the active frame (given to it as a WCS->BCS transform by the HMI), the
feed override and its alarms. It knows nothing about measuring tasks.

Conventions (design.md §3/§4): mm, deg, mm/min, seconds. MCS axis positions are those of the
tool reference point (spindle nose). Probing directions are unit vectors in MCS.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np

# Alarm numbers used by the machine (spec/jog-measuring.md §10). 61301 "probe not switched" is
# not one of them: a probe() without a switch is no fault of the machine, the measuring tasks raise it.
ALARM_PROBE_COLLISION = 61302
ALARM_LIMIT = 21614            # "software limit switch" style alarm of the NC
ALARM_PROBE_BROKEN = 61302     # overtravel beyond the permissible deflection (measuring-math §1.3);
                               # same number as a collision, but not resettable
ALARM_RESET = 16900            # motion aborted by Reset (informational, cleared by Reset)


@dataclass(frozen=True)
class Alarm:
    code: int
    text: str
    resettable: bool = True


class MachineAlarm(Exception):
    """A machine fault that stopped a motion. The alarm is also in ``status().alarms``."""

    def __init__(self, alarm: Alarm):
        super().__init__(f"{alarm.code}: {alarm.text}")
        self.alarm = alarm


class MachineBusy(Exception):
    """A motion is already running."""


@dataclass(frozen=True)
class ActiveFrame:
    """What the machine needs to show and command WCS positions."""

    name: str = "G500"                              # G54.., G500
    wcs2bcs: np.ndarray = field(default_factory=lambda: np.eye(4))  # 4x4 homogeneous
    rotary_offsets: dict[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class MachineStatus:
    mcs: dict[str, float]            # tool reference point, X/Y/Z (+ rotary axes)
    wcs: dict[str, float]            # tool tip (probe ball centre) in the active WCS
    active_offset: str               # "G54".. or "G500"
    tool: int | None
    tool_length: float               # offset length the NC uses (L1 along the tool axis)
    feed_override: float             # percent
    spindle_angle: float             # deg (SPOS)
    spindle_speed: float             # rpm, 0 = stationary
    busy: bool
    alarms: tuple[Alarm, ...]
    mode: str = "JOG"
    plane: str = "G17"
    tool_axis: tuple[float, float, float] = (0.0, 0.0, 1.0)   # MCS unit vector tip -> spindle (swivel head)


@dataclass(frozen=True)
class MoveResult:
    """End of a positioning/jog move. ``completed`` is False when stopped (alarm, Reset)."""

    mcs: dict[str, float]
    completed: bool
    alarm: Alarm | None = None


@dataclass(frozen=True)
class ProbeResult:
    """One measuring move (MEAS): latched axis positions at the trigger, or not triggered."""

    triggered: bool
    latched_mcs: dict[str, float] | None   # axis positions latched on the fly
    end_mcs: dict[str, float]              # where the axes stopped (after braking)
    feed: float                            # programmed feed (mm/min), before override
    override: float                        # percent in effect


@runtime_checkable
class Machine(Protocol):
    def status(self) -> MachineStatus: ...

    def jog(self, axis: str, distance: float, feed: float | None = None) -> MoveResult:
        """Incremental jog of one axis by ``distance`` (mm or deg), collision-monitored."""

    def jog_continuous(self, axis: str, direction: int, feed: float | None = None) -> None:
        """Start a continuous jog (+1/-1) in the background until ``stop()`` or a limit."""

    def stop(self) -> None:
        """Stop motion without an alarm (jog key released)."""

    def goto(self, target_mcs: dict[str, float], feed: float | None = None) -> MoveResult:
        """Straight positioning to ``target_mcs`` (missing axes stay); rapid when feed is None.

        A probe switch on the way stops the axes with alarm 61302 (MoveResult.alarm set).
        """

    def probe(self, direction, distance: float, feed: float) -> ProbeResult:
        """Measuring move along ``direction`` (MCS unit vector) over ``distance`` at ``feed``."""

    def change_tool(self, tool: int | None, offset_length: float) -> None:
        """Put tool ``tool`` into the spindle; the NC uses ``offset_length`` as its L1."""

    def set_tool_offset(self, offset_length: float) -> None:
        """Update the active tool's offset length (after a length calibration)."""

    def activate_frame(self, frame: ActiveFrame) -> None: ...

    def spindle_position(self, angle: float) -> None:
        """SPOS: orient the spindle (the probe's eccentricity turns with it)."""

    def spindle_rotate(self, speed_rpm: float) -> None:
        """Spindle rotation for tool measuring (0 stops it)."""

    def set_override(self, percent: float) -> None: ...

    def reset(self) -> None:
        """Abort any motion and clear resettable alarms."""

    def post_alarm(self, alarm: Alarm) -> None:
        """Show an alarm raised by a measuring cycle (61301, 61367..) until Reset."""

    @property
    def axes(self) -> tuple[str, ...]: ...

"""``NcRuntime``: what the interpreter needs from the machine (the product implements it on its
machine service; the tests implement it with a fake and on ``app.machine.sim.SimulatedMachine``).

Conventions (design.md §3): mm, deg, mm/min. MCS positions are the axis positions of the tool
reference point (spindle nose), as ``app.machine.protocol.Machine`` reports them. The interpreter
does the coordinate work itself: it asks for the frame chain of the active settable offset and the
tool's offset length and sends MCS axis targets (tool length along the plane's infeed axis).

Every command blocks until it is done. A command the machine refuses or aborts (collision, limit
switch, Reset, unknown tool, broken probe) raises ``NcRuntimeError`` with the catalogue entry;
the interpreter then stops the program with an ``NcAlarm`` at the block that gave the command.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import NamedTuple, Protocol, runtime_checkable

from engine.frames import FrameChain

from .errors import NcRuntimeError

__all__ = ["MeasureResult", "NcRuntime", "NcRuntimeError"]


class MeasureResult(NamedTuple):
    """One measuring move: did the probe switch, and the axis positions latched on the fly (MCS)."""

    triggered: bool
    latched_mcs: Mapping[str, float] | None


@runtime_checkable
class NcRuntime(Protocol):
    """The machine as the part-program interpreter drives it."""

    @property
    def axes(self) -> tuple[str, ...]:
        """Axis names: X, Y, Z, then the rotary axes (A, B, C) the machine has."""

    def position(self) -> Mapping[str, float]:
        """The axis positions now (MCS, every axis of ``axes``)."""

    def move(self, target_mcs: Mapping[str, float], feed: float | None) -> None:
        """Straight, collision-monitored positioning to ``target_mcs`` (axes not named stay);
        rapid when ``feed`` is None, else ``feed`` mm/min. A probe switch on the way is a collision
        (``NcRuntimeError`` with PROBE_COLLISION)."""

    def measure(self, target_mcs: Mapping[str, float], feed: float, stop_on_trigger: bool) -> MeasureResult:
        """Measuring move (MEAS/MEAW, G100) straight to ``target_mcs`` at ``feed`` mm/min.

        The positions are latched on the probe's switching edge. ``stop_on_trigger`` (MEAS, G100):
        the axes brake and the distance to go is deleted; otherwise (MEAW) they go on to the end
        point. No switch is not an error here: ``MeasureResult(False, None)``."""

    def offset_chain(self, name: str) -> FrameChain:
        """WCS -> BCS for the settable offset ``name`` ("G54".."G57", "G505".."G599"), with the
        system and basic frames below it; "G500": the basic chain only (identity settable frame).
        An offset the control does not have: ``NcRuntimeError`` (ZO_NUMBER)."""

    def active_offset(self) -> str:
        """The settable offset active now ("G54".., or "G500"): where a program starts from."""

    def activate_offset(self, name: str) -> None:
        """Make ``name`` the control's active settable offset (display, JOG), as G54.. in a program does."""

    def tool_state(self) -> tuple[int | None, int]:
        """(T in the spindle or None, active D number; 0 = no offset)."""

    def tool_length(self, tool: int | None, edge: int) -> float:
        """Offset length L1 (mm) the NC uses for ``tool`` with cutting edge D ``edge``:
        geometry + wear as the control holds it; 0 for no tool or D0. Unknown tool or D:
        ``NcRuntimeError`` (NO_TOOL_FOR_IDENTIFIER / NC_D_NUMBER)."""

    def change_tool(self, tool: int | None, edge: int) -> None:
        """M6: put ``tool`` (None = empty the spindle) into the spindle, edge ``edge`` active."""

    def select_edge(self, edge: int) -> None:
        """D: make edge ``edge`` of the tool in the spindle active (its offset length)."""

    def spindle(self, direction: int, speed: float) -> None:
        """M3 (``direction`` +1), M4 (-1) at ``speed`` rev/min, M5 (0) stops."""

    def spindle_position(self, angle: float) -> None:
        """SPOS: orient the (stopped) spindle to ``angle`` degrees."""

    def lathe_lengths(self) -> tuple[float, float]:
        """A lathe only (an ``is_lathe`` property that is true): the effective (L1, L2) of the tool
        in the turret; the tip is F − (L1·x̂ + L2·ẑ) (turning.md §0.1)."""

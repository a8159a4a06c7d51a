"""What a measurement is evaluated in: the measuring context, and what the workflow needs from the app.

``MeasuringContext`` is the snapshot of frames, tool, probe record and settings taken at NC
Start; ``WorkflowEnv`` is implemented by ``app.services.measuring.MeasuringEnv``; a finisher
turns a session's stored points into (answer, commit) for one task family.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Protocol

from app.gud import GudSettings
from app.machine.protocol import Machine
from app.workflow.session import MeasureSession
from engine.frames import Frame, FrameChain, is_basic, parent2bcs_of
from engine.planes import Plane
from engine.types import ProbeRecord

MEASURE_ONLY = "measure_only"


@dataclass(frozen=True)
class MeasuringContext:
    """Snapshot of everything a measurement needs, taken when NC Start is pressed."""

    active_offset: str                  # WO active while measuring ("G500", "G54", ..)
    offsets: dict[str, Frame]           # every stored frame by name
    frame_chain: FrameChain             # WCS -> BCS while measuring (settable = active_offset)
    basic_names: tuple[str, ...]        # names of frame_chain.basic (BASIC_0, BASIC_1, ..)
    plane: Plane
    tool_length: float                  # NC offset length of the tool in the spindle
    tool: dict | None                   # tool table row of the tool in the spindle
    spindle_angle: float
    feed_override: float
    settings: GudSettings               # GUD settings (app.gud)
    probe: ProbeRecord | None           # active workpiece probe record, None if no probe
    probe_data: dict | None = None      # the stored probe record as JSON
    extra: dict = field(default_factory=dict)

    def chain(self) -> FrameChain:
        return self.frame_chain

    @staticmethod
    def in_chain(target: str) -> bool:
        """A basic frame (BASIC_REF, BASIC_n): always part of the active chain, unlike a WO."""
        return is_basic(target)

    def parent2bcs_of(self, target: str) -> Frame:
        """Composition of the frames outside ``target`` (MCS side first) while measuring."""
        return parent2bcs_of(self.offsets, target)


@dataclass(frozen=True)
class OffsetOutcome:
    """A computed zero-offset write: frames as API dicts, the audit detail, what the answer shows."""

    before: dict
    after: dict
    detail: dict
    answer: dict          # merged into the calculate answer (correction, set-up support, activation)


@dataclass(frozen=True)
class OffsetChange:
    """A zero-offset write that is computed inside the write transaction from the frames as
    stored then (design.md §9.1): components the task does not determine keep their value."""

    target: str
    compute: Callable[[Mapping[str, Frame]], OffsetOutcome]


@dataclass(frozen=True)
class MeasuringSetup:
    """What opening a task screen needs: cheap to get (no tool, probe or frame data)."""

    plane: Plane
    active_offset: str
    offset_names: tuple[str, ...]
    settings: GudSettings


@dataclass(frozen=True)
class ToolOffsetOutcome:
    """A decided tool-offset write (design.md §9.3): the tool data after (None: not written), the
    memory values to write, the result keys and the correction the answer and the log show."""

    tool: int
    after: dict | None
    memories: dict                  # {("EV"|"MV", n): value}
    result: dict                    # deviation, mean_value, decision, compensation, alarm, ...
    correction: dict
    repeat: bool = False            # the repeat rule asks for another measurement (measuring-math §3.6)


@dataclass(frozen=True)
class ToolOffsetChange:
    """A tool-offset decision made inside the write transaction from the tool data and the
    EV/MV memories as stored then: ``compute(tool_row, memory(kind, n))``."""

    tool: int
    compute: Callable[[dict, Callable[[str, int], float]], ToolOffsetOutcome]


class WorkflowEnv(Protocol):
    """What the app provides to the workflow (implemented in app.services)."""

    @property
    def machine(self) -> Machine: ...     # read-only: the app rebuilds it on a lathe/mill switch

    def measuring_context(self) -> MeasuringContext: ...

    def measuring_setup(self) -> MeasuringSetup: ...

    def commit_measurement(self, *, offset: OffsetChange | None = None, log_entry: dict,
                           probe_update: tuple[int, dict] | None = None,
                           tool_update: tuple[int, dict] | None = None,
                           tool_probe_update: tuple[int, dict] | None = None,
                           tool_offset: ToolOffsetChange | None = None,
                           kinematics_update: dict | None = None
                           ) -> tuple[int, OffsetOutcome | ToolOffsetOutcome | None]:
        """Offset + audit + log (+ data records) in one transaction; (log id, what was decided)."""

    def activate(self, name: str) -> None: ...

    def refresh_frames(self) -> None:
        """Re-send the active frame chain to the machine (after a basic frame changed)."""

    def post_alarm(self, code: int, text: str) -> None: ...

    def interlock(self, action: str) -> None:
        """Raise ``ModeError`` when the channel's mode refuses ``action`` (a program runs)."""


# A finisher turns the stored points (in the context's WCS) into (answer, commit kwargs).
Finisher = Callable[[MeasureSession, MeasuringContext, list], tuple[dict, dict]]


def points_of(session: MeasureSession) -> list:
    return [s.point for s in session.slots]

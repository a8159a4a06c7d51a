"""The machine as the HMI sees it. A real controller would implement the same Protocol.

The machine knows only axis positions (MCS), the tool in the spindle and its offset length
as the NC holds it, the active frame (given to it as a WCS->BCS transform by the HMI), the
feed override and its alarms. It knows nothing about measuring tasks.

Conventions (design.md §3/§4): mm, deg, mm/min, seconds. MCS axis positions are those of the
tool reference point (spindle nose). Probing directions are unit vectors in MCS.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Protocol, runtime_checkable

import numpy as np

from engine.alarms import AlarmDef


@dataclass(frozen=True)
class Alarm:
    """An alarm as the machine shows it: the catalogue's number, a text naming what happened.

    The machine raises collisions, a broken probe, limit switches and Reset aborts
    (``engine.alarms``); "probe not switched" is not one of them: a probe() without a switch is
    no fault of the machine, the measuring tasks raise it.
    """

    code: int
    text: str
    resettable: bool = True

    @classmethod
    def of(cls, definition: AlarmDef, text: str | None = None) -> Alarm:
        """The catalogue entry ``definition`` with an optional text saying what happened."""
        return cls(definition.number, text or definition.text, definition.resettable)

    def is_(self, definition: AlarmDef) -> bool:
        return self.code == definition.number and self.resettable == definition.resettable


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
class ProbeState:
    """What a probe tells the control besides its switch (design.md §10.4).

    ``in_spindle``: the workpiece probe is the tool in the spindle (the tool probe: it is there);
    ``armed``/``battery``: a radio or optical probe is switched on / its charge 0..1 (None: a
    cable probe, always ready); ``deflected``: the probe signal is on now (None: not known)."""

    in_spindle: bool
    armed: bool | None = None
    deflected: bool | None = False
    battery: float | None = None

    def to_api(self) -> dict:
        return {"in_spindle": self.in_spindle, "armed": self.armed, "deflected": self.deflected,
                "battery": self.battery}


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
    tool_axis: tuple[float, float, float] = (0.0, 0.0, 1.0)   # MCS unit vector tip -> spindle (swivel head,
    #                                                           horizontal spindle: scenario machine.spindle_axis)
    probe: ProbeState | None = None          # the workpiece probe; None: the controller cannot tell
    tool_probe: ProbeState | None = None     # the tool probe; None: none, or the controller cannot tell
    estop: bool = False                      # the controller's emergency stop is active (design.md §10.7)
    machine_on: bool = True                  # the drives are on (LinuxCNC: task state ON)
    # where the control's head kinematics put the spindle nose relative to the X/Y/Z axis position
    # (MCS, mm; design.md §10.6): 0 for a head turning about the tool reference point, or no head
    head_shift: tuple[float, float, float] = (0.0, 0.0, 0.0)


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
    """What every controller offers the HMI (the simulator now, LinuxCNC later).

    The NC owns what a control owns (design.md, Standards): the active frame, the named zero
    offsets and the tool data as it holds them; the HMI writes them through this interface and
    keeps history, audit and log itself. Motion calls block until the motion ends (or is
    stopped); ``status()`` may be called from any thread meanwhile. Bad arguments (unknown
    axis, non-finite numbers, malformed data) raise ValueError; faults raise MachineAlarm.
    tests/contract/test_machine_contract.py is the executable form of this contract.
    """

    @property
    def controller(self) -> str:
        """Which controller this is: "sim", "linuxcnc" (GET /api/machine, design.md §9.6)."""

    @property
    def axes(self) -> tuple[str, ...]:
        """Axis names: X, Y, Z, then the rotary axes."""

    def status(self) -> MachineStatus: ...

    # --- motion ---------------------------------------------------------------------------
    def jog(self, axis: str, distance: float, feed: float | None = None) -> MoveResult:
        """Incremental jog of one axis by ``distance`` (mm or deg), collision-monitored."""

    def jog_continuous(self, axis: str, direction: int, feed: float | None = None) -> None:
        """Start a continuous jog (+1/-1) in the background until ``stop()`` or a limit."""

    def stop(self) -> None:
        """Stop motion without an alarm (jog key released)."""

    def goto(self, target_mcs: dict[str, float], feed: float | None = None) -> MoveResult:
        """Straight positioning to ``target_mcs`` (missing axes stay); rapid when feed is None.

        A probe switch on the way stops the axes with a collision alarm (MoveResult.alarm set).
        """

    def probe(self, direction, distance: float, feed: float) -> ProbeResult:
        """Measuring move along ``direction`` (MCS unit vector) over ``distance`` at ``feed``."""

    def reset(self) -> None:
        """Abort any motion and clear resettable alarms."""

    # --- spindle and tool -------------------------------------------------------------------
    def change_tool(self, tool: int | None, offset_length: float) -> None:
        """Put tool ``tool`` into the spindle; the NC uses ``offset_length`` as its L1."""

    def set_tool_offset(self, offset_length: float) -> None:
        """Update the active tool's offset length (after a length calibration)."""

    def write_tool(self, t: int, data: dict) -> None:
        """The control's tool data of T ``t``: ``{"type", "length", "radius", "wear": {"length", "radius"}}``.

        A malformed shape raises ValueError naming the field; motion keeps using the offset
        length of ``change_tool``/``set_tool_offset``."""

    def spindle_position(self, angle: float) -> None:
        """SPOS: orient the spindle (the probe's eccentricity turns with it)."""

    def spindle_rotate(self, speed_rpm: float) -> None:
        """Spindle rotation for tool measuring (0 stops it)."""

    def set_override(self, percent: float) -> None:
        """Feed override 0..120 % (ValueError outside); acts on the feed in effect of every motion."""

    # --- frames -----------------------------------------------------------------------------
    def write_offset(self, name: str, frame: dict) -> None:
        """The control's copy of a named zero offset (G54.., BASIC_n): ``{"trans", "fine", "rot"}``.

        Each part is keyed by axis (``trans``: the machine's axes, ``fine``/``rot``: X, Y, Z). A
        malformed shape raises ValueError naming the field; a controller that cannot hold
        ``name`` (or its rotation) raises MachineAlarm before anything changes. Writing does not
        activate: display and motion follow ``activate_frame``."""

    def activate_frame(self, frame: ActiveFrame) -> None:
        """Make ``frame`` (the composed WCS -> BCS chain) the one motion and display use."""

    # --- alarms and life cycle -----------------------------------------------------------------
    def post_alarm(self, alarm: Alarm) -> None:
        """Show an alarm raised by a measuring cycle (probe not switched, ...) until Reset."""

    def close(self) -> None:
        """Stop motion and release the controller (the HMI shuts down)."""


@runtime_checkable
class SwivelHead(Protocol):
    """Optional: a machine with swivel kinematics (CYCLE800-like re-alignment, jog-measuring §6.2)."""

    def has_swivel(self) -> bool: ...

    def head_axes(self) -> tuple[str, ...]:
        """The head's rotary axes in their order (ValueError without a swivel head)."""

    def retract_tool_axis(self, distance: float | None = None) -> MoveResult: ...

    def swivel_to_wcs(self, wcs2bcs_rotation, infeed=(0.0, 0.0, 1.0)) -> MoveResult: ...


@runtime_checkable
class KinematicData(Protocol):
    """Optional: a control that holds rotary-axis kinematic data (design.md §10.6): the axis lines
    ``{axis: {"point": [x, y, z], "direction": [dx, dy, dz]}}`` at the zero position of every
    rotary axis (head axes relative to the tool reference point, a table's in MCS)."""

    def kinematic_data(self) -> dict[str, dict[str, Any]]: ...

    def write_kinematic_data(self, lines: dict) -> None:
        """Replace the lines of the axes given (others keep theirs); ValueError names a bad axis."""


@runtime_checkable
class MachineData(Protocol):
    """Optional: a control whose machine data the HMI can read (manual ch. 9): MD number (text,
    "18118") -> value, a list for an array datum (app.machine.machine_data)."""

    def machine_data(self) -> dict[str, Any]: ...


@runtime_checkable
class Lathe(Protocol):
    """Optional: a lathe (turning.md §10.2): X in MCS is a radius, with DIAMON the control shows and
    takes it as a diameter; the tools sit in a turret and their lengths L1/L2 come from the NC's
    tool data; SPOS turns the clamped part. The HMI asks ``isinstance(machine, Lathe)``."""

    @property
    def diameter_programming(self) -> bool:
        """DIAMON: X shown and programmed as a diameter."""

    @property
    def spos_capable(self) -> bool:
        """The main spindle can be positioned (SPOS); else the cycles refuse what needs it."""


@runtime_checkable
class ProtectedSpace(Protocol):
    """Optional: a control with a commissioned model of its work space (the start guard, issue 24 §1)."""

    def protection_model(self) -> dict:
        """The solids and axis limits the control protects (plain data, MCS)."""


@runtime_checkable
class ProbeReach(Protocol):
    """Optional: a control that knows how far its axes run on behind a probe switch (the start
    guard's reach check, measuring-math §1.3, issue 24 §1) and the probes' permissible deflection."""

    def probe_braking(self) -> dict:
        """``{"latency_s": t [s], "decel": a [m/s²], "kv": Kv [(m/min)/mm], "max_deflection":
        {"workpiece": mm, "tool": mm or None}}`` (None: that probe is not broken by overtravel)."""


@runtime_checkable
class FrameCapacity(Protocol):
    """Optional: a control that cannot hold every frame the HMI offers (LinuxCNC: no tilted G54)."""

    def holds(self, name: str, frame: dict) -> Alarm | None:
        """None when the NC can hold ``frame`` as ``name``; else the alarm it refuses it with."""


@runtime_checkable
class OwnConfiguration(Protocol):
    """Optional: a control started on the machine's own configuration (LinuxCNC ``--linuxcnc-ini``):
    its INI file and the tool table it holds, which the HMI takes over at its start."""

    @property
    def own_ini(self):
        """The machine's own INI file (a path), None on a generated configuration."""

    def nc_tool_table(self) -> dict[int, dict]:
        """{T: {"length", "radius"}} as the control holds them; {} on a generated configuration."""


@runtime_checkable
class SimulatorControl(Protocol):
    """Only the simulator offers these: its truth (never used for measuring), scenario load and
    the time scale. The HMI asks ``isinstance(machine, SimulatorControl)`` before using them."""

    @property
    def scenario(self): ...

    def load(self, scenario) -> None:
        """Replace the truth and reset the machine (axes to the start position, probe in spindle)."""

    def scene_geometry(self) -> dict:
        """The true scene for the machine view (JSON-ready, MCS)."""

    def machine_part(self, scatter_sigma: float = 0.0) -> int:
        """The next part of a machined-part series replaces the workpiece (design.md §9.3)."""

    def set_probe(self, which: str, deflect: bool | None = None, battery: float | None = None,
                  armed: bool | None = None) -> None:
        """The operator's hand on probe ``which`` ("workpiece", "tool"): deflect or release it,
        change the battery, switch a radio probe on or off (design.md §10.4). ValueError names
        the field."""

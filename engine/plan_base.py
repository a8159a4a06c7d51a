"""Planning contracts and the common probing execution (spec/jog-measuring.md §2.4).

``PlanContext`` (``ParamError`` is engine.checks'), the stored points of calibration and tool
tasks, and ``Motion``: the positioning/probing helper every point program uses. Re-exported
by ``engine.plan`` (the public module).
"""

from __future__ import annotations

from collections.abc import Generator, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Literal, TypeGuard

import numpy as np
import numpy.typing as npt

from engine import alarms
from engine.frames import Frame
from engine.planes import Plane
from engine.types import (
    FloatArray,
    Latch,
    MeasuringError,
    MoveStep,
    ProbeRecord,
    ProbeStep,
    SpindleStep,
    Step,
    probe_record,
)

if TYPE_CHECKING:
    from engine.types import HitLatch

TWO_STAGE_RETRACT = 2.0   # mm back after the fast first touch (jog-measuring §2.4 step 3, jog-measuring §8.4 _SPEED[3])


@dataclass(frozen=True)
class PlanContext:
    plane: Plane
    probe_record: ProbeRecord | None    # the workpiece probe (_WP); None: no probe in the spindle
    skew_wcs: FloatArray            # from compensation.skew_in_wcs
    spindle_angle: float = 0.0      # SPOS while probing (a probe's lobing map turns with it)
    wcs2bcs: Frame | None = None    # measuring WCS -> BCS (the lobing map's directions are machine ones)
    measuring_feed: float = 300.0   # E_MESS_FM
    position_feed: float = 2000.0   # E_MESS_F (plane)
    position_feed_infeed: float = 2000.0  # E_MESS_FZ
    measuring_path: float = 50.0    # E_MESS_D_M
    attempts: int = 1               # 1 (_JM_B[1]=1) or 5
    fast_feed: float | None = None  # _SPEED[3] when _JM_B[3]=1 (two-stage), else None
    rapid_return: bool = False      # _JM_B[2]
    spigot_safety: float = 5.0
    ring_chords: bool = False       # ring calibration also along chords off the centre (design.md §9.8)
    # --- tool measuring (jog-measuring §7, jog-measuring §8.3 GUD7 E_MESS_MT_*; tool probe record _TP[n] jog-measuring §8.4) -----
    tool_probe: dict[str, float] | None = None  # _TP[n,0..4] by travel key "X-","X+","Y-","Y+","Z-" (MCS, tool edge)
    tool_radius: float = 0.0        # active tool R (geometry + wear) as the NC knows it
    tool_length: float = 0.0        # active tool L1 the NC uses for the tip (informative)
    mt_axes: int = 133              # E_MESS_MT_AX digit code (units X, tens Y, hundreds Z)
    mt_diameter_length: float = 0.0  # E_MESS_MT_DL: probe width for length measuring
    mt_diameter_radius: float = 0.0  # E_MESS_MT_DR: probe width for radius measuring
    mt_dz: float = 2.0              # E_MESS_MT_DZ: tool lower edge below the probe's upper edge
    mt_dir: int = -1                # E_MESS_MT_DIR: approach along -1st (−1) / +1st (+1) axis
    mt_path: float = 10.0           # E_MESS_MT_D: calibration / rotating-spindle measuring path
    mt_feed: float = 100.0          # E_MESS_MT_FM
    path_length: float = 2.0        # E_MESS_D_L (stationary length; fine-stage path)
    path_radius: float = 1.0        # E_MESS_D_R (stationary radius; fine-stage path)
    max_surface_speed: float = 100.0  # E_MESS_MAX_V [m/min]
    max_spindle_speed: float = 1000.0  # E_MESS_MAX_S [rpm]
    max_feed_rotating: float = 20.0  # E_MESS_MAX_F
    min_feed_rotating: float = 1.0   # E_MESS_MIN_F
    feed_factor1: float = 10.0      # E_MESS_F_FAK1
    feed_factor2: float = 0.0       # E_MESS_F_FAK2
    min_accuracy: float = 0.01      # E_MESS_MIN_D

    @property
    def probe(self) -> ProbeRecord:
        """The workpiece probe record; NoProbeRecord when there is none (a tool task's context
        has none: it measures a cutter)."""
        return probe_record(self.probe_record, "planning a workpiece probing")


# --- stored points of calibration and tool tasks (raw data in, not results) ---------------

@dataclass(frozen=True)
class RingPass:
    """One pass in the ring gauge (jog-measuring §5.3): raw recs (WCS, no skew, no triggers).

    ``rec``/``latched_mcs`` keyed by travel direction "X+", "X-", ... (+1st, −1st, +2nd, −2nd).
    A pass of an n-direction calibration (engine.lobing) keys them by its own labels and gives
    each label's unit travel direction (WCS) in ``directions``; axis keys need none.
    """

    spindle_angle: float
    rec: dict[str, FloatArray]
    latched_mcs: dict[str, FloatArray | None] = field(default_factory=dict)
    directions: dict[str, FloatArray] = field(default_factory=dict)


@dataclass(frozen=True)
class RingCalibrationPoint:
    """probe.radius: ring diameter, centre search (spindle 0°) and the passes at 180° then 0°."""

    diameter: float
    search: RingPass
    passes: tuple[RingPass, ...]    # (SPOS 180°, SPOS 0°) — measuring-math §7.3 m180, m0


@dataclass(frozen=True)
class BoreCalibrationPoint:
    """CYCLE976 in a bore along some directions (manual §5.3.1/§5.3.2, measuring-math §7.2–7.4).

    ``keys`` name the directions "+1", "-1", "+2", "-2" (1st/2nd plane axis turned by ``angle``,
    _STA1), in probing order; ``units`` their WCS travel directions; ``rec`` the raw recs (WCS,
    no skew) of the final pass.
    ``centre``: the known bore centre MP (the start), or None: unknown centre, then
    ``pass_centres`` = (m180, m0), the raw centres of the passes at SPOS 180° and 0°.
    """

    diameter: float
    angle: float
    keys: tuple[str, ...]
    units: tuple[FloatArray, ...]
    rec: tuple[FloatArray, ...]
    centre: FloatArray | None = None
    pass_centres: tuple[FloatArray, FloatArray] | None = None


@dataclass(frozen=True)
class ToolTouch:
    """One tool-probe touch: tool tip (MCS) at switching; ``key`` = travel direction "Z-", "X+"."""

    key: str
    rec: FloatArray
    latched_mcs: FloatArray | None = None
    feed: float = 0.0


@dataclass(frozen=True)
class ToolProbePoint:
    """toolprobe.calibrate: touches in probing order (the final "Z-" at the found centre last).

    ``tool_radius``/``tool_length``: the calibration tool's data used (jog-measuring §7.2 formulas).
    """

    mode: str
    touches: tuple[ToolTouch, ...]
    tool_radius: float
    tool_length: float


@dataclass(frozen=True)
class ToolPoint:
    """tool.length / tool.diameter: the final (finest) touch and how it was made (jog-measuring §7.3)."""

    kind: str                      # "length" | "radius"
    touch: ToolTouch               # final touch (L1 = F_z − _TP[n,4]; R = F_a − _TP[n,0] ...)
    rotating: bool
    speed: float                   # rpm, 0 = stationary
    feeds: tuple[float, ...]       # feeds of the probing stages, last = final
    offset_v: float
    lateral_offset: float          # length: tool axis offset from the probe centre along +1st
    tool_radius: float
    tool_length: float


# --- common probing execution -------------------------------------------------------------

def hit(latch: Latch | None) -> TypeGuard[HitLatch]:
    return latch is not None and latch.triggered and latch.rec is not None


class Motion:
    """Tracks the NC reference position and builds steps (jog-measuring §2.4 steps 2, 3, 5, 6).

    Targets are NC reference positions in ``coords`` (WCS: ball centre/tip as the NC knows it;
    MCS: tool tip). ``ball_offset`` = true ball centre − NC reference (skew, jog-measuring §1.3 / measuring-math §5.2):
    ``to_ball`` commands the reference so that the *ball* reaches a point.
    """

    def __init__(self, start: npt.ArrayLike, ctx: PlanContext, coords: str = "WCS",
                 ball_offset: npt.ArrayLike | None = None) -> None:
        self.pos = np.asarray(start, dtype=float).copy()
        self.start = self.pos.copy()
        self.ctx = ctx
        self.coords = coords
        self.ball_offset = np.zeros(3) if ball_offset is None else np.asarray(ball_offset, float)

    def feed_for(self, target: FloatArray) -> float:
        """E_MESS_FZ for pure infeed-axis moves, else E_MESS_F (jog-measuring §2.4 step 1)."""
        delta = target - self.pos
        p = self.ctx.plane.infeed_unit
        in_plane = delta - float(delta @ p) * p
        if np.linalg.norm(in_plane) <= 1e-12 and abs(float(delta @ p)) > 0.0:
            return self.ctx.position_feed_infeed
        return self.ctx.position_feed

    def move(self, target: npt.ArrayLike, label: str = "", feed: float | None | Literal["auto"] = "auto"
             ) -> list[Step]:
        """Monitored intermediate positioning (61302 on a switch, jog-measuring §2.4 step 2).

        ``feed``: a feed, None (rapid) or "auto" (``feed_for``)."""
        to = np.asarray(target, dtype=float)
        if all(abs(a - b) <= 1e-12 for a, b in zip(to.tolist(), self.pos.tolist(), strict=True)):
            return []                   # np.allclose(rtol=0, atol=1e-12) without its cost per move
        f = self.feed_for(to) if isinstance(feed, str) else feed      # str: "auto"
        self.pos = to.copy()
        return [MoveStep(target=to.copy(), feed=f, monitored=True, coords=self.coords, label=label)]

    def to_ball(self, ball_target: npt.ArrayLike, label: str = "") -> list[Step]:
        return self.move(np.asarray(ball_target, float) - self.ball_offset, label)

    def back(self, target: npt.ArrayLike, label: str = "return") -> list[Step]:
        """Return move: rapid with _JM_B[2]=1, else positioning feed (jog-measuring §2.4 step 6)."""
        to = np.asarray(target, dtype=float)
        feed: Literal["auto"] | None = None if self.ctx.rapid_return else "auto"
        return self.move(to, label, feed)

    def probe(self, direction: npt.ArrayLike, distance: float, label: str, *, expected: float | None = None,
              feeds: Sequence[float] | None = None, fine_retract: float = TWO_STAGE_RETRACT
              ) -> Generator[Step, Latch | None, HitLatch]:
        """Probe from the current position; retries and multi-stage probing (jog-measuring §2.4 3–5).

        ``feeds`` default: [_SPEED[3], E_MESS_FM] with _JM_B[3]=1, else [E_MESS_FM]. Every later
        stage retracts ``fine_retract`` against the travel from the latched position and probes
        over 2·fine_retract. No switch (in any stage): back to the stroke start and retry, up to
        ``ctx.attempts`` (_JM_B[1]); then 61301.
        """
        d = np.asarray(direction, dtype=float)
        if feeds is None:
            ctx = self.ctx
            feeds = [ctx.fast_feed, ctx.measuring_feed] if ctx.fast_feed else [ctx.measuring_feed]
        origin = self.pos.copy()
        for attempt in range(max(1, int(self.ctx.attempts))):
            if attempt:
                yield from self.move(origin, f"{label} retry {attempt + 1}")
            latch = yield ProbeStep(direction=d.copy(), distance=float(distance), feed=float(feeds[0]),
                                    coords=self.coords, label=label, expected=expected)
            if not hit(latch):
                self.pos = origin + float(distance) * d
                continue
            self.pos = np.asarray(latch.rec, dtype=float).copy()
            for stage, f in enumerate(feeds[1:], start=2):
                yield from self.move(latch.rec - fine_retract * d, f"{label} retract")
                fine = yield ProbeStep(direction=d.copy(), distance=2.0 * fine_retract, feed=float(f),
                                       coords=self.coords, label=f"{label} stage {stage}",
                                       expected=fine_retract)
                if not hit(fine):
                    self.pos = self.pos + 2.0 * fine_retract * d
                    latch = None
                    break
                latch = fine
                self.pos = np.asarray(latch.rec, dtype=float).copy()
            if latch is not None:
                return latch
        raise MeasuringError(alarms.PROBE_NOT_SWITCHED, "Probe not switched")


def spindle(angle: float | None = None, speed: float | None = None, label: str = "") -> SpindleStep:
    return SpindleStep(angle=angle, speed=speed, label=label)

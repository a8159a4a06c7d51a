"""The probing program of one position of ``kinematics.measure`` (design.md §10.6, CYCLE996-like).

Pure: yields steps, receives latches (engine.plan). Coordinates are MCS of the NC's ball centre
(the executor converts with the control's kinematic data). One position:

1. up to a safe height (the start height, 2·ρ' above the sphere, or ``swivel_z``: up to the probe
   length higher, as far as the Z limit allows, since a head axis swings the ball sideways by up to
   L·sin θ), across above the sphere;
2. turn the measured axis to its position, every other rotary axis to 0 (the zero position the
   axis lines refer to, jog-measuring §6.3 "basic position of the machine kinematics");
3. over the sphere where the control expects it now (a table turns it, DIN 66217: −θ about the
   axis line), probe it radially: the top and ``ring`` points at 15° and 50° elevation
   (measuring-math §13: the ball centre lies on the sphere of radius R + ρ; ρ' = R + ρ + clearance
   is the start radius, the probe travels 2·clearance towards the centre). Each approach goes from
   the hub 2ρ' above the centre out to 2ρ'·u, then radially in: the chord between two points of
   the 2ρ' sphere at most 90° apart stays ≥ √2·ρ' from the centre. The low ring fixes the centre
   across the axis (noise σ: about σ/2.8 per coordinate with 25 touches);
4. every rotary axis back to 0 with X/Y/Z moving along so that the ball ends at the hub again (in
   between it sags below the hub by L·(cos(θ/2) − (1 + cos θ)/2), 6 mm at 40°, well clear).

The stored point: the angle and the latched X/Y/Z axis positions (engine.kinematics fits them).
"""

from __future__ import annotations

import math
from collections.abc import Generator
from dataclasses import dataclass

import numpy as np

from engine import alarms
from engine.types import FloatArray, Latch, MeasuringError, MoveStep, ProbeStep, RotaryStep, Step

ELEVATIONS_DEG = (15.0, 50.0)


@dataclass(frozen=True)
class KinematicsPoint:
    """One measured position: the axis angle, the latched X/Y/Z axis positions and directions."""

    angle: float
    latched: FloatArray       # (k, 3) MCS axis positions at the triggers
    directions: FloatArray    # (k, 3) probing directions (MCS unit vectors)
    reference: bool = False   # measured with every rotary axis at 0 (the sphere's own place)


@dataclass(frozen=True)
class SphereProgram:
    """What one position needs. ``sphere`` = centre at the zero position (MCS), ``table_line`` =
    the control's (point, direction) of the table axis when ``kind`` is "table"."""

    axis: str
    kind: str                            # "head" | "table"
    angle: float
    rotary_axes: tuple[str, ...]         # every rotary axis of the machine (the others go to 0)
    sphere: FloatArray
    sphere_diameter: float
    ball_radius: float                   # ρ
    clearance: float
    measuring_feed: float
    position_feed: float
    table_line: tuple[FloatArray, FloatArray] | None = None
    ring: int = 12                       # touches per elevation
    # another head axis held at an angle while ``axis`` turns (the outer axis of an A/C or B/C head
    # turns about the tool axis at the zero position: the inner one tilts the probe off it)
    partner: tuple[str, float] | None = None
    reference: bool = False              # this point: every rotary axis at 0 (the sphere's place)
    swivel_z: float | None = None        # ball height (MCS) to turn the axes at: clear of what stands nearby

    def expected_centre(self) -> FloatArray:
        """Where the control expects the sphere at ``angle``: fixed for a head, turned by −θ about
        the table's line for a table (DIN 66217)."""
        if self.kind != "table" or self.table_line is None:
            return np.asarray(self.sphere, dtype=float)
        point, direction = (np.asarray(v, dtype=float) for v in self.table_line)
        d = direction / np.linalg.norm(direction)
        t = math.radians(-self.angle)
        cross = np.array([[0.0, -d[2], d[1]], [d[2], 0.0, -d[0]], [-d[1], d[0], 0.0]])
        rot = math.cos(t) * np.eye(3) + math.sin(t) * cross + (1.0 - math.cos(t)) * np.outer(d, d)
        out: FloatArray = point + rot @ (np.asarray(self.sphere, dtype=float) - point)
        return out


def outward_directions(ring: int) -> list[FloatArray]:
    """Unit vectors from the sphere centre to the touch starts: the top, then ``ring`` per
    elevation (the second ring turned by half a step)."""
    out = [np.array([0.0, 0.0, 1.0])]
    for k, elevation in enumerate(ELEVATIONS_DEG):
        e = math.radians(elevation)
        for i in range(ring):
            az = 2.0 * math.pi * (i + 0.5 * k) / ring
            out.append(np.array([math.cos(e) * math.cos(az), math.cos(e) * math.sin(az), math.sin(e)]))
    return out


def _rotary(prog: SphereProgram, angle: float, label: str, partner: bool = True) -> RotaryStep:
    held = dict([prog.partner]) if prog.partner is not None and partner else {}
    return RotaryStep(tuple((a, float(angle) if a == prog.axis else float(held.get(a, 0.0)))
                            for a in prog.rotary_axes), label)


def sphere_position_program(prog: SphereProgram, start: FloatArray, label: str
                            ) -> Generator[Step, Latch | None, KinematicsPoint]:
    """The steps of one position (module docstring); returns the KinematicsPoint."""
    if not prog.sphere_diameter > 0.0:
        raise MeasuringError(alarms.SPHERE_DIAMETER, f"sphere diameter {prog.sphere_diameter:g}: must be > 0")
    rho_start = prog.sphere_diameter / 2.0 + prog.ball_radius + prog.clearance
    fixed = np.asarray(prog.sphere, dtype=float)
    centre = fixed if prog.reference else prog.expected_centre()
    safe_z = max(float(start[2]), float(fixed[2]) + 2.0 * rho_start, float(centre[2]) + 2.0 * rho_start,
                 -math.inf if prog.swivel_z is None else float(prog.swivel_z))
    here = np.asarray(start, dtype=float)
    yield MoveStep(np.array([here[0], here[1], safe_z]), None, coords="MCS", label=f"{label} up")
    yield MoveStep(np.array([fixed[0], fixed[1], safe_z]), None, coords="MCS", label=f"{label} over the sphere")
    if prog.reference:
        yield _rotary(prog, 0.0, f"{label} zero position", partner=False)
    else:
        yield _rotary(prog, prog.angle, f"{label} {prog.axis}={prog.angle:g}")
    hub = centre + np.array([0.0, 0.0, 2.0 * rho_start])
    yield MoveStep(np.array([hub[0], hub[1], max(hub[2], safe_z)]), None, coords="MCS", label=f"{label} across")
    yield MoveStep(hub, None, coords="MCS", label=f"{label} hub")
    latched, directions = [], []
    for k, u in enumerate(outward_directions(prog.ring)):
        begin = centre + rho_start * u
        far = centre + 2.0 * rho_start * u
        yield MoveStep(far, None, coords="MCS", label=f"{label} touch {k + 1} out")
        yield MoveStep(begin, prog.position_feed, coords="MCS", label=f"{label} touch {k + 1} start")
        latch = yield ProbeStep(-u, 2.0 * prog.clearance, prog.measuring_feed, coords="MCS",
                                label=f"{label} touch {k + 1}", expected=prog.clearance)
        if latch is None or not latch.triggered or latch.latched_mcs is None:
            raise MeasuringError(alarms.PROBE_NOT_SWITCHED, f"{label}: the sphere was not touched at touch {k + 1} "
                                 f"({prog.axis}={prog.angle:g}°): check the sphere's centre")
        latched.append(np.asarray(latch.latched_mcs, dtype=float))
        directions.append(-u)
        yield MoveStep(far, None, coords="MCS", label=f"{label} touch {k + 1} back")
        yield MoveStep(hub, None, coords="MCS", label=f"{label} hub")
    back = _rotary(prog, 0.0, f"{label} back to the zero position", partner=False)
    yield RotaryStep(back.axes, back.label, tip=hub)          # the ball stays over the sphere
    return KinematicsPoint(angle=0.0 if prog.reference else float(prog.angle), latched=np.array(latched),
                           directions=np.array(directions), reference=prog.reference)

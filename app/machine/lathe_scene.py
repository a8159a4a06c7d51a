"""The simulated lathe's true solids and the contact physics of its probe and tools.

Solids (MCS, X = radius direction, Z = spindle axis; scene.py's exact convex primitives and
root-finding contact, so every face and cylinder is touched exactly):

- ``part``: the chuck-clamped body of revolution. Each profile ``cylinder`` is a body, every
  ``bore`` a cut-out of each; the part axis runs through ``e(φ) = Rot_z(φ)·e₀`` (the clamping
  eccentricity turning with the spindle, φ = SPOS, counter-clockwise seen from +Z, turning.md
  turning §11) and is tilted by ``face_runout_deg`` towards the direction (cos φ, sin φ), pivoting on
  the chuck face: a face at part z lies at ``z + r·tan τ·cos(θ − φ)``. A bore that reaches an
  end of the part is open there (its cut-out reaches beyond).
- ``chuck``: everything at Z below ``chuck_face_z`` (turning.md §10.2 [I]); it does not turn.
- ``groove``: the rings of the reference grooves (lathe_scenario ``bodies``), machine-fixed.
- ``tool_probe``: the cube, faces at the scenario's ``faces``, ``y_size`` deep in Y.

Contact (decisions where the spec leaves room):
- The workpiece probe: its true ball (radius ball_diameter/2 about F − (l1, l2)) against every
  solid; it switches after the pre-travel of its travel direction (keys of the probe, which
  sits in the turret and does not turn: the machine's axes, physics.pretravel_along); an
  already deflected probe pressing deeper switches at once. A switch during positioning is a
  collision (61302), braking beyond ``max_deflection`` breaks the stylus.
- A turning tool: its nose ball (radius R about S) against the tool probe switches the tool
  probe after its ``pretravel``; against the part, the chuck or a groove it is a crash (61302)
  at the contact. Overtravel of the tool probe beyond its ``max_deflection`` is a collision.
- The latch lies ``latency_s``·v behind the switch, plus Gaussian noise (the probe's
  ``noise_sigma``, seeded); the axes stop after the braking distance (measuring-math §1.3).
"""

from __future__ import annotations

import math

import numpy as np

from .contact import Event, Stop
from .lathe_kinematics import LatheKinematics, sl_unit
from .lathe_scenario import LatheScenario, LatheTool, LatheWorkpiece
from .physics import braking_distance, latency_path, pretravel_along
from .scene import Body, Box, Cylinder, Primitive, Scene

EXTEND = 1000.0          # mm: an open bore's cut-out reaches this far beyond the part
BIG = 10_000.0           # mm: the chuck's extent (a half-space for every reachable point)
OBSTACLES = ("part", "chuck", "groove")


def eccentricity_at(e0, angle_deg: float) -> np.ndarray:
    """e(φ) = Rot_z(φ)·e₀ (exact at multiples of 90°)."""
    phi = float(angle_deg) % 360.0
    exact = {0.0: (1.0, 0.0), 90.0: (0.0, 1.0), 180.0: (-1.0, 0.0), 270.0: (0.0, -1.0)}
    c, s = exact.get(phi, (math.cos(math.radians(phi)), math.sin(math.radians(phi))))
    ex, ey = float(e0[0]), float(e0[1])
    return np.array([ex * c - ey * s, ex * s + ey * c, 0.0])


def runout_rotation(tau_deg: float, angle_deg: float) -> np.ndarray:
    """The part's axis tilted by τ towards (cos φ, sin φ): rotation about u = (sin φ, −cos φ, 0)."""
    if tau_deg == 0.0:
        return np.eye(3)
    phi, tau = math.radians(angle_deg), math.radians(tau_deg)
    u = np.array([math.sin(phi), -math.cos(phi), 0.0])
    k = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
    return np.eye(3) + math.sin(tau) * k + (1.0 - math.cos(tau)) * (k @ k)


def part_pose(scenario: LatheScenario, angle_deg: float) -> tuple[np.ndarray, np.ndarray]:
    """Part -> MCS (R, base): p_mcs = base + R·(x, y, z_part)."""
    wp = scenario.workpiece or LatheWorkpiece()     # as the scenario's clearance check reads it
    base = eccentricity_at(wp.eccentricity, angle_deg)
    base[2] = wp.chuck_face_z
    return runout_rotation(wp.face_runout_deg, angle_deg), base


def _axial(rotation, base, radius: float, z0: float, z1: float) -> Cylinder:
    centre = np.asarray(base, dtype=float) + np.asarray(rotation, dtype=float) @ np.array([0.0, 0.0, (z0 + z1) / 2])
    return Cylinder(rotation, centre, radius, (z1 - z0) / 2)


def _ring(kind: str, r_in: float, r_out: float, z0: float, z1: float) -> Body:
    eye, origin = np.eye(3), np.zeros(3)
    cutouts: list[Primitive] = []
    if r_in > 0.0:
        cutouts.append(_axial(eye, origin, r_in, z0 - EXTEND, z1 + EXTEND))
    return Body(kind, _axial(eye, origin, r_out, z0, z1), cutouts)


def part_bodies(scenario: LatheScenario, angle_deg: float, diameters: dict[int, float] | None = None) -> list[Body]:
    """The part at spindle angle φ; ``diameters`` replaces profile item i's diameter (a cut part)."""
    wp = scenario.workpiece
    if wp is None or not wp.cylinders:
        return []
    rotation, base = part_pose(scenario, angle_deg)
    size = dict(diameters or {})
    z_lo = min(c.z[0] for c in wp.cylinders)
    z_hi = max(c.z[1] for c in wp.cylinders)
    bores = []
    for i, item in enumerate(wp.profile):
        if item.type != "bore":
            continue
        z0 = item.z[0] - EXTEND if item.z[0] <= z_lo + 1e-9 else item.z[0]
        z1 = item.z[1] + EXTEND if item.z[1] >= z_hi - 1e-9 else item.z[1]
        bores.append(_axial(rotation, base, size.get(i, item.diameter) / 2, z0, z1))
    return [Body("part", _axial(rotation, base, size.get(i, item.diameter) / 2, item.z[0], item.z[1]), list(bores))
            for i, item in enumerate(wp.profile) if item.type == "cylinder"]


def fixed_bodies(scenario: LatheScenario) -> list[Body]:
    """What does not turn with the spindle: chuck, groove rings, tool probe cube."""
    bodies: list[Body] = []
    chuck = scenario.workpiece.chuck_face_z if scenario.workpiece is not None else None
    if chuck is not None:
        bodies.append(Body("chuck", _axial(np.eye(3), np.zeros(3), BIG, chuck - BIG, chuck)))
    for groove in scenario.grooves:
        bodies.extend(_ring("groove", *ring) for ring in groove.bodies())
    tp = scenario.tool_probe
    if tp is not None:
        f = tp.faces
        centre = [(f["X-"] + f["X+"]) / 2, 0.0, (f["Z-"] + f["Z+"]) / 2]
        half = [(f["X-"] - f["X+"]) / 2, tp.y_size / 2, (f["Z-"] - f["Z+"]) / 2]
        bodies.append(Body("tool_probe", Box(np.eye(3), centre, half)))
    return bodies


class LatheContact:
    """The true scene (part at the spindle angle) and what happens first along a path."""

    def __init__(self, scenario: LatheScenario, kinematics: LatheKinematics,
                 diameters: dict[int, float] | None = None) -> None:
        self._scenario = scenario
        self._kinematics = kinematics
        self._rng = np.random.default_rng(scenario.seed)
        self._fixed = fixed_bodies(scenario)
        self._diameters = dict(diameters or {})
        self._angle: float | None = None
        self._scene = Scene(self._fixed)

    @property
    def diameters(self) -> dict[int, float]:
        return dict(self._diameters)

    def scene(self, angle_deg: float) -> Scene:
        angle = float(angle_deg) % 360.0
        if angle != self._angle:
            self._scene = Scene(part_bodies(self._scenario, angle, self._diameters) + self._fixed)
            self._angle = angle
        return self._scene

    def is_probe(self, tool: int | None) -> bool:
        return tool is not None and tool == self._scenario.probe.t

    def _cutter(self, tool: int) -> LatheTool:
        cutter = self._scenario.tool(tool)
        if cutter is None:      # the lathe's change_tool refuses a number the scenario has no tool for
            raise ValueError(f"T{tool} is neither the probe nor one of the scenario's tools")
        return cutter

    def _what(self, scene: Scene, point: np.ndarray, radius: float) -> str:
        """The kind of the solid nearest to a contact (for the alarm text)."""
        best = min(scene.bodies, key=lambda b: b.sdf(point), default=None)
        return {"part": "the workpiece", "chuck": "the chuck", "groove": "a reference groove",
                "tool_probe": "the tool probe"}.get(best.kind if best else "", "a solid")

    def first_event(self, start: np.ndarray, d: np.ndarray, length: float, tool: int | None, angle: float,
                    worn: tuple[float, float] = (0.0, 0.0)) -> Event | None:
        if tool is None:
            return None
        scene = self.scene(angle)
        if self.is_probe(tool):
            probe = self._scenario.probe
            centre = self._kinematics.ball_centre(start)
            radius = probe.ball_diameter / 2.0
            s = scene.first_contact(centre, d, length, radius)
            if s is None:
                return None
            deflected = s == 0.0 and scene.sdf(centre) <= radius
            s_switch = s if deflected else s + pretravel_along(d, probe.pretravel)
            what = self._what(scene, centre + s * d, radius)
            return Event("switch", s, s_switch, f"Probe collision: the probe touched {what}")
        cutter = self._cutter(tool)
        nose = self._kinematics.nose_centre(start, cutter, worn)
        events = []
        tool_probe = self._scenario.tool_probe
        if tool_probe is not None:                      # its cube is the scene's "tool_probe" body
            probe_scene = scene.subset({"tool_probe"})
            s = probe_scene.first_contact(nose, d, length, cutter.radius)
            if s is not None:
                deflected = s == 0.0 and probe_scene.sdf(nose) <= cutter.radius
                s_switch = s if deflected else s + tool_probe.pretravel
                events.append(Event("switch", s, s_switch, f"Probe collision: T{tool} touched the tool probe"))
        obstacles = scene.subset(set(OBSTACLES))
        s = obstacles.first_contact(nose, d, length, cutter.radius)
        if s is not None:
            what = self._what(obstacles, nose + s * d, cutter.radius)
            events.append(Event("crash", s, s, f"Probe collision: T{tool} hit {what}"))
        return min(events, key=lambda e: e.s_switch) if events else None

    def in_solid(self, position: np.ndarray, tool: int | None, angle: float,
                 worn: tuple[float, float] = (0.0, 0.0)) -> bool:
        """Does the probe ball / the tool's nose overlap a solid (after the spindle turned)?"""
        if tool is None:
            return False
        scene = self.scene(angle)
        if self.is_probe(tool):
            return scene.sdf(self._kinematics.ball_centre(position)) < self._scenario.probe.ball_diameter / 2.0 - 1e-12
        cutter = self._cutter(tool)
        return scene.subset(set(OBSTACLES)).sdf(self._kinematics.nose_centre(position, cutter, worn)) \
            < cutter.radius - 1e-12

    def touching(self, position: np.ndarray, tool: int | None, angle: float,
                 worn: tuple[float, float] = (0.0, 0.0)) -> tuple[bool, bool]:
        """(workpiece probe, tool probe): does a solid deflect it at the axes ``position`` now?
        The ball deflects the probe against any solid (the tool probe's cube too); the ball or a
        tool's nose on the cube deflects the tool probe (design.md §10.4)."""
        if tool is None:
            return False, False
        scene = self.scene(angle)
        cube = scene.subset({"tool_probe"})
        if self.is_probe(tool):
            centre = self._kinematics.ball_centre(position)
            radius = self._scenario.probe.ball_diameter / 2.0
            on_cube = self._scenario.tool_probe is not None and cube.sdf(centre) < radius - 1e-12
            return bool(scene.sdf(centre) < radius - 1e-12), bool(on_cube)
        if self._scenario.tool_probe is None:
            return False, False
        cutter = self._cutter(tool)
        nose = self._kinematics.nose_centre(position, cutter, worn)
        return False, bool(cube.sdf(nose) < cutter.radius - 1e-12)

    # --- after the event ------------------------------------------------------------------------
    def braking(self, feed_in_effect: float) -> float:
        cfg = self._scenario.machine
        return braking_distance(feed_in_effect, cfg.latency_s, cfg.decel, cfg.kv)

    def _limit(self, tool: int | None) -> float:
        if self.is_probe(tool):
            return self._scenario.probe.max_deflection
        tp = self._scenario.tool_probe
        return tp.max_deflection if tp is not None else math.inf

    def positioning_stop(self, event: Event, feed_in_effect: float, length: float, tool: int | None) -> Stop:
        if event.kind != "switch":
            return Stop(event.s_contact, None, False)
        s_stop = min(event.s_switch + self.braking(feed_in_effect), length)
        return Stop(s_stop, None, s_stop - event.s_contact > self._limit(tool))

    def measuring_stop(self, event: Event, feed_in_effect: float, distance: float, tool: int | None) -> Stop:
        s_stop = min(event.s_switch + self.braking(feed_in_effect), distance)
        s_latch = min(event.s_switch + latency_path(feed_in_effect, self._scenario.machine.latency_s), s_stop)
        sigma = self._scenario.probe.noise_sigma
        if sigma > 0.0 and self.is_probe(tool):
            s_latch += float(self._rng.normal(0.0, sigma))
        return Stop(s_stop, s_latch, s_stop - event.s_contact > self._limit(tool))


# --- the machine view (X up, Z right) ------------------------------------------------------------

def lathe_outline(scenario: LatheScenario, angle_deg: float, diameters: dict[int, float] | None = None) -> dict:
    """The true solids in the XZ half-plane for the machine view (JSON-ready, MCS radius/Z):
    the part's profile items as rectangles of the section (``r`` from the axis, eccentric by
    e_x(φ)), the chuck face, the groove rings, the tool probe cube."""
    out: dict = {"kind": "lathe", "part": [], "chuck_face_z": None, "grooves": [], "tool_probe": None,
                 "spindle_angle": float(angle_deg) % 360.0}
    wp = scenario.workpiece
    if wp is not None:
        out["chuck_face_z"] = float(wp.chuck_face_z)
        e = eccentricity_at(wp.eccentricity, angle_deg)
        size = dict(diameters or {})
        for i, item in enumerate(wp.profile):
            out["part"].append({"type": item.type, "z": [wp.chuck_face_z + item.z[0], wp.chuck_face_z + item.z[1]],
                                "diameter": float(size.get(i, item.diameter)), "axis_x": float(e[0])})
    for k, groove in enumerate(scenario.grooves):
        out["grooves"].append({"number": k + 1, "rings": [list(map(float, ring)) for ring in groove.bodies()]})
    if scenario.tool_probe is not None:
        out["tool_probe"] = {k: float(v) for k, v in scenario.tool_probe.faces.items()}
    return out


def tool_outline(kinematics: LatheKinematics, scenario: LatheScenario, position: np.ndarray, tool: int | None,
                 worn: tuple[float, float] = (0.0, 0.0)) -> dict:
    """The active tool for the view: F, and the ball (probe) or the tip, nose centre and radius."""
    f = [float(v) for v in position]
    if tool is not None and tool == scenario.probe.t:
        c = kinematics.ball_centre(position)
        return {"f": f, "is_probe": True, "tip": [float(v) for v in c], "diameter": scenario.probe.ball_diameter,
                "sl": scenario.probe.sl}
    cutter = scenario.tool(tool) if tool is not None else None
    if cutter is None:
        return {"f": f, "is_probe": False, "tip": f, "diameter": 0.0, "sl": None}
    tip = kinematics.tool_tip(position, cutter, worn)
    nose = tip - cutter.radius * sl_unit(cutter.sl)
    return {"f": f, "is_probe": False, "tip": [float(v) for v in tip], "nose": [float(v) for v in nose],
            "diameter": 2.0 * cutter.radius, "sl": cutter.sl}

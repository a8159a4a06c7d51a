"""An analytic lathe for the turning-cycle tests: latches computed from a known truth.

``ToolWorld``: a tool probe cube (true effective faces, keyed by the travel direction that
touches them, turning.md §10.2 ``tool_probe.faces``) and the active tool's truth (turning tool:
nose circle of radius R at S = P − R·s(SL); mill: a cylinder, axial or radial). The NC
reference the steps move is the tip as the NC computes it from the *stored* lengths; the true
tip is ``nc + (L_stored − L_true)`` per axis (P = F − L, turning.md §0.4).

``ProbeWorld``: a workpiece probe (ball of effective radius per travel direction = true radius
minus pre-travel; true ball centre = NC centre + skew) among solids of revolution about the
spindle axis, each an (r, z) box [r_in, r_out] × [z_lo, z_hi], optionally clamped with an
eccentricity that turns with the spindle (turning.md §11). Contacts are solved exactly on the
lateral cylinders and the faces; a corner contact or a collision on a positioning move fails
the test (the programs are meant to touch faces).

Both are ``respond(step)`` callables for engine.plan.run_program and record the steps.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pytest

from engine.turning import SL_TIP
from engine.types import Latch, MoveStep, ProbeStep, SpindleStep

_IDX = {"X": 0, "Y": 1, "Z": 2}
EPS = 1e-9


class Collision(AssertionError):
    """A positioning move or probing path went through a solid (the simulator's 61302)."""


def _axis_sign(direction) -> tuple[str, int]:
    d = np.asarray(direction, float)
    j = int(np.argmax(np.abs(d)))
    assert abs(abs(d[j]) - 1.0) < 1e-12 and np.count_nonzero(np.abs(d) > 1e-12) == 1, f"not axis-parallel: {d}"
    return "XYZ"[j], (1 if d[j] > 0 else -1)


# --- tool probe -------------------------------------------------------------------------------

@dataclass
class TurningToolTruth:
    sl: int
    l1: float
    l2: float
    radius: float
    recode: bool = False       # _CHBIT[23]: the turret turned 180° (s_X mirrored)

    def s(self):
        sx, sz = SL_TIP[self.sl]
        return (-sx if self.recode else sx), sz


@dataclass
class MillTruth:
    l1: float
    l2: float
    radius: float
    radial: bool = False
    length: float = 40.0       # cutter length along its axis (the solid the probe can touch)


@dataclass
class ToolWorld:
    faces: dict                # {"Z-": right face, "Z+": left, "X-": top, "X+": bottom}
    tool: object               # TurningToolTruth | MillTruth
    stored_l1: float
    stored_l2: float
    start: np.ndarray
    steps: list = field(default_factory=list)
    angle: float | None = None
    touches: list = field(default_factory=list)

    def __post_init__(self):
        self.pos = np.asarray(self.start, float).copy()

    # true tool shape in (x, z)
    def _true_tip(self, nc):
        return (nc[0] + self.stored_l1 - self.tool.l1, nc[2] + self.stored_l2 - self.tool.l2)

    def _shape(self, nc):
        """("circle", cx, cz, R) or ("rect", x0, x1, z0, z1)."""
        px, pz = self._true_tip(nc)
        t = self.tool
        if isinstance(t, TurningToolTruth):
            sx, sz = t.s()
            return ("circle", px - t.radius * sx, pz - t.radius * sz, t.radius)
        if t.radial:      # axis ∥ X at Z = pz, end face at X = px facing −X
            return ("rect", px, px + t.length, pz - t.radius, pz + t.radius)
        return ("rect", px - t.radius, px + t.radius, pz, pz + t.length)

    def _box(self):
        f = self.faces
        return f["X+"], f["X-"], f["Z+"], f["Z-"]      # x0, x1, z0, z1

    def _penetrates(self, nc) -> bool:
        x0, x1, z0, z1 = self._box()
        shape = self._shape(nc)
        if shape[0] == "circle":
            _, cx, cz, r = shape
            dx = max(x0 - cx, 0.0, cx - x1)
            dz = max(z0 - cz, 0.0, cz - z1)
            return math.hypot(dx, dz) < r - EPS
        _, a0, a1, b0, b1 = shape
        return a0 < x1 - EPS and a1 > x0 + EPS and b0 < z1 - EPS and b1 > z0 + EPS

    def _contact_travel(self, nc, axis, d) -> float | None:
        """Travel along (axis, d) until the tool's leading side reaches a probe face (exact)."""
        x0, x1, z0, z1 = self._box()
        shape = self._shape(nc)
        if axis == "X":
            face = x1 if d < 0 else x0       # travelling − touches the upper face of that axis
        else:
            face = z1 if d < 0 else z0
        if shape[0] == "circle":
            _, cx, cz, r = shape
            c_axis, c_cross = (cx, cz) if axis == "X" else (cz, cx)
            cross_lo, cross_hi = (z0, z1) if axis == "X" else (x0, x1)
            if not cross_lo - EPS <= c_cross <= cross_hi + EPS:
                return None                  # would touch a corner: not a face contact
            return (face - (c_axis + d * r)) * d
        _, a0, a1, b0, b1 = shape
        if axis == "X":
            overlap = b0 < z1 - EPS and b1 > z0 + EPS
            lead = a0 if d < 0 else a1
        else:
            overlap = a0 < x1 - EPS and a1 > x0 + EPS
            lead = b0 if d < 0 else b1
        return (face - lead) * d if overlap else None

    def __call__(self, step):
        self.steps.append(step)
        if isinstance(step, SpindleStep):
            self.angle = step.angle
            return None
        if isinstance(step, MoveStep):
            target = np.asarray(step.target, float)
            for u in np.linspace(0.0, 1.0, 41)[1:]:
                if self._penetrates(self.pos + u * (target - self.pos)):
                    raise Collision(f"move {step.label!r} to {target} hits the tool probe")
            self.pos = target.copy()
            return None
        assert isinstance(step, ProbeStep)
        axis, d = _axis_sign(step.direction)
        travel = self._contact_travel(self.pos, axis, d)
        if travel is not None and travel < -EPS:
            raise Collision(f"probing {step.label!r} starts inside the probe")
        if travel is None or travel > step.distance + EPS:
            self.pos = self.pos + step.distance * np.asarray(step.direction, float)
            return Latch(triggered=False)
        rec = self.pos + travel * np.asarray(step.direction, float)
        self.pos = rec.copy()
        self.touches.append((step.label, rec.copy(), self.angle))
        return Latch(triggered=True, rec=rec.copy())


# --- workpiece probe among solids of revolution ------------------------------------------------

@dataclass
class Solid:
    """Solid of revolution: radii [r_in, r_out] × z [z_lo, z_hi] about the spindle axis, shifted
    by ``ecc`` (X, Y) at spindle 0° that turns with the spindle (``turns``) or is fixed."""

    r_in: float
    r_out: float
    z_lo: float
    z_hi: float
    ecc: tuple[float, float] = (0.0, 0.0)
    turns: bool = True

    def centre(self, angle_deg: float):
        ex, ey = self.ecc
        if not self.turns or (ex == 0.0 and ey == 0.0):
            return ex, ey
        a = math.radians(angle_deg or 0.0)
        return ex * math.cos(a) - ey * math.sin(a), ex * math.sin(a) + ey * math.cos(a)

    def sdf(self, p, angle) -> float:
        cx, cy = self.centre(angle)
        r = math.hypot(p[0] - cx, p[1] - cy)
        zc, zh = 0.5 * (self.z_lo + self.z_hi), 0.5 * (self.z_hi - self.z_lo)
        rc, rh = 0.5 * (self.r_in + self.r_out), 0.5 * (self.r_out - self.r_in)
        qx, qz = abs(r - rc) - rh, abs(p[2] - zc) - zh
        outside = math.hypot(max(qx, 0.0), max(qz, 0.0))
        return outside + min(max(qx, qz), 0.0)


@dataclass
class ProbeWorld:
    solids: list
    radius: dict               # effective ball radius per travel direction (true r − pre-travel)
    true_r: float
    skew: tuple[float, float] = (0.0, 0.0)     # (Z, X): true ball centre − NC centre
    start: np.ndarray = field(default_factory=lambda: np.zeros(3))
    angle: float = 0.0
    steps: list = field(default_factory=list)
    touches: list = field(default_factory=list)

    def __post_init__(self):
        self.pos = np.asarray(self.start, float).copy()
        self.e = np.array([self.skew[1], 0.0, self.skew[0]])

    def _min_sdf(self, ball) -> float:
        return min(s.sdf(ball, self.angle) for s in self.solids)

    def _candidates(self, ball, axis, d, rho):
        out = []
        for s in self.solids:
            cx, cy = s.centre(self.angle)
            if axis == "Z":
                for zf in (s.z_lo - rho, s.z_hi + rho):
                    out.append((zf - ball[2]) * d)
            else:
                j, k = (0, 1) if axis == "X" else (1, 0)
                c = (cx, cy)
                for rv in (s.r_in, s.r_out):
                    for val in (rv + rho, rv - rho):
                        if val < 0:
                            continue
                        h2 = val * val - (ball[k] - c[k]) ** 2
                        if h2 < 0:
                            continue
                        for sgn in (1, -1):
                            out.append((c[j] + sgn * math.sqrt(h2) - ball[j]) * d)
        return sorted(t for t in out if t > -EPS)

    def _contact(self, ball, axis, d, distance_limit):
        """Exact first contact of a sphere of the true radius along (axis, d)."""
        u = np.zeros(3)
        u[_IDX[axis]] = d
        rho = self.true_r
        if self._min_sdf(ball) < min([rho, *self.radius.values()]) - 1e-7:
            raise Collision("the ball starts inside a solid")
        for t in self._candidates(ball, axis, d, rho):
            if abs(self._min_sdf(ball + t * u) - rho) < 1e-7:
                for v in np.linspace(0.0, t, 60)[1:-1]:
                    if self._min_sdf(ball + v * u) < rho - 1e-7:
                        raise Collision("the ball touched an edge before the face (a corner contact)")
                return t
        return None

    def __call__(self, step):
        self.steps.append(step)
        if isinstance(step, SpindleStep):
            if step.angle is not None:
                self.angle = float(step.angle)
            return None
        if isinstance(step, MoveStep):
            target = np.asarray(step.target, float)
            clearance = min([self.true_r, *self.radius.values()])     # a deflected stylus may leave
            for v in np.linspace(0.0, 1.0, 61)[1:]:
                ball = self.pos + v * (target - self.pos) + self.e
                if self._min_sdf(ball) < clearance - 1e-7:
                    raise Collision(f"move {step.label!r} to {target} hits a solid")
            self.pos = target.copy()
            return None
        assert isinstance(step, ProbeStep)
        axis, d = _axis_sign(step.direction)
        k = f"{axis}{'+' if d > 0 else '-'}"
        t = self._contact(self.pos + self.e, axis, d, step.distance)
        if t is None:
            self.pos = self.pos + step.distance * np.asarray(step.direction, float)
            return Latch(triggered=False)
        t_switch = t + (self.true_r - self.radius[k])            # pre-travel beyond first contact
        if t_switch > step.distance + EPS:
            self.pos = self.pos + step.distance * np.asarray(step.direction, float)
            return Latch(triggered=False)
        rec = self.pos + t_switch * np.asarray(step.direction, float)
        self.pos = rec.copy()
        self.touches.append((step.label, rec.copy(), self.angle))
        return Latch(triggered=True, rec=rec.copy())


def drive(program, world):
    """Run a point program against a world; returns the stored point."""
    from engine.plan import run_program
    return run_program(program, world)


# --- the model itself -------------------------------------------------------------------------

def test_tool_world_turning_tool_contact():
    """SL 3, R 5, stored = true: travelling −X onto the top face 400 the tip stops at 400."""
    w = ToolWorld(faces={"Z-": 220.0, "Z+": 200.0, "X-": 400.0, "X+": 380.0},
                  tool=TurningToolTruth(sl=3, l1=10.0, l2=40.0, radius=5.0), stored_l1=10.0, stored_l2=40.0,
                  start=np.array([401.0, 0.0, 205.0]))
    latch = w(ProbeStep(direction=np.array([-1.0, 0, 0]), distance=2.0, feed=150.0))
    assert latch.triggered and latch.rec[0] == pytest.approx(400.0, abs=1e-12)
    w.pos = np.array([369.0, 0.0, 205.0])
    latch = w(ProbeStep(direction=np.array([1.0, 0, 0]), distance=2.0, feed=150.0))
    assert latch.rec[0] == pytest.approx(370.0, abs=1e-12)          # top of the nose = tip + 2R


def test_probe_world_cylinder_with_eccentricity():
    """OD R 22.5 shifted 0.03 in +X: travelling −X the ball (r 3) switches at 22.53 + 3 = 25.53."""
    w = ProbeWorld(solids=[Solid(0.0, 22.5, 0.0, 60.0, ecc=(0.03, 0.0))], radius={"X-": 3.0}, true_r=3.0,
                   start=np.array([27.0, 0.0, 30.0]))
    latch = w(ProbeStep(direction=np.array([-1.0, 0, 0]), distance=4.0, feed=300.0))
    assert latch.rec[0] == pytest.approx(25.53, abs=1e-12)
    w.pos = np.array([27.0, 0.0, 30.0])
    w(SpindleStep(angle=180.0))
    latch = w(ProbeStep(direction=np.array([-1.0, 0, 0]), distance=4.0, feed=300.0))
    assert latch.rec[0] == pytest.approx(25.47, abs=1e-12)

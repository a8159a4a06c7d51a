"""Analytic ring-gauge touches for the calibration tests — independent of ``engine``.

The physics of measuring-math §1.7 / design.md §5, written out once more: the NC reference
moves along a line Q + s·u (machine plane, G17, WCS = MCS unless a WCS rotation is given);
the true ball centre is the reference + E(φ), E(φ) = Rz(φ)·e (eccentricity turns with SPOS);
the ball (radius r) first touches the ring wall (centre M, radius R) where |b − M| = R − r,
switches δ(θ) later along u and is latched v·τ later still (plus Gaussian noise along u).
θ is the travel angle in the probe's frame (θ_machine − φ) or in the machine frame.
"""

from __future__ import annotations

import math

import numpy as np


def quadrant_pretravel(table: dict[str, float]):
    """The simulator's kinematic model p(d) = Σ d_i²·p(axis_i, sign d_i) (app/machine/physics)."""

    def delta(theta_deg: float) -> float:
        c, s = math.cos(math.radians(theta_deg)), math.sin(math.radians(theta_deg))
        px = table["X+"] if c > 0 else table["X-"]
        py = table["Y+"] if s > 0 else table["Y-"]
        return c * c * px + s * s * py
    return delta


def trilobe_pretravel(mean: float, amplitude: float, phase_deg: float = 0.0, first=(0.0, 0.0)):
    """δ(θ) = δ0 + A·cos 3(θ − θ0) + k·(cos θ, sin θ): three lobes plus an optional first harmonic."""

    def delta(theta_deg: float) -> float:
        t = math.radians(theta_deg)
        return (mean + amplitude * math.cos(3.0 * (t - math.radians(phase_deg)))
                + first[0] * math.cos(t) + first[1] * math.sin(t))
    return delta


def fourier_amplitudes(func, orders: int = 64, samples: int = 4096) -> np.ndarray:
    """Amplitude A_m of order m = 0..orders of a 360°-periodic function (dense DFT)."""
    th = np.arange(samples) * 360.0 / samples
    f = np.array([func(t) for t in th])
    c = np.fft.rfft(f) / samples
    amp = 2.0 * np.abs(c)
    amp[0] = abs(c[0].real)
    return amp[: orders + 1]


class RingTruth:
    def __init__(self, center=(600.0, 100.0), diameter=25.0, r=2.0, ecc=(0.010, -0.006), delta=None,
                 frame="probe", latency_path=0.02, sigma=0.0, seed=0, depth=-158.0, wcs_rot=0.0):
        self.m = np.asarray(center, dtype=float)
        self.big_r = diameter / 2.0
        self.diameter = diameter
        self.r = r
        self.e = np.asarray(ecc, dtype=float)
        self.delta = delta or (lambda theta: 0.0)
        self.frame = frame
        self.lat = latency_path
        self.sigma = sigma
        self.rng = np.random.default_rng(seed)
        self.depth = depth
        g = math.radians(wcs_rot)             # WCS turned by wcs_rot about Z against the machine
        self.rot = np.array([[math.cos(g), -math.sin(g)], [math.sin(g), math.cos(g)]])

    def ecc_at(self, phi_deg: float) -> np.ndarray:
        c, s = math.cos(math.radians(phi_deg)), math.sin(math.radians(phi_deg))
        return np.array([c * self.e[0] - s * self.e[1], s * self.e[0] + c * self.e[1]])

    def rho(self, theta_deg: float) -> float:
        """True effective radius r − δ(θ) − v·τ in the model's frame."""
        return self.r - self.delta(theta_deg) - self.lat

    def latch(self, q, u, phi: float) -> np.ndarray:
        """rec (machine plane) of a touch from reference q along unit u at SPOS φ."""
        q, u = np.asarray(q, float), np.asarray(u, float)
        w = q + self.ecc_at(phi) - self.m
        a = self.big_r - self.r
        bw = float(w @ u)
        s_contact = -bw + math.sqrt(bw * bw - float(w @ w) + a * a)
        theta = math.degrees(math.atan2(u[1], u[0]))
        theta_frame = theta - phi if self.frame == "probe" else theta
        s = s_contact + self.delta(theta_frame) + self.lat
        if self.sigma:
            s += float(self.rng.normal(0.0, self.sigma))
        return q + s * u

    # --- WCS <-> machine (plane part) -----------------------------------------------------
    def to_wcs(self, p_mcs) -> np.ndarray:
        return self.rot.T @ np.asarray(p_mcs, float)

    def dir_wcs(self, u_mcs) -> np.ndarray:
        return self.rot.T @ np.asarray(u_mcs, float)

    # --- programs ---------------------------------------------------------------------------
    def jog_program(self, miss=(0.3, -0.2)):
        """The JOG ring program (engine.plan_workpiece.ring_program, measuring-math §7.3): SPOS 0
        search from the start (±X, to the X mid-point of the raw recs, ±Y), then passes at 180°
        and 0° from the found centre. -> list of passes (angle, [(key, rec_mcs, u_mcs), ...])."""
        start = self.m + np.asarray(miss, dtype=float)
        passes = []
        centre = start
        for phi in (0.0, 180.0, 0.0):
            touches, centre_next = self._pass(centre, phi)
            passes.append((phi, touches))
            if phi == 0.0 and len(passes) == 1:
                centre = centre_next          # passes 180° and 0° both start from the found centre
        return passes

    def _pass(self, centre, phi):
        ux, uy = np.array([1.0, 0.0]), np.array([0.0, 1.0])
        p1, p2 = self.latch(centre, ux, phi), self.latch(centre, -ux, phi)
        mid = np.array([0.5 * (p1[0] + p2[0]), centre[1]])
        p3, p4 = self.latch(mid, uy, phi), self.latch(mid, -uy, phi)
        found = np.array([mid[0], 0.5 * (p3[1] + p4[1])])
        return [("X+", p1, ux), ("X-", p2, -ux), ("Y+", p3, uy), ("Y-", p4, -uy)], found

    def n_direction_program(self, n: int, spindle_angles=(180.0, 0.0), start_deg: float = 0.0,
                            miss=(0.3, -0.2)):
        """Search as in the JOG program, then n directions from the found centre per angle."""
        search, found = self._pass(self.m + np.asarray(miss, dtype=float), 0.0)
        passes = [(0.0, search)]
        for phi in spindle_angles:
            touches = []
            for k in range(n):
                a = math.radians(start_deg + 360.0 * k / n)
                u = np.array([math.cos(a), math.sin(a)])
                touches.append((f"{start_deg + 360.0 * k / n:g}", self.latch(found, u, phi), u))
            passes.append((phi, touches))
        return passes

    def oblique_program(self, n: int, offset: float, spindle_angles=(180.0, 0.0), miss=(0.3, -0.2)):
        """Search as in the JOG program, then per spindle angle n directions, each along two
        chords ``offset`` to either side of the found centre (oblique incidence on the wall)."""
        search, found = self._pass(self.m + np.asarray(miss, dtype=float), 0.0)
        passes = [(0.0, search)]
        for phi in spindle_angles:
            touches = []
            for k in range(n):
                a = math.radians(360.0 * k / n)
                u = np.array([math.cos(a), math.sin(a)])
                u_perp = np.array([-u[1], u[0]])
                for side in (1.0, -1.0):
                    touches.append((f"{360.0 * k / n:g}/{side:+g}", self.latch(found + side * offset * u_perp, u, phi), u))
            passes.append((phi, touches))
        return passes

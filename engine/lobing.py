"""Direction-dependent trigger map ("lobing") of a workpiece probe in the working plane.

Physics (measuring-math §1.7, design.md §9.8). A kinematic touch-trigger probe switches after
its ball has travelled a pre-travel δ past first contact, and δ depends on the direction of
travel *in the probe body's own frame* (the classic three-lobed pattern of a three-point
kinematic seat); the NC latches v·τ later (latency). Along the travel direction d̂ the latched
ball centre therefore lies ``δ(θ) + v·τ`` beyond the contact centre, and the surface lies
``ρ(θ) = r − δ(θ) − v·τ`` beyond the latched ball centre: ρ is the *effective radius* in the
direction of travel θ (ball-centre relative, the magnitude of the trigger value t, measuring-math §5.1).

Frames. ``frame="probe"``: θ is the travel direction in the probe's frame, θ = θ_machine − φ
with φ the SPOS spindle angle (the lobing turns with the spindle, like the eccentricity; the
real probe and the wave-2 simulator). ``frame="machine"``: θ = θ_machine (the wave-1 simulator
fixed the pre-travel to the machine axes). Directions are measured in the machine plane from +X
towards +Y (G17; spindle on Z).

Model (how the map is estimated: ``engine.calibration.estimate_ring`` on a ring calibration with
n ≥ 4 directions, optionally at several spindle angles). The estimator returns one effective
radius ρ_j per calibrated direction θ_j. Only the along-d sum ``e·d̂ + ρ(θ)`` is observable
(e = eccentricity at φ), and a first harmonic ``k·d̂`` of ρ is indistinguishable from an
eccentricity (probe frame) or from the ring centre (machine frame). The calibration therefore puts
the first harmonic into the skew (probe frame: effective skew = e − k) resp. into the centre
(machine frame, unknown centre), so the ρ_j have no (sampled) first harmonic — unless a known
centre (machine frame) or oblique chords (``first_harmonic="estimate"``) leave it free. The map
is the low-order Fourier series

    ρ(θ) = c0 + Σ_{m ∈ orders} (a_m·cos mθ + b_m·sin mθ)        (m = 1 only when it is free)

fitted by least squares to the ρ_j. With n equally spaced directions the default orders
(2 … ⌊n/2⌋, the Nyquist order with its cosine only, plus 1 when free) give exactly n − 2
(resp. n) terms, so the series *interpolates* the calibrated values. Between them the along-d
correction g(θ) = e·d̂ + ρ(θ) (skew plus map) is the trigonometric interpolant of the true one,
whose error is the aliased Fourier tail: |g_map(θ) − g(θ)| ≤ 2·Σ_{m ≥ n/2} A_m with A_m the
amplitude of order m of the true ρ(θ). A band-limited lobing (orders < n/2, e.g. three lobes,
orders 0 and 3, with n = 12 directions) is reproduced exactly.

Application (``radius_for``, ``surface_point``; ``engine.compensation.make_touch(lobing=...)``):
for a touch along d̂ (WCS) at spindle angle φ with ball centre c = rec + e(φ) the surface point
is ``s = c + ρ(θ(d̂, φ))·d̂`` — exact at normal incidence (bores, bosses, rings at any angle,
axis-parallel edges). Directions with an infeed component d_p blend with the axial value like
the simulator's kinematic model p(d) = Σ d_i²·p_i: ρ = (1 − d_p²)·ρ(θ) + d_p²·ρ_axial.
Oblique faces (the surface normal n̂ not along d̂): the pre-travel acts along d̂ but the ball
radius along n̂, so ``contact_centre`` removes the pre-travel, c₀ = c − (r − ρ(θ))·d̂, and the face
is fitted through the c₀ and offset by the ball radius r along n̂ (exact when r is the true ball
radius and the skew is the true eccentricity; the point-wise s = c + ρ·d̂ is off by
r(1/cos α − 1) at incidence α, measuring-math §5.3). Under the convention (skew = e − k) an
oblique face keeps up to |k|·sin α: the first harmonic k acts along d̂, the skew in full.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from engine.types import FloatArray

if TYPE_CHECKING:                      # engine.calibration imports this module
    from engine.frames import Frame

FRAMES = ("probe", "machine")


def _wrap(angle_deg: npt.ArrayLike) -> FloatArray:
    wrapped: FloatArray = np.mod(np.asarray(angle_deg, dtype=float), 360.0)
    return wrapped


def _terms_for(angles_deg: FloatArray, include_first: bool, orders: Iterable[int] | None = None
               ) -> tuple[tuple[int, str], ...]:
    """Basis terms (order, "cos"|"sin") with the constant first; greedy: a term is kept when it
    raises the rank of the sampled basis (drops sin at the Nyquist order of equal spacing)."""
    m = len(angles_deg)
    th = np.radians(angles_deg)
    if orders is None:
        cap = m if include_first else m - 2
        candidates = [o for o in range(1 if include_first else 2, m // 2 + 1)]
    else:
        cap = m
        candidates = sorted({int(o) for o in orders if int(o) > 0})
        if not include_first and 1 in candidates:
            raise ValueError("the first harmonic lives in the skew/centre here: leave order 1 out")
    terms: list[tuple[int, str]] = [(0, "cos")]
    cols = [np.ones(m)]
    for order in candidates:
        for kind in ("cos", "sin"):
            if len(terms) >= cap:
                break
            col = np.cos(order * th) if kind == "cos" else np.sin(order * th)
            trial = np.column_stack([*cols, col])
            if np.linalg.matrix_rank(trial, tol=1e-9 * np.sqrt(m)) == trial.shape[1]:
                terms.append((order, kind))
                cols.append(col)
    return tuple(terms)


def _basis(terms: Sequence[tuple[int, str]], angles_deg: npt.ArrayLike) -> FloatArray:
    th = np.radians(np.atleast_1d(np.asarray(angles_deg, dtype=float)))
    return np.column_stack([np.cos(o * th) if k == "cos" else np.sin(o * th) for o, k in terms])


@dataclass(frozen=True)
class LobingMap:
    """Effective radius ρ(θ) of the probe per travel direction θ (module docstring).

    ``angles``/``values``: the calibrated directions (deg, in ``frame``, at spindle 0° for the
    probe frame) and their ρ_j; ``covariance`` (m, m) of the ρ_j (None if unknown).
    ``terms``/``coefficients``: the Fourier series; ``fit_residuals`` = values − series at the
    angles (zero when it interpolates). ``skew``: machine X/Y at spindle 0° that goes with the
    map (the first harmonic, probe frame: e − k). ``axial_radius``: ρ for travel along the
    infeed (|t(−p)| of the record), used for directions with an infeed component.
    """

    frame: str
    angles: FloatArray
    values: FloatArray
    terms: tuple[tuple[int, str], ...]
    coefficients: FloatArray
    skew: FloatArray
    covariance: FloatArray | None = None
    fit_residuals: FloatArray | None = None
    axial_radius: float | None = None
    projector: FloatArray | None = None     # P with coefficients = P @ values (fit_lobing_map)

    # --- evaluation -----------------------------------------------------------------------
    def _projector(self) -> FloatArray:
        """P with coefficients = P @ values (least squares, unweighted)."""
        if self.projector is not None:
            return self.projector
        return np.asarray(np.linalg.pinv(_basis(self.terms, self.angles)), dtype=float)

    def weights(self, angle_deg: float) -> FloatArray:
        """w with ρ(θ) = w·values: the map is linear in the calibrated values."""
        w: FloatArray = (_basis(self.terms, angle_deg) @ self._projector())[0]
        return w

    def weights_mean(self) -> FloatArray:
        """w with c0 = w·values (the mean radius)."""
        w: FloatArray = self._projector()[0]
        return w

    def radius(self, angle_deg: float) -> float:
        """ρ(θ) for a travel direction θ (deg) in the map's frame."""
        return float((_basis(self.terms, angle_deg) @ self.coefficients)[0])

    def radius_std(self, angle_deg: float) -> float:
        """Std of ρ(θ) from the calibration (NaN without a covariance)."""
        if self.covariance is None:
            return float("nan")
        w = self.weights(angle_deg)
        return float(np.sqrt(max(float(w @ self.covariance @ w), 0.0)))

    @property
    def mean_radius(self) -> float:
        """c0: the effective radius averaged over all directions (_WP[k,0]/2)."""
        return float(self.coefficients[0])

    @property
    def amplitudes(self) -> dict[int, float]:
        """|ĉ_m| per harmonic order m ≥ 1 in the series (the lobing's strength per order)."""
        out: dict[int, float] = {}
        for (order, _kind), c in zip(self.terms, self.coefficients, strict=True):
            if order:
                out[order] = float(np.hypot(out.get(order, 0.0), c))
        return out

    # --- directions -----------------------------------------------------------------------
    def frame_angle(self, direction_mcs: npt.ArrayLike, spindle_angle: float = 0.0) -> float:
        """θ (deg) of a machine-frame direction in the map's frame at SPOS ``spindle_angle``."""
        d = np.asarray(direction_mcs, dtype=float)
        if np.hypot(d[0], d[1]) == 0.0:
            raise ValueError("direction has no component in the machine plane")
        theta = float(np.degrees(np.arctan2(d[1], d[0])))
        if self.frame == "probe":
            theta -= float(spindle_angle)
        return float(_wrap(theta))

    def radius_for(self, direction_wcs: npt.ArrayLike, spindle_angle: float = 0.0, wcs2bcs: Frame | None = None,
                   axial_radius: float | None = None) -> float:
        """ρ for a travel direction given in the WCS (``wcs2bcs``: WCS -> BCS frame, BCS = MCS).

        In-plane part from the series, the infeed part (machine Z) blended by d_z²
        (module docstring); ``axial_radius`` overrides the map's.
        """
        d = np.asarray(direction_wcs, dtype=float)
        d = d / np.linalg.norm(d)
        d_mcs = d if wcs2bcs is None else wcs2bcs.dir_child2parent(d)
        axial2 = float(d_mcs[2] ** 2)
        if np.hypot(d_mcs[0], d_mcs[1]) < 1e-12:
            in_plane, axial2 = 0.0, 1.0
        else:
            in_plane = self.radius(self.frame_angle(d_mcs, spindle_angle))
        if axial2 == 0.0:
            return in_plane
        axial = axial_radius if axial_radius is not None else self.axial_radius
        if axial is None:
            axial = self.mean_radius
        return (1.0 - axial2) * in_plane + axial2 * float(axial)

    def surface_point(self, ball_centre: npt.ArrayLike, direction_wcs: npt.ArrayLike, spindle_angle: float = 0.0,
                      wcs2bcs: Frame | None = None) -> FloatArray:
        """s = c + ρ(θ)·d̂ (exact at normal incidence); ``ball_centre`` c = rec + e(φ), WCS."""
        d = np.asarray(direction_wcs, dtype=float)
        d = d / np.linalg.norm(d)
        point: FloatArray = np.asarray(ball_centre, dtype=float) + self.radius_for(d, spindle_angle, wcs2bcs) * d
        return point

    def contact_centre(self, ball_centre: npt.ArrayLike, direction_wcs: npt.ArrayLike, ball_radius: float,
                       spindle_angle: float = 0.0, wcs2bcs: Frame | None = None) -> FloatArray:
        """c₀ = c − (r − ρ(θ))·d̂: the ball centre at first contact, pre-travel and latency
        removed (for oblique faces: fit through the c₀, offset by r along the normal)."""
        d = np.asarray(direction_wcs, dtype=float)
        d = d / np.linalg.norm(d)
        travel = float(ball_radius) - self.radius_for(d, spindle_angle, wcs2bcs)
        centre: FloatArray = np.asarray(ball_centre, dtype=float) - travel * d
        return centre

    def trigger_values(self, spindle_angle: float = 0.0) -> dict[str, float]:
        """Axis-parallel trigger values (measuring-math §5.1: t(+) = −ρ, t(−) = +ρ) for travel
        along machine ±X/±Y at SPOS ``spindle_angle``."""
        out = {}
        for key, vec in (("X+", (1.0, 0.0)), ("X-", (-1.0, 0.0)), ("Y+", (0.0, 1.0)), ("Y-", (0.0, -1.0))):
            rho = self.radius(self.frame_angle((vec[0], vec[1], 0.0), spindle_angle))
            out[key] = -rho if key.endswith("+") else rho
        return out

    def values_json(self) -> dict[str, Any]:
        """JSON view (for the result and the probe record)."""
        return {"frame": self.frame, "angles": [float(a) for a in self.angles],
                "values": [float(v) for v in self.values],
                "terms": [[int(o), k] for o, k in self.terms],
                "coefficients": [float(c) for c in self.coefficients],
                "skew": {"X": float(self.skew[0]), "Y": float(self.skew[1])},
                "mean_radius": self.mean_radius,
                "max_fit_residual": (0.0 if self.fit_residuals is None
                                     else float(np.max(np.abs(self.fit_residuals)))),
                "axial_radius": self.axial_radius}


def fit_lobing_map(angles_deg: npt.ArrayLike, values: npt.ArrayLike, *, frame: str = "probe",
                   skew: npt.ArrayLike = (0.0, 0.0), covariance: npt.ArrayLike | None = None,
                   include_first: bool = False, orders: Iterable[int] | None = None,
                   axial_radius: float | None = None) -> LobingMap:
    """Least-squares Fourier series ρ(θ) through calibrated (θ_j, ρ_j) (module docstring).

    ``include_first``: the ρ_j carry a first harmonic (machine frame with a known ring centre);
    otherwise it belongs to ``skew`` and order 1 is left out. ``orders``: harmonic orders to use
    (default: as many as the directions determine). Needs ≥ 4 distinct directions.
    """
    if frame not in FRAMES:
        raise ValueError(f"frame must be one of {FRAMES}, got {frame!r}")
    th = _wrap(angles_deg)
    rho = np.asarray(values, dtype=float)
    if th.ndim != 1 or rho.shape != th.shape:
        raise ValueError("angles and values must be 1-D of equal length")
    if len(th) < 4 or len(np.unique(np.round(th, 6))) < len(th):
        raise ValueError(f"a lobing map needs >= 4 distinct directions, got {len(th)}")
    terms = _terms_for(th, include_first, orders)
    basis = _basis(terms, th)
    projector = np.asarray(np.linalg.pinv(basis), dtype=float)
    coefficients = projector @ rho
    cov = None if covariance is None else np.asarray(covariance, dtype=float)
    return LobingMap(frame=frame, angles=th, values=rho, terms=terms, coefficients=coefficients,
                     skew=np.asarray(skew, dtype=float)[:2].copy(), covariance=cov,
                     fit_residuals=rho - basis @ coefficients, axial_radius=axial_radius,
                     projector=projector)


def lobing_map_from_json(data: dict[str, Any]) -> LobingMap:
    """The map as ``LobingMap.values_json`` stored it with the probe record (design.md §9.8):
    the calibrated (θ_j, ρ_j) and the series' terms; the coefficients are fitted again from them
    and must agree with the stored ones (a record edited by hand is refused)."""
    try:
        frame = str(data["frame"])
        angles = _wrap(data["angles"])
        values = np.asarray(data["values"], dtype=float)
        terms = tuple((int(o), str(k)) for o, k in data["terms"])
        skew = np.array([float(data["skew"]["X"]), float(data["skew"]["Y"])])
    except (KeyError, TypeError, ValueError) as exc:
        raise ValueError(f"lobing: not a stored lobing map ({exc})") from None
    if frame not in FRAMES:
        raise ValueError(f"lobing.frame must be one of {FRAMES}, got {frame!r}")
    if angles.ndim != 1 or values.shape != angles.shape or len(angles) < 4:
        raise ValueError("lobing: angles and values must be equally long lists of >= 4 directions")
    if not terms or terms[0] != (0, "cos") or any(k not in ("cos", "sin") or o < 0 for o, k in terms) \
            or len(terms) > len(angles):
        raise ValueError("lobing.terms: the constant first, then (order, cos|sin), at most one per direction")
    basis = _basis(terms, angles)
    projector = np.asarray(np.linalg.pinv(basis), dtype=float)
    coefficients = projector @ values
    stored = data.get("coefficients")
    if stored is not None and (len(stored) != len(terms)
                               or not np.allclose(coefficients, np.asarray(stored, dtype=float), rtol=0, atol=1e-9)):
        raise ValueError("lobing.coefficients do not follow from the stored directions and values")
    axial = data.get("axial_radius")
    return LobingMap(frame=frame, angles=angles, values=values, terms=terms, coefficients=coefficients,
                     skew=skew, fit_residuals=values - basis @ coefficients,
                     axial_radius=None if axial is None else float(axial), projector=projector)

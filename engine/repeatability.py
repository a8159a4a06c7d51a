"""Probe repeatability from repeated touches of one point (issue [probe-health] item 3).

The manual's test (measuring-math §1.5, manual §10.4: "measure one position 10 times to obtain
the repeatability") and ISO 230-10:2022 §7.1 (probing repeatability: N touches of one point of a
reference face from the same direction, at the same feed): the latched positions along the
probing direction scatter by the probe's switching repeatability. The figures:

- ``two_sigma`` = 2·s with s the sample standard deviation (n − 1 in the denominator; an
  unbiased variance: for Gaussian scatter of σ, s²·(n−1)/σ² is χ² with n − 1 degrees of freedom,
  so for n = 25 s lies within ±30 % of σ with about 96 % probability);
- ``range`` = max − min of the positions (ISO 230-10's "range" R).

Objective and minimum: no fit, at least 2 touches (a spread needs two).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

MIN_TOUCHES = 2


@dataclass(frozen=True)
class Repeatability:
    n: int
    two_sigma: float       # mm, 2·s
    range: float           # mm, max − min
    mean: float            # mm, mean position along the probing direction
    deviations: tuple[float, ...]   # mm, each touch minus the mean, in the order probed


def repeatability(positions: npt.ArrayLike) -> Repeatability:
    """The scatter of ``positions`` (mm along the probing direction, one per touch)."""
    values = np.asarray(positions, dtype=float).reshape(-1)
    if values.size < MIN_TOUCHES:
        raise ValueError(f"positions: at least {MIN_TOUCHES} touches, got {values.size}")
    if not np.all(np.isfinite(values)):
        raise ValueError("positions: every touch must be a finite number")
    mean = float(np.mean(values))
    return Repeatability(n=int(values.size), two_sigma=2.0 * float(np.std(values, ddof=1)),
                         range=float(np.max(values) - np.min(values)), mean=mean,
                         deviations=tuple(float(v - mean) for v in values))

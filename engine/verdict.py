"""Verdicts of a measured characteristic and statistics of a series (design.md §10.3).

A characteristic has a nominal, a lower and an upper limit (absolute values: nominal + _TLL and
nominal + _TUL, measuring-math §3.2; no symmetrisation, the band is the drawing's) and an
actual value. Its verdict:

- ``ok``: lower ≤ actual ≤ upper (each limit inclusive to within ``EPS``, as engine.strategy
  compares bands: 20.03 typed is 20.029999999999998 in binary and still on the band);
- ``rework`` / ``scrap`` outside the band, by the side of the deviation and the feature
  (rule ``material``, the default): material left over is rework (an outer feature such as a
  spigot or shaft above its upper limit, an inner feature such as a bore or pocket below its
  lower limit), material missing is scrap. A feature with no material side (a position, an
  angle) cannot be reworked into place: scrap. Rule ``scrap``: every violation is scrap;
- ``not_decidable``: no actual (the measurement failed) or no band.

The part's verdict is the worst of its characteristics in the order of ``VERDICTS``.

Statistics of a series (individuals chart, the usual SPC at the machine; AIAG SPC manual,
2nd ed., ch. II): moving ranges MR_i = |x_i − x_{i−1}|, σ_within = mean(MR)/d2 with d2 = 1.128
for n = 2; control limits x̄ ± 3 σ_within; Cp = (USL − LSL)/(6 σ_within),
Cpk = min(USL − x̄, x̄ − LSL)/(3 σ_within); Pp, Ppk the same with the overall sample standard
deviation s. Pure: numbers in, value objects out.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from engine import checks

__all__ = ["EPS", "MATERIAL_SIDES", "VERDICTS", "VERDICT_RULES", "SeriesStatistics", "series_statistics",
           "verdict", "worst"]

EPS = 1e-9
VERDICTS = ("ok", "not_decidable", "rework", "scrap")          # best to worst
VERDICT_RULES = ("material", "scrap")
# the side on which a feature keeps material: +1 outer (larger = material left over), −1 inner
# (smaller = material left over), None: a position or an angle
MATERIAL_SIDES = {"outer": 1, "inner": -1}
D2_MOVING_RANGE = 1.128           # d2 for subgroups of 2 (moving range of individuals)


def verdict(actual: float | None, lower: float | None, upper: float | None, material: int | None,
            rule: str = "material") -> str:
    """The verdict of one characteristic (module doc). ``material``: +1 outer, −1 inner, None."""
    if rule not in VERDICT_RULES:
        raise ValueError(f"verdict rule: one of {', '.join(VERDICT_RULES)}")
    if not (checks.is_finite(actual) and checks.is_finite(lower) and checks.is_finite(upper)):
        return "not_decidable"
    assert actual is not None and lower is not None and upper is not None
    if lower - EPS <= actual <= upper + EPS:
        return "ok"
    if rule == "scrap" or material is None:
        return "scrap"
    above = actual > upper
    material_left = above if material > 0 else not above
    return "rework" if material_left else "scrap"


def worst(verdicts: Iterable[str]) -> str:
    """The worst verdict; ``not_decidable`` for none at all."""
    ranks = [VERDICTS.index(v) for v in verdicts]
    return VERDICTS[max(ranks)] if ranks else "not_decidable"


@dataclass(frozen=True)
class SeriesStatistics:
    n: int
    mean: float | None
    sigma: float | None              # overall sample standard deviation s (n − 1)
    sigma_within: float | None       # mean moving range / d2
    ucl: float | None
    lcl: float | None
    cp: float | None
    cpk: float | None
    pp: float | None
    ppk: float | None


def _capability(sigma: float | None, mean: float, lower: float | None, upper: float | None
                ) -> tuple[float | None, float | None]:
    if sigma is None or sigma <= 0.0 or not (checks.is_finite(lower) and checks.is_finite(upper)):
        return None, None
    assert lower is not None and upper is not None
    return (upper - lower) / (6.0 * sigma), min(upper - mean, mean - lower) / (3.0 * sigma)


def series_statistics(values: Sequence[float], lower: float | None = None, upper: float | None = None
                      ) -> SeriesStatistics:
    """Individuals-chart statistics of a series in measuring order (module doc). Needs 2 values
    for σ, limits and capability; with fewer those are None."""
    xs = [float(v) for v in values if checks.is_finite(v)]
    n = len(xs)
    if n == 0:
        return SeriesStatistics(0, None, None, None, None, None, None, None, None, None)
    mean = math.fsum(xs) / n
    if n < 2:
        return SeriesStatistics(n, mean, None, None, None, None, None, None, None, None)
    sigma = math.sqrt(math.fsum((x - mean) ** 2 for x in xs) / (n - 1))
    moving = [abs(b - a) for a, b in zip(xs, xs[1:], strict=False)]
    within = math.fsum(moving) / len(moving) / D2_MOVING_RANGE
    cp, cpk = _capability(within, mean, lower, upper)
    pp, ppk = _capability(sigma, mean, lower, upper)
    return SeriesStatistics(n, mean, sigma, within, mean + 3.0 * within, mean - 3.0 * within, cp, cpk, pp, ppk)

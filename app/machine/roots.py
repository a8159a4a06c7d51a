"""Brent's root finder on a bracket (the one scipy function the simulator used, issue 29 item 7).

Brent (1973), "Algorithms for Minimization without Derivatives", ch. 4, as in scipy's
``brentq`` (Brent's zeroin: inverse quadratic interpolation or secant, falling back to bisection
when a step would not shrink the bracket enough). Used by app/machine/scene.py to find where the
probe ball's path enters and leaves a body to 1e-13 mm (design.md §5: "root-found, never stepped").
"""

from __future__ import annotations

from collections.abc import Callable


def brentq(f: Callable[[float], float], a: float, b: float, xtol: float = 2e-12, rtol: float = 8.9e-16,
           maxiter: int = 200) -> float:
    """A root of ``f`` in [a, b] (f(a), f(b) of opposite sign or zero) to ``xtol + rtol·|x|``."""
    fa, fb = f(a), f(b)
    if fa == 0.0:
        return a
    if fb == 0.0:
        return b
    if (fa > 0.0) == (fb > 0.0):
        raise ValueError(f"f(a) and f(b) must have opposite signs, got {fa!r} and {fb!r}")
    c, fc = a, fa                       # c: the previous iterate; [b, c] brackets the root
    d = e = b - a
    for _ in range(maxiter):
        if (fb > 0.0) == (fc > 0.0):     # keep the root between b and c
            c, fc = a, fa
            d = e = b - a
        if abs(fc) < abs(fb):            # b is the best estimate
            a, b, c = b, c, b
            fa, fb, fc = fb, fc, fb
        tol = 2.0 * rtol * abs(b) + 0.5 * xtol
        m = 0.5 * (c - b)
        if abs(m) <= tol or fb == 0.0:
            return b
        if abs(e) >= tol and abs(fa) > abs(fb):
            s = fb / fa
            if a == c:                   # secant
                p, q = 2.0 * m * s, 1.0 - s
            else:                        # inverse quadratic interpolation
                q, r = fa / fc, fb / fc
                p = s * (2.0 * m * q * (q - r) - (b - a) * (r - 1.0))
                q = (q - 1.0) * (r - 1.0) * (s - 1.0)
            if p > 0.0:
                q = -q
            else:
                p = -p
            if 2.0 * p < min(3.0 * m * q - abs(tol * q), abs(e * q)):
                e, d = d, p / q          # accept the interpolation
            else:
                d = e = m                # bisection
        else:
            d = e = m
        a, fa = b, fb
        b += d if abs(d) > tol else (tol if m > 0.0 else -tol)
        fb = f(b)
    raise RuntimeError(f"no convergence within {maxiter} iterations")

"""app/machine/roots.brentq against roots known in closed form (issue 29 item 7)."""

from __future__ import annotations

import math

import pytest

from app.machine.roots import brentq


@pytest.mark.parametrize("f, a, b, root", [
    (lambda x: x * x - 2.0, 0.0, 2.0, math.sqrt(2.0)),
    (lambda x: math.cos(x) - x, 0.0, 1.0, 0.7390851332151607),          # the Dottie number
    (lambda x: x ** 3 - 2.0 * x - 5.0, 2.0, 3.0, 2.0945514815423265),    # Newton's cubic
    (lambda x: math.hypot(x - 30.0, 4.0) - 5.0, 0.0, 30.0, 27.0),        # a ball's path entering a cylinder (3-4-5)
    (lambda x: (x - 1e-3) * 1e9, 0.0, 2000.0, 1e-3),                     # steep, far bracket
])
def test_roots_to_the_tolerance(f, a, b, root):
    found = brentq(f, a, b, xtol=1e-13, rtol=4 * 2.220446049250313e-16)
    assert found == pytest.approx(root, abs=1e-12)


def test_a_bracket_without_sign_change_is_refused():
    with pytest.raises(ValueError, match="opposite signs"):
        brentq(lambda x: x * x + 1.0, -1.0, 1.0)


def test_an_end_that_is_a_root_is_returned():
    assert brentq(lambda x: x - 1.0, 1.0, 3.0) == 1.0

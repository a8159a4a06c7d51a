"""engine.checks, the engine's one module of scalar and vector checks (issue 27 item 7)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from engine import checks
from engine.checks import ParamError


@pytest.mark.parametrize("value", [True, "1", None, [1.0], math.nan, math.inf, -math.inf])
def test_real_refuses_what_is_no_finite_number(value):
    with pytest.raises(ValueError, match="^k "):
        checks.real("k", value)


def test_real_takes_ints_floats_and_numpy_numbers():
    assert checks.real("k", 3) == 3.0 and isinstance(checks.real("k", 3), float)
    assert checks.real("k", np.float32(0.5)) == 0.5
    assert checks.real("k", np.int64(-7)) == -7.0
    assert checks.real("sigma", 0.0, minimum=0.0) == 0.0
    with pytest.raises(ValueError, match=">= 0"):
        checks.real("sigma", -1e-12, minimum=0.0)


def test_integer_unit_sign_choice():
    assert checks.integer("n", 3.0) == 3
    with pytest.raises(ValueError):
        checks.integer("n", 2.5)
    assert checks.unit_sign("d", -1) == -1 and checks.unit_sign("d", 1) == 1
    for bad in (0, 2, True, "1"):
        with pytest.raises(ValueError):
            checks.unit_sign("d", bad)
    assert checks.choice("q", "length", ("length", "radius")) == "length"
    with pytest.raises(ValueError, match="length, radius"):
        checks.choice("q", "LENGTH", ("length", "radius"))


def test_unit_vector_and_vector():
    u = checks.unit_vector([3.0, 4.0])
    assert u == pytest.approx([0.6, 0.8], abs=1e-15)
    assert checks.unit_vector([0.0, 0.0, -2.0], dim=3) == pytest.approx([0.0, 0.0, -1.0])
    for bad in ([0.0, 0.0], [math.nan, 1.0], [math.inf, 0.0]):
        with pytest.raises(ValueError, match="non-zero"):
            checks.unit_vector(bad)
    with pytest.raises(ValueError, match="shape"):
        checks.unit_vector([1.0, 0.0], dim=3)
    source = [1.0, 2.0, 3.0]
    v = checks.vector(source, "t")
    v[0] = 9.0                      # a copy: the source is untouched
    assert source == [1.0, 2.0, 3.0]
    with pytest.raises(ValueError, match="finite"):
        checks.vector([1.0, math.nan, 0.0], "t")


def test_param_number_names_the_field():
    assert checks.param_number({"d": "12.5"}, "d") == 12.5          # a form's text is a number
    assert checks.param_number({}, "d") is None
    assert checks.param_number({"d": ""}, "d", 4.0) is None          # an empty field is no value
    cases = [({}, {"required": True}, "is required"), ({"d": True}, {}, "must be a number"),
             ({"d": "x"}, {}, "must be a number"), ({"d": math.nan}, {}, "finite"),
             ({"d": 1e6}, {"bound": 1e5}, "within")]
    for params, kw, text in cases:
        with pytest.raises(ParamError, match=text) as err:
            checks.param_number(params, "d", field_name="target.d", **kw)
        assert err.value.field == "target.d"
    with pytest.raises(ParamError, match="> 0"):
        checks.param_positive({"w": 0}, "w", required=True)
    assert checks.param_int({"n": 4.0}, "n", 1, 1) == 4
    with pytest.raises(ParamError, match="integer >= 1"):
        checks.param_int({"n": 0}, "n", 1, 1)
    assert checks.param_bool({}, "b", True) is True
    with pytest.raises(ParamError):
        checks.param_bool({"b": 1}, "b", False)
    assert checks.param_choice({"axis": "x"}, "axis", ("Z", "X"), None) == "X"
    assert checks.param_choice({}, "kind", ("outside", "inside"), "outside") == "outside"
    with pytest.raises(ParamError, match="required"):
        checks.param_choice({}, "axis", ("Z", "X"), None, required=True)
    with pytest.raises(ParamError, match="one of"):
        checks.param_choice({"kind": "OUTSIDE"}, "kind", ("outside", "inside"), "outside")

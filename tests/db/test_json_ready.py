"""``db.repository._json_ready`` (what the log, the audit and the probe data store): the same
answer as the JSON round trip it stands for, plain values copied without the text."""

from __future__ import annotations

import enum
import json
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from db.repository import _json_ready


def _round_trip(value):
    return json.loads(json.dumps(value, allow_nan=False))


def _typed(value):
    """``value`` with every leaf's exact type, so that 1, 1.0 and True differ."""
    if isinstance(value, dict):
        return {k: _typed(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_typed(v) for v in value]
    return (type(value).__name__, value if not (isinstance(value, float) and value == 0.0)
            else math.copysign(1.0, value))


class Colour(enum.IntEnum):
    RED = 1


leaves = st.one_of(st.none(), st.booleans(), st.integers(), st.text(max_size=5),
                   st.floats(allow_nan=False, allow_infinity=False),
                   st.builds(np.float64, st.floats(allow_nan=False, allow_infinity=False)),
                   st.just(Colour.RED))
keys = st.one_of(st.text(max_size=4), st.integers(-3, 3), st.booleans(), st.none())
values = st.recursive(leaves, lambda inner: st.one_of(st.lists(inner, max_size=4),
                                                       st.tuples(inner, inner),
                                                       st.dictionaries(keys, inner, max_size=4)), max_leaves=20)


@given(values)
def test_the_same_answer_as_the_round_trip(value):
    assert _typed(_json_ready(value, "x")) == _typed(_round_trip(value))


def test_a_copy_the_caller_may_change():
    value = {"a": [1, 2.5, {"b": (3, None)}]}
    copied = _json_ready(value, "x")
    assert copied == {"a": [1, 2.5, {"b": [3, None]}]}
    copied["a"][2]["b"].append(4)
    assert value == {"a": [1, 2.5, {"b": (3, None)}]}


@pytest.mark.parametrize("value", [float("nan"), {"a": [float("inf")]}, {"a": object()}, {(1, 2): 3}, {1, 2}])
def test_what_json_refuses_is_refused(value):
    with pytest.raises(ValueError, match="x is not JSON-ready"):
        _json_ready(value, "x")


def test_a_cycle_is_refused():
    value: list = []
    value.append(value)
    with pytest.raises(ValueError, match="x is not JSON-ready"):
        _json_ready(value, "x")

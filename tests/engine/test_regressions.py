"""Regression tests of engine bugs found by the end-to-end checks (one test per fix)."""

from __future__ import annotations

import pytest

from engine.plan import ParamError, validate_params
from engine.planes import plane

G17 = plane("G17")


@pytest.mark.parametrize("task,params,key", [
    ("edge.set", {"axis": "X", "setpoint": None}, "setpoint"),
    ("edge.set", {"axis": "Y", "setpoint": {"Y": None}}, "setpoint"),
    ("corner.right", {"setpoint": {"X": None, "Y": ""}}, "setpoint"),
    ("hole.2", {"diameter": 10, "setpoint_angle": None}, "setpoint_angle"),
    ("hole.1", {"diameter": 10, "probe_angle": None}, "probe_angle"),
    ("tool.length", {"offset_v": None}, "offset_v"),
])
def test_empty_numeric_fields_default_to_zero(task, params, key):
    """An explicit null/empty setpoint, angle or offset V was kept as None (later a 500 in
    Calculate) or compared with a number (TypeError): an empty field now means the default 0."""
    out = validate_params(task, params, G17)
    value = out[key]
    values = value.values() if isinstance(value, dict) else [value]
    assert all(v == 0.0 and isinstance(v, float) for v in values)


def test_non_numeric_setpoint_still_rejected():
    with pytest.raises(ParamError) as err:
        validate_params("edge.set", {"axis": "X", "setpoint": "abc"}, G17)
    assert err.value.field == "setpoint.X"


def test_frame_rotation_is_cached_and_read_only():
    """Frame.rotation rebuilt the RPY matrix on every point mapping (thousands per NC Start);
    it is computed once per (immutable) frame now and cannot be changed behind its back."""
    import numpy as np

    from engine.frames import Frame, matrix_from_rpy

    frame = Frame(coarse=[1.0, 2.0, 3.0], rot=[0.5, -0.3, 12.5])
    assert frame.rotation is frame.rotation
    assert np.array_equal(frame.rotation, matrix_from_rpy([0.5, -0.3, 12.5]))
    with pytest.raises(ValueError):
        frame.rotation[0, 0] = 2.0
    turned = frame.replace(rot=[0.0, 0.0, 90.0])
    assert np.allclose(turned.child2parent([1.0, 0.0, 0.0]), [1.0, 3.0, 3.0], atol=1e-12)
    assert frame.isclose(Frame.from_api(frame.to_api()))

"""What engine keeps between calls (issue 30: NC Start) changes no answer: a plane's axis matrix
is built once, and the copy the property hands out may be changed without changing the plane."""

from __future__ import annotations

from engine.planes import PLANES


def test_a_plane_matrix_handed_out_is_a_copy() -> None:
    plane = PLANES["G18"]                        # (a, o, p) = (Z, X, Y)
    m = plane.aop2xyz
    m[:] = 0.0
    assert plane.to_aop([1.0, 2.0, 3.0]).tolist() == [3.0, 1.0, 2.0]
    assert plane.to_xyz([3.0, 1.0, 2.0]).tolist() == [1.0, 2.0, 3.0]
    assert plane.aop2xyz.tolist() == [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]

"""What engine keeps between calls (issue 30: NC Start) changes no answer.

A plane's axis matrix is built once: the copy the property hands out may be changed without
changing the plane. The last circle fit is kept for the same touches: a caller changing the
centre it got does not change the next answer, and other touches (or the same touches with
another plane, kind or probe record) are fitted anew. The truth is a circle built here: a bore
of radius R touched by a ball of radius r has its ball centres at R - r from the bore's centre.
"""

from __future__ import annotations

import numpy as np
import pytest

from engine.evaluate import circle_fit_of_touches
from engine.planes import PLANES
from engine.types import MeasuringError, ProbeRecord, Touch

R, BALL_R = 6.0, 2.0
PROBE = ProbeRecord(ball_diameter=2 * BALL_R, effective_diameter=2 * BALL_R)
DIRS = ((1.0, 0.0, 0.0), (-1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, -1.0, 0.0))


def bore_touches(centre) -> tuple[Touch, ...]:
    c = np.asarray(centre, dtype=float)
    out = []
    for d in DIRS:
        u = np.asarray(d)
        out.append(Touch(ball_centre=c + (R - BALL_R) * u, direction=u, surface=c + R * u))
    return tuple(out)


def test_a_plane_matrix_handed_out_is_a_copy() -> None:
    plane = PLANES["G18"]                        # (a, o, p) = (Z, X, Y)
    m = plane.aop2xyz
    m[:] = 0.0
    assert plane.to_aop([1.0, 2.0, 3.0]).tolist() == [3.0, 1.0, 2.0]
    assert plane.to_xyz([3.0, 1.0, 2.0]).tolist() == [1.0, 2.0, 3.0]
    assert plane.aop2xyz.tolist() == [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]


def test_the_kept_fit_answers_only_the_same_touches() -> None:
    g17 = PLANES["G17"]
    first = bore_touches((10.0, 20.0, -5.0))
    centre, diameter, _ = circle_fit_of_touches(first, g17, "hole", PROBE)
    assert centre.tolist() == [10.0, 20.0, -5.0] and diameter == 2 * R
    centre[:] = 99.0                              # the caller's copy
    again, diameter, _ = circle_fit_of_touches(first, g17, "hole", PROBE)
    assert again.tolist() == [10.0, 20.0, -5.0] and diameter == 2 * R
    again[:] = 77.0                               # a kept answer's copy too
    assert circle_fit_of_touches(first, g17, "hole", PROBE)[0].tolist() == [10.0, 20.0, -5.0]
    other = bore_touches((-3.0, 4.0, 1.0))        # equal in shape, another measurement
    centre, _, _ = circle_fit_of_touches(other, g17, "hole", PROBE)
    assert centre.tolist() == [-3.0, 4.0, 1.0]
    centre, diameter, _ = circle_fit_of_touches(first, g17, "hole", PROBE)
    assert centre.tolist() == [10.0, 20.0, -5.0]
    # the same touches as a shaft's: the v chord the other way round, a non-positive diameter
    with pytest.raises(MeasuringError, match="non-positive diameter"):
        circle_fit_of_touches(first, g17, "spigot", PROBE)

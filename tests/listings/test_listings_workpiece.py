"""CYCLE977/978 listings of the manual (§5.4, §5.5) as printed, against the scenario's truth.

Adapted: ``循环977`` → ``CYCLE977`` (the Chinese print's translation of the cycle name), nothing
else; the part is placed so that the printed positions fit, a little off the printed G54 (the
error the cycles find). Truth: the part's pose in the scenario (listing_kit), read through
``GET /api/offsets/G54`` after the run.
"""

from __future__ import annotations

import pytest
from listing_kit import G54, Machine
from manual_listings import NV_ERMITTLUNG_1_11777, NV_RECHTECK_11315

ERROR = (0.3, -0.2)           # the part's true place minus where the printed G54 expects it


ARTEFACT = {"循环": "CYCLE"}   # the Chinese print translated the cycle names (issue 28: refusing 循环 is right)


def test_zero_offset_from_two_faces_x_then_y(client):
    """§5.5 %_N_NV_ERMITTLUNG_1_MPF (lines 11777–11801): CYCLE978 _MVAR=100 _SETVAL=0 _KNUM=1 on
    the face X0 (travelling +X), then _MA=2 on the face Y0: G54 X/Y become the part's corner, Z
    stays. Part: its front-left corner at G54 (0.3, −0.2), top face at Z20 (the printed Z10 is
    measuring height on its sides)."""
    m = Machine(client, part={"origin": (*ERROR, 20.0), "size": (200, 120, 60)})
    before = m.offset("G54")
    answer = m.run(NV_ERMITTLUNG_1_11777, replace=ARTEFACT)
    assert answer["state"] == "done", answer
    after = m.offset("G54")
    corner = [G54["block"][0] + ERROR[0], G54["block"][1] + ERROR[1]]
    assert [after["trans"]["X"] + after["fine"]["X"], after["trans"]["Y"] + after["fine"]["Y"]] == \
        pytest.approx(corner, abs=1e-6)
    assert after["trans"]["Z"] + after["fine"]["Z"] == pytest.approx(before["trans"]["Z"] + before["fine"]["Z"])
    assert m.wcs()["X"] == pytest.approx(-40.0) and m.wcs()["Y"] == pytest.approx(80.0)   # N160


def test_outer_rectangle_centre_into_g54(client):
    """§5.4.3 %_N_NV_RECHTECK_MPF (lines 11315–11336): CYCLE977 _MVAR=106 (outer rectangle
    100 × 200, _ID=−30 below the start Z120, _KNUM=1): G54 then puts the rectangle's centre at
    the start X150 Y170 (measuring-math §8.3: d = actual − setpoint at the start). Part: a boss
    100 × 200 × 80 whose centre lies at G54 (150.3, 169.8), top face at Z100."""
    boss = {"type": "boss", "center": [150.0 + ERROR[0], 170.0 + ERROR[1]], "size": [100, 200], "height": 80}
    m = Machine(client, part={"origin": (0.0, 0.0, 20.0), "size": (300, 300, 60), "features": [boss]})
    answer = m.run(NV_RECHTECK_11315, replace=ARTEFACT)
    assert answer["state"] == "done", answer
    ovr = m.ovr()
    assert ovr[4:6] == pytest.approx([100.0, 200.0], abs=1e-6)
    assert ovr[6:8] == pytest.approx([150.0 + ERROR[0], 170.0 + ERROR[1]], abs=1e-6)
    after = m.offset("G54")
    assert [after["trans"][a] + after["fine"][a] for a in "XY"] == \
        pytest.approx([G54["block"][0] + ERROR[0], G54["block"][1] + ERROR[1]], abs=1e-6)

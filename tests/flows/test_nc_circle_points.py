"""N touches on a circle in a program (issue 28 items 1/3, design.md §10.2): ``_NPTS`` (this HMI's
extension, as the JSON API's ``params.points``) makes CYCLE977 bore/shaft and CYCLE979 fit their
circle to that many touches; 0 keeps the manual's 4 (CYCLE977) or 3/4 (CYCLE979, ``_PRNUM``).
Truth: the hole's and spigot's centres from the scenario's pose (truthkit), never the product's
output.
"""

from __future__ import annotations

import numpy as np
import pytest
import test_nc_cycles_truth as cycles_truth
from truthkit import HOLE_D, HOLES, SPIGOT_D, SPIGOT_H, SPIGOTS, TOL_MM, scenario

DEPTH = -8.0


class Nc(cycles_truth.Nc):
    def wcs_of(self, part_point) -> np.ndarray:
        return self.frame("G54").to_child(self.part.mcs(*part_point))

    def last_entry(self) -> dict:
        return self.ok(self.c.get("/api/log"))[0]


def _nc(client, kind: str = "holes", noise: float = 0.0) -> Nc:
    data = scenario(rot=(0.0, 0.0, 4.0), kind=kind)
    data["probe"]["noise_sigma"] = noise
    data["machine"]["limits"]["Z"] = [-400, 100]          # room for the safe height Z40
    nc = Nc(client, data)
    nc.load()
    pose = data["workpiece"]["pose"]
    nc.put_offset("G54", rot=pose["rot"], trans=np.add(pose["trans"], (0.3, -0.2, 0.0)))
    return nc


def _approach(x: float, y: float, z: float) -> str:
    return f"G54 G17 G90 G0 Z40\nX{x} Y{y}\nZ{z}\n"


def _close(actual, expected, tol: float = TOL_MM) -> None:
    assert np.max(np.abs(np.asarray(actual, float) - np.asarray(expected, float))) <= tol, (actual, expected)


@pytest.mark.parametrize("npts", [3, 8])
def test_cycle977_bore_from_npts_touches_is_the_true_bore(client, npts):
    nc = _nc(client)
    hole = HOLES[1]
    truth = nc.wcs_of((*hole, DEPTH))
    nc.mda(_approach(truth[0] + 0.4, truth[1] - 0.3, DEPTH)
           + f"_MVAR=1 _SETVAL={HOLE_D} _KNUM=0 _FA=2 _NPTS={npts}\nCYCLE977\n_NPTS=0\nG0 Z40")
    ovr = nc.ovr()
    _close(ovr[4], HOLE_D)
    _close(ovr[5:7], truth[:2])
    entry = nc.last_entry()
    assert entry["task"] == "hole.1" and entry["params"]["points"] == npts
    assert len(entry["result"]["residuals"]) == npts and entry["result"]["form_error"] == pytest.approx(0.0, abs=1e-6)


def test_cycle977_shaft_from_six_touches(client):
    nc = _nc(client, kind="spigots")
    c = SPIGOTS[0]
    truth = nc.wcs_of((*c, SPIGOT_H - 5.0))
    top = nc.wcs_of((*c, SPIGOT_H))
    nc.mda(_approach(truth[0] - 0.3, truth[1] + 0.2, top[2] + 5.0)
           + f"_MVAR=2 _SETVAL={SPIGOT_D} _ID=-10 _KNUM=0 _FA=2 _NPTS=6\nCYCLE977\n_NPTS=0\nG0 Z40")
    ovr = nc.ovr()
    _close(ovr[4], SPIGOT_D)
    _close(ovr[5:7], truth[:2])
    assert len(nc.last_entry()["result"]["residuals"]) == 6


def test_cycle979_bore_from_six_touches_at_an_angle(client):
    nc = _nc(client)
    hole = HOLES[0]
    truth = nc.wcs_of((*hole, DEPTH))
    cp = (truth[0] + 0.2, truth[1] - 0.1)
    nc.mda(_approach(*cp, DEPTH) + f"_MVAR=1 _SETVAL={HOLE_D} _CPA={cp[0]} _CPO={cp[1]} _STA1=10 _INCA=60 "
           "_PRNUM=1 _KNUM=0 _FA=1 _RF=500 _NPTS=6\nCYCLE979\n_NPTS=0\nG0 Z40")
    ovr = nc.ovr()
    _close(ovr[4], HOLE_D)
    _close(ovr[5:7], truth[:2])
    assert len(nc.last_entry()["result"]["residuals"]) == 6


@pytest.mark.parametrize("words, names", [
    ("_MVAR=1 _SETVAL=12 _NPTS=2", "3..36"),
    ("_MVAR=1 _SETVAL=12 _NPTS=37", "3..36"),
    ("_MVAR=3 _MA=1 _SETVAL=12 _NPTS=6", "only bore and shaft"),
])
def test_a_wrong_npts_is_refused_before_anything_moves(client, words, names):
    nc = _nc(client)
    hole = HOLES[1]
    truth = nc.wcs_of((*hole, DEPTH))
    nc.mda(_approach(truth[0], truth[1], DEPTH))
    before = nc.ball_mcs()
    answer = nc.mda(f"{words} _KNUM=0\nCYCLE977", state="alarm")
    assert answer["alarm"]["code"] == 65103 and "_NPTS" in answer["alarm"]["message"], answer
    assert names in answer["alarm"]["message"]
    assert list(nc.ball_mcs()) == list(before)
    nc.ok(nc.c.post("/api/nc/reset"))
    nc.mda("_NPTS=0")


def test_the_editor_writes_and_reads_back_npts():
    """The cycle support's form (design.md §10.2) offers _NPTS for CYCLE977 and CYCLE979."""
    from app.nc.cycle_forms import CYCLES, read, render

    for cycle in ("CYCLE977", "CYCLE979"):
        assert "_NPTS" in [f.name for f in CYCLES[cycle]]
        params = {"_MVAR": 1, "_SETVAL": 12.0, "_NPTS": 8}
        assert read(render(cycle, params)) == (cycle, params)

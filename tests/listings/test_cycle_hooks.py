"""CYCLE198 / CYCLE199 (manual §3.2, design.md §10.2): stored user programs run before and after
every measuring cycle; without them nothing changes (the listings' tests run without)."""

from __future__ import annotations

import pytest
from listing_kit import Machine
from manual_listings import KALIBRIEREN_IN_Z


def store(m: Machine, name: str, text: str) -> None:
    m.ok(m.c.post("/api/programs", json={"name": name, "text": text}), 201)


def test_cycle199_runs_after_the_cycle(client):
    """CYCLE199 lifts the probe to Z70 after the cycle: the listing's N80 Z55 then comes down
    from there, and the calibration is the one without the hook."""
    m = Machine(client)
    store(m, "CYCLE199", "G0 Z70\nM17")
    text = KALIBRIEREN_IN_Z.text.replace("  N80 Z55 ;测量头在工件上的定位 \n", "")
    answer = m.mda(text)
    assert answer["state"] == "done", answer
    assert m.wcs()["Z"] == pytest.approx(70.0)                 # where CYCLE199 left the probe
    assert m.probe(1)["trigger"] == {"Z-": pytest.approx(2.0 - 0.2, abs=1e-9)}


def test_an_alarm_in_cycle198_stops_before_the_measurement(client):
    m = Machine(client)
    store(m, "CYCLE198", "N10 G1 X0\nM17")                      # no feed: 10860 in line 1
    answer = m.mda(KALIBRIEREN_IN_Z.text)
    assert answer["state"] == "alarm" and answer["alarm"]["code"] == 10860, answer
    assert "CYCLE198 line 1" in answer["alarm"]["message"]
    assert m.probe(1)["trigger"] == {}                          # nothing measured

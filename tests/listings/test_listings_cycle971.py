"""CYCLE971 (tool probe calibration and tool measuring, manual §5.2) as printed in the manual, against truth.

Each listing of tests/listings/manual_listings.py runs unchanged as an MDA program. Its positions
are machine coordinates (``SUPA``, tool tip): the scenario's tool probe (a disc, top-face centre
``center`` in MCS) is placed under the printed start so that they fit. Truth is the scenario
(noise-free, no latch delay, no pre-travel, time_scale 0): the tool-probe record ``_TP[0, 0…4]``
holds the tool-edge positions at switching (jog-measuring §7.2: travelling −X touches the +X
face at cx + D/2, travelling +X the −X face at cx − D/2, likewise Y; −Z the top), and a measured
tool's geometry is the cutter's true length / radius.
"""

from __future__ import annotations

import pytest
from listing_kit import G54, Machine, scenario
from manual_listings import (
    AUTO_KALIBRIEREN_7895,
    KALIBRIEREN_MTWZ_7510,
    KALIBRIEREN_MTWZ_X_7620,
    T3_MESSEN_8342,
)

DISC = 20.0
TP = (70.0, 90.0, 95.0)            # under the printed SUPA X70 Y90; the tip at SUPA Z100 is 5 mm above
CAL_T = {"t": 7, "type": 120, "length": 100.0, "radius": 6.0}            # exact calibration tool T7
CUTTER = {"t": 3, "type": 120, "length": 85.0, "radius": 5.0, "nominal": {"length": 85.04, "radius": 5.03}}


def faces(center, disc: float) -> dict:
    """The true trigger values of a disc probe (MCS, tool edge at contact)."""
    cx, cy, top = center
    h = disc / 2.0
    return {"X-": cx + h, "X+": cx - h, "Y-": cy + h, "Y+": cy - h, "Z-": top}


class ToolMachine(Machine):
    def __init__(self, client, center=TP, disc=DISC, tools=(CAL_T, CUTTER)):
        self.center, self.disc, self.tools = center, disc, tools
        super().__init__(client)

    def load(self, **changes) -> None:
        self.kw = {**self.kw, **changes}
        self.scen = scenario(**self.kw)
        self.scen["tool_probe"] = {"center": list(self.center), "disc_diameter": self.disc, "height": 40.0}
        self.scen["tools"] = [dict(t) for t in self.tools]
        self.ok(self.c.post("/api/sim/scenario", json={**self.scen, "reset_data": True}))
        self.put_offset("G54", G54[self.frame])

    def tool_probe(self, n: int = 1) -> dict:
        return self.ok(self.c.get(f"/api/tool-probes/{n}"))

    def put_tool_probe(self, n: int = 1, **fields) -> None:
        keep = {k: v for k, v in self.tool_probe(n).items()
                if k in ("number", "trigger", "disc_diameter", "axes", "type", "dz")}
        self.ok(self.c.put(f"/api/tool-probes/{n}", json={**keep, **fields}))


def test_calibration_listing_first_cycle_writes_the_true_faces_then_n70_is_refused(client):
    """§5.2.2 %_N_KALIBRIEREN_MTWZ_MPF (lines 7510–7548), run unchanged; the probe's top-face
    centre is at the printed SUPA X70 Y90, its top 5 mm under SUPA Z100. N50 (_MVAR=0 _MA=102)
    writes _TP[0,0…4] = the true faces within 1e-6 (this control's _MVAR=0 calibrates every
    direction from the start above the probe, not the single direction _MA).

    PRODUCT GAP (reported, not fixed): N60 SUPA Y0 puts the tool 90 mm beside the probe, from
    where the manual's N70 (_MA=2) calibrates +Y from the side. This control's CYCLE971 runs the
    whole JOG calibration from the start (first −Z at the start), so N70 ends in 61301 "Probe
    not switched". The record keeps N50's true values."""
    m = ToolMachine(client)
    answer = m.run(KALIBRIEREN_MTWZ_7510)
    assert answer["state"] == "alarm", answer
    assert answer["alarm"]["code"] == 61301 and answer["block"]["number"] == 70, answer
    assert "Probe not switched" in answer["alarm"]["message"]
    record = m.tool_probe(1)
    truth = faces(TP, DISC)
    assert record["trigger"] == {k: pytest.approx(v, abs=1e-6) for k, v in truth.items()}
    assert record["calibration_tool"] == 7


def test_workpiece_related_calibration_listing_is_refused_by_name(client):
    """§5.2.2 %_N_KALIBRIEREN_MTWZ_X_MPF (lines 7620–7638), run unchanged (G54 = the kit's block
    frame, not used by the probe): _MVAR=10 is the workpiece-related calibration (_TPW), which
    this control does not have (scope text of 8496): N50 ends in 61307 "Wrong measuring variant"
    naming _MVAR=10 and _TPW, and neither _TP nor _TPW of record 1 is written."""
    m = ToolMachine(client)
    before = m.tool_probe(1)
    answer = m.run(KALIBRIEREN_MTWZ_X_7620)
    assert answer["state"] == "alarm", answer
    assert answer["alarm"]["code"] == 61307 and answer["block"]["number"] == 50, answer
    assert "_MVAR=10" in answer["alarm"]["message"] and "_TPW" in answer["alarm"]["message"]
    assert m.tool_probe(1) == before


AUTO_TP = (39.2, 30.9, 80.4)       # the manual's probe (centre X39 Y31, top 80, disc 21), 0.2/−0.1/0.4 off
AUTO_DISC = 21.0
AUTO_CAL_T = {"t": 7, "type": 120, "length": 70.123, "radius": 5.0}     # the manual's T7 (§5.2.3 example)


def test_automatic_calibration_listing_writes_the_true_probe(client):
    """§5.2.3 %_N_AUTO_KALIBRIEREN_MPF (lines 7895–7908), run unchanged with the manual's example
    data: T7 L1 = 70.123, R = 5 (exact), the record calibrated before with the printed _TP[0,0…4]
    = 50, 28, 42, 20, 80, _TP[0,6] = 21, _TP[0,7] = 133, _TP[0,8] = 101, _TP[0,9] = 4. The true
    probe (disc Ø21) stands 0.2/−0.1/0.4 mm off the printed centre X39 Y31 / top 80, inside
    _TSA=5. _MVAR=100000 sets no _MA (the print gives none): the record gets the true faces within
    1e-6. (Before this file the control refused the listing with 61325 "_MA = 0".)"""
    m = ToolMachine(client, center=AUTO_TP, disc=AUTO_DISC, tools=(AUTO_CAL_T, CUTTER))
    m.put_tool_probe(1, trigger={"X-": 50.0, "X+": 28.0, "Y-": 42.0, "Y+": 20.0, "Z-": 80.0},
                     disc_diameter=21.0, axes=133, type=101, dz=4.0)
    answer = m.run(AUTO_KALIBRIEREN_7895)
    assert answer["state"] == "done", answer
    record = m.tool_probe(1)
    truth = faces(AUTO_TP, AUTO_DISC)
    assert record["trigger"] == {k: pytest.approx(v, abs=1e-6) for k, v in truth.items()}
    assert record["calibration_tool"] == 7


def test_t3_listing_measures_the_true_length_and_radius(client):
    """§5.2.4 %_N_T3_MESSEN_MPF (lines 8342–8363), run unchanged on the probe of the first test
    (already calibrated: _TP[0] = its true faces, entered as truth). T3 is 85/5 true, typed
    85.04/5.03. N40 (_MVAR=1 _MA=103 _ID=2.2, stationary: 2R ≤ Ø20) writes L1 = 85; N80
    (_MVAR=2 _MA=1 _ID=2.4, rotating) writes R = 5, into the geometry (_CHBIT[3]=0), within 1e-6.

    Adapted: E_MESS_MT_DZ = 4 (the manual's _TP[0,9] of §5.2.3's example) instead of the default 2:
    this control raises the radius measuring height by _ID (jog-measuring §11 Q12), so with the
    default DZ 2 the printed _ID=2.4 puts the tip 0.4 mm above the disc and N80 ends in 61301
    (test below)."""
    m = ToolMachine(client)
    m.put_tool_probe(1, trigger=faces(TP, DISC))
    m.ok(client.put("/api/settings", json={"mt_dz": 4.0}))
    answer = m.run(T3_MESSEN_8342)
    assert answer["state"] == "done", answer
    tool = m.tool(3)
    assert tool["length"] == pytest.approx(CUTTER["length"], abs=1e-6)
    assert tool["radius"] == pytest.approx(CUTTER["radius"], abs=1e-6)
    assert tool["wear"] == {"length": 0.0, "radius": 0.0}
    ovr = m.ovr()
    assert ovr[10] == pytest.approx(CUTTER["radius"], abs=1e-6)
    assert ovr[11] == pytest.approx(CUTTER["radius"] - CUTTER["nominal"]["radius"], abs=1e-6)
    assert m.ovi()[8] == 3


def test_t3_listing_with_the_default_dz_passes_over_the_disc(client):
    """The same run with E_MESS_MT_DZ at its default 2 mm: the length is measured (N40), then
    N80's tip height top − 2 + 2.4 lies above the disc, 61301 at N80, the radius stays typed."""
    m = ToolMachine(client)
    m.put_tool_probe(1, trigger=faces(TP, DISC))
    answer = m.run(T3_MESSEN_8342)
    assert answer["state"] == "alarm", answer
    assert answer["alarm"]["code"] == 61301 and answer["block"]["number"] == 80, answer
    tool = m.tool(3)
    assert tool["length"] == pytest.approx(CUTTER["length"], abs=1e-6)
    assert tool["radius"] == pytest.approx(CUTTER["nominal"]["radius"])

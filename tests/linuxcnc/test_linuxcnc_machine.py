"""The LinuxCNC adapter beyond the shared contract: the latch against the feed, what LinuxCNC
cannot hold, its own faults (a rapid into the part, a jog into the part, Reset).

One LinuxCNC for the module (the contract scenario: a block turned 10° about Z, the probe with
pre-travel, latency 4 ms, no noise); every test positions the probe itself.
"""

from __future__ import annotations

import threading
import time

import numpy as np
import pytest
from test_machine_contract import (
    CONTRACT_SCENARIO,
    L_PROBE,
    LATENCY_S,
    START,
    _above_block,
    _pretravel,
    _xyz,
)

from app.machine.protocol import MachineAlarm
from app.machine.scenario import load_scenario
from engine import alarms

SERVO_PERIOD_S = 0.001
LATCH: dict[float, dict] = {}


@pytest.fixture(scope="module")
def m(tmp_path_factory):
    from app.machine.linuxcnc import LinuxCncMachine

    machine = LinuxCncMachine(load_scenario(CONTRACT_SCENARIO), folder=tmp_path_factory.mktemp("linuxcnc"))
    machine.change_tool(9, L_PROBE)
    yield machine
    machine.close()


@pytest.fixture(autouse=True)
def _clean(m):
    m.reset()
    if m.status().tool != 9 or any(a.is_(alarms.PROBE_BROKEN) for a in m.status().alarms):
        m.change_tool(9, L_PROBE)
    yield
    m.reset()


def test_linuxcnc_started_homed_at_the_start_position(m):
    st = m.status()
    assert m.controller == "linuxcnc" and st.alarms == ()
    assert m.startup_s < 10.0
    print(f"\nLinuxCNC up in {m._process.started_in_s:.2f} s, connected and homed after {m.startup_s:.2f} s")


@pytest.mark.parametrize("feed", [300.0, 1000.0, 3000.0])
def test_the_latch_is_interpolated_so_it_does_not_depend_on_the_feed(m, feed):
    """Contact + pre-travel + v·latency, to 0.1 µm at every feed; LinuxCNC's own probed position
    lands up to two servo periods later (v·1 ms: 5 µm at 300, 17 µm at 1000, 50 µm at 3000)."""
    _above_block(m, 100.0, 60.0, clearance=5.0)
    start = _xyz(m.status().mcs)
    d = np.array([0.0, 0.0, -1.0])
    result = m.probe(d, 10.0, feed)
    assert result.triggered
    expected = start + (5.0 + _pretravel(d) + feed / 60.0 * LATENCY_S) * d
    error = float(np.linalg.norm(_xyz(result.latched_mcs) - expected))
    own_late = float((np.asarray(m.last_probe["linuxcnc_probed"]) - _xyz(result.latched_mcs)) @ d)
    LATCH[feed] = {"latch_error_um": error * 1000, "linuxcnc_probed_late_um": own_late * 1000}
    print(f"\n{feed:g} mm/min: latch error {error * 1e3:.4f} µm, LinuxCNC's probed_position "
          f"{own_late * 1e3:.1f} µm later")
    assert error < 1e-4
    assert m.last_probe["linuxcnc_tripped"] is True
    assert -1e-9 <= own_late <= 2 * SERVO_PERIOD_S * feed / 60.0 + 1e-6
    assert (_xyz(result.end_mcs) - start) @ d > (_xyz(result.latched_mcs) - start) @ d   # braked behind it


def test_frames_linuxcnc_cannot_hold_are_refused_before_anything_changes(m):
    m.write_offset("G57", {"trans": {"X": 5.0, "Y": 6.0, "Z": -7.0}, "fine": {"Z": 0.002}, "rot": {"Z": -3.25}})
    before = m.nc_offset("G57")
    assert before == {"trans": {"X": 5.0, "Y": 6.0, "Z": -6.998}, "rot": {"Z": -3.25}}
    for name, frame in [("G57", {"trans": {"X": 1.0}, "rot": {"X": 0.5}}),
                        ("G57", {"rot": {"Y": -0.1}}),
                        ("BASIC_0", {"trans": {"X": 1.0}}),
                        ("BASIC_REF", {"rot": {"Z": 1.0}}),
                        ("G505", {"trans": {"Y": 2.0}})]:
        assert m.holds(name, frame) is not None
        with pytest.raises(MachineAlarm) as err:
            m.write_offset(name, frame)
        assert err.value.alarm.is_(alarms.ZO_NUMBER) and name in err.value.alarm.text
    assert m.nc_offset("G57") == before                       # nothing changed
    assert any(a.is_(alarms.ZO_NUMBER) for a in m.status().alarms)
    identity = {"trans": {"X": 0.0, "Y": 0.0, "Z": 0.0}, "fine": {}, "rot": {"X": 0.0, "Y": 0.0, "Z": 0.0}}
    for name in ("BASIC_0", "BASIC_REF", "G505", "G599"):   # nothing to hold: accepted
        assert m.holds(name, identity) is None
        m.write_offset(name, identity)
    m.write_offset("G59.3", {"trans": {"X": -1.5}, "rot": {"Z": 45.0}})
    assert m.nc_offset("G59.3") == {"trans": {"X": -1.5, "Y": 0.0, "Z": 0.0}, "rot": {"Z": 45.0}}
    m.reset()
    assert m.status().alarms == ()


def test_a_rapid_into_the_part_is_linuxcncs_probe_fault_and_breaks_the_probe(m):
    """G0 at 10 m/min decelerates over ~14 mm at 1 m/s²: far beyond the 5 mm deflection."""
    _above_block(m, 100.0, 60.0, clearance=10.0)
    above = m.status().mcs
    result = m.goto({"Z": above["Z"] - 40.0})
    assert not result.completed and result.alarm.is_(alarms.PROBE_COLLISION)
    assert result.mcs["Z"] < above["Z"] - 10.0 - 5.0           # LinuxCNC's real braking distance
    assert any(a.is_(alarms.PROBE_BROKEN) for a in m.status().alarms)
    with pytest.raises(MachineAlarm) as err:
        m.goto(above)
    assert err.value.alarm.is_(alarms.PROBE_BROKEN)
    m.reset()
    assert any(a.is_(alarms.PROBE_BROKEN) for a in m.status().alarms)   # Reset does not repair it
    m.change_tool(9, L_PROBE)                                  # a new stylus
    assert m.goto(above).completed


def test_a_continuous_jog_into_the_part_stops_with_the_collision_alarm(m):
    _above_block(m, 100.0, 60.0, clearance=3.0)
    z = m.status().mcs["Z"]
    m.jog_continuous("Z", -1, feed=600.0)
    deadline = time.monotonic() + 5.0
    while m.status().busy and time.monotonic() < deadline:
        time.sleep(0.01)
    st = m.status()
    assert not st.busy and any(a.is_(alarms.PROBE_COLLISION) for a in st.alarms)
    assert z - 3.0 - 1.0 < st.mcs["Z"] < z - 3.0                # stopped just past the contact


def test_stop_ends_a_continuous_jog_at_once_and_reset_aborts_a_goto(m):
    m.goto(START)
    m.jog_continuous("Y", +1, feed=1000.0)
    time.sleep(0.3)
    t0 = time.monotonic()
    m.stop()
    assert time.monotonic() - t0 < 0.3 and not m.status().busy and m.status().alarms == ()
    answer = {}
    mover = threading.Thread(target=lambda: answer.setdefault("r", m.goto({"X": 500.0}, 3000.0)))
    mover.start()
    time.sleep(0.4)
    m.reset()
    mover.join(5.0)
    result = answer["r"]
    assert not result.completed and result.alarm.is_(alarms.RESET_ABORT)
    assert 0.0 < result.mcs["X"] < 500.0

"""The issue's bar on LinuxCNC: calibrate + corner + Z edge into G54 against the hidden pose.

Driven only through the JSON API (tests/flows/flowkit.py, the same flow as the simulator's
truth tests), in real time, at the measuring feeds 300 and 1000 mm/min (calibration and
measurement at the same feed, as the manual asks). The probe input comes from the scenario's
scene through the realtime comparator; the latch is interpolated inside the servo period, so
the set-up error must not grow with the feed. LinuxCNC itself must then hold that G54, with
its rotation, as its G5x (read with its python module).

Figures (this machine, seed 7, the example probe's asymmetric pre-travel whose unobservable
k = (−0.5, −1.5) µm is part of the error, see tests/flows/test_calibration_truth.py) are
printed and kept in ``RESULTS``.
"""

from __future__ import annotations

import contextlib
import math
import time

import numpy as np
import pytest
from conftest import BRISK_POSITIONING, brisk, linuxcnc_client
from flowkit import Flow, cal_scenario, ok
from truthkit import rpy

RESULTS: dict[float, dict] = {}


def k_shift(sc: dict) -> np.ndarray:
    p = sc["probe"]["pretravel"]
    return np.array([(p["X+"] - p["X-"]) / 2.0, (p["Y+"] - p["Y-"]) / 2.0, 0.0])


@pytest.mark.parametrize("feed", [300.0, 1000.0])
def test_setup_into_g54_matches_the_pose_and_linuxcnc_holds_it(tmp_path, feed):
    sc = brisk(cal_scenario())
    t0 = time.monotonic()
    with contextlib.ExitStack() as stack:
        for attempt in (1, 2):
            where = tmp_path / f"start{attempt}"
            where.mkdir()
            client = stack.enter_context(linuxcnc_client(where, sc))
            started = time.monotonic() - t0
            flow = Flow(client, sc)
            state = ok(client.get("/api/machine"))
            assert state["controller"] == "linuxcnc" and state["alarms"] == []
            ok(client.put("/api/settings", json={**BRISK_POSITIONING, "measuring_feed": feed}))
            try:
                flow.calibrate_radius()
                break
            except AssertionError as first:
                # Known intermittent (CI, fresh clone, loaded computer): one LinuxCNC start runs
                # no block at all and says nothing; the adapter answers 65200 with LinuxCNC's
                # state (issue 18 note). Still open; the test starts LinuxCNC once more.
                if attempt == 2 or not ("65200" in str(first) or "61301" in str(first)):
                    raise
                print(f"\nfirst calibration refused ({first}); LinuxCNC started again; the probing move: "
                      f"{client.app.state.services.machine.machine.last_probe}")
                stack.close()
                t0 = time.monotonic()
        flow.calibrate_length()
        answer = flow.corner_and_z_setup("G54")
        assert answer["corner"]["warnings"] == [] and answer["edge"]["warnings"] == []
        _t, angle, dt = flow.offset_error("G54")
        stored = ok(client.get("/api/offsets/G54"))
        machine = client.app.state.services.machine.machine
        lc = machine.linuxcnc_stat()                           # LinuxCNC itself, its python module
        held = np.array(lc.g5x_offset[:3])
        assert lc.g5x_index == 1                               # G54 active in LinuxCNC
        trans = np.array([stored["trans"][a] + stored["fine"][a] for a in "XYZ"])
        assert held == pytest.approx(trans, abs=1e-9)
        assert lc.rotation_xy == pytest.approx(stored["rot"]["Z"], abs=1e-9)
        assert stored["rot"]["X"] == 0.0 and stored["rot"]["Y"] == 0.0
        pose = sc["workpiece"]["pose"]
        lc_angle = abs(math.radians(lc.rotation_xy - pose["rot"][2]))
        last = machine.last_probe
    k_machine = rpy(sc["workpiece"]["pose"]["rot"]) @ k_shift(sc)
    RESULTS[feed] = {"error_um": (dt * 1000).round(3).tolist(), "error_norm_um": float(np.linalg.norm(dt) * 1000),
                     "error_without_k_um": float(np.linalg.norm(dt - k_machine) * 1000),
                     "angle_urad": angle * 1e6, "start_s": started, "run_s": time.monotonic() - t0,
                     "linuxcnc_own_latch_late_um": 1000 * float(np.linalg.norm(
                         np.subtract(last["linuxcnc_probed"], last["latch"])))}
    print(f"\nLinuxCNC set-up at {feed:g} mm/min: {RESULTS[feed]}")
    # the done bar: 3 µm / 20 µrad; the test bar: 2 µm / 10 µrad beyond the unobservable k
    assert np.linalg.norm(dt) < 0.003 and angle < 20e-6 and lc_angle < 20e-6
    assert np.linalg.norm(dt - k_machine) < 0.002 and angle < 10e-6

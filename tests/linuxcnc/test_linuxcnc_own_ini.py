"""The machine's own LinuxCNC configuration (``--linuxcnc-ini``, design.md §10.7, issue 34): LinuxCNC's
shipped sample ``axis_mm.ini`` with a probe made of standard HAL components (own_config.py).

The truth is the probe's plane: ``wcomp`` switches in the first servo period in which machine Z
is below it, so the switching position lies within v·T (T = 1 ms) beyond the plane; LinuxCNC's
own probed position lands another 1-2 servo periods later (measured 10-20 µm at 1000 mm/min),
which the HMI removes with its second, slow stage and the delay from the two feeds."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import httpx
import pytest
from own_config import PLANE_Z, own_config
from waiting import wait_until

ROOT = Path(__file__).resolve().parent.parent.parent


def _client(tmp_path: Path, ini: Path):
    from fastapi.testclient import TestClient

    from app.config import Settings
    from app.main import create_app

    return TestClient(create_app(Settings(db_path=tmp_path / "hmi.db", machine="linuxcnc", linuxcnc_ini=ini)))


def _probe_plane(client, feed: float) -> dict:
    above = {"X": 10.0, "Y": -5.0, "Z": PLANE_Z + 4.0, "coords": "MCS"}
    assert client.post("/api/machine/goto", json=above).status_code == 200
    answer = client.post("/api/machine/probe", json={"direction": [0, 0, -1], "distance": 8.0, "feed": feed})
    assert answer.status_code == 200, answer.text
    return answer.json()


def test_the_sample_configuration_with_a_wcomp_probe_sets_up_within_2_um(tmp_path):
    ini = own_config(tmp_path / "config")
    with _client(tmp_path, ini) as client:
        state = client.get("/api/machine").json()
        assert state["controller"] == "linuxcnc" and state["alarms"] == []
        assert state["estop"] is False and state["machine_on"] is True
        machine = client.app.state.services.machine.machine
        assert machine.own_ini == ini.resolve()
        for feed in (300.0, 1000.0):
            answer = _probe_plane(client, feed)
            assert answer["triggered"]
            z = answer["mcs"]["Z"]
            own_late = PLANE_Z - machine.last_probe["linuxcnc_probed"][2]
            print(f"\n{feed:g} mm/min: switching position {1000 * (z - PLANE_Z):+.3f} µm from the plane, "
                  f"LinuxCNC's own probed position {1000 * own_late:.1f} µm late; {machine.last_probe}")
            assert abs(z - PLANE_Z) < 0.002
            assert answer["mcs"]["X"] == pytest.approx(10.0, abs=1e-9)
            assert answer["end_mcs"]["Z"] > PLANE_Z                      # it ends with the probe released
        assert own_late > 0.005                                          # what the two stages removed at 1000
        # the guard has no model of this machine's work space and says so
        assert client.get("/api/machine").json()["alarms"] == []
    assert not Path("/tmp/linuxcnc.lock").exists()                       # stopped with the HMI


def test_a_bouncing_probe_neither_trips_a_move_nor_moves_the_latch(tmp_path):
    ini = own_config(tmp_path / "config", probe="chatter")
    with _client(tmp_path, ini) as client:
        answer = _probe_plane(client, 1000.0)
        assert answer["triggered"] and abs(answer["mcs"]["Z"] - PLANE_Z) < 0.002
        state = client.get("/api/machine").json()
        assert state["alarms"] == []
        up = client.post("/api/machine/goto", json={"Z": PLANE_Z + 10.0, "coords": "MCS"})
        assert up.status_code == 200 and up.json()["alarms"] == []


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _serve(tmp_path: Path, ini: Path) -> tuple[subprocess.Popen, str]:
    port = _free_port()
    env = dict(os.environ, HMI_LINUXCNC_DIR=str(tmp_path / "linuxcnc"))
    app = subprocess.Popen([sys.executable, "-m", "app", "--linuxcnc-ini", str(ini), "--db", str(tmp_path / "hmi.db"),
                            "--port", str(port)], cwd=ROOT, env=env, stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL)
    return app, f"http://127.0.0.1:{port}"


def _wait_up(app: subprocess.Popen, url: str) -> dict:
    """The HMI's first ``GET /api/machine`` answer, once it serves (LinuxCNC started and homed)."""
    with httpx.Client(base_url=url, timeout=5) as http:
        def answer() -> dict | None:
            assert app.poll() is None, "the HMI ended"
            try:
                response = http.get("/api/machine")
            except httpx.TransportError:
                return None
            return response.json() if response.status_code == 200 else None

        return wait_until(answer, "the HMI comes up with LinuxCNC", 120.0)


def test_sigkill_of_the_hmi_then_a_start_reaches_linuxcnc_and_sigterm_ends_a_measurement(tmp_path):
    ini = own_config(tmp_path / "config")
    first, url = _serve(tmp_path, ini)
    try:
        assert _wait_up(first, url)["controller"] == "linuxcnc"
    finally:
        first.send_signal(signal.SIGKILL)
        first.wait()
    second, url = _serve(tmp_path, ini)
    try:
        state = _wait_up(second, url)
        assert state["controller"] == "linuxcnc" and state["alarms"] == []
        with httpx.Client(base_url=url, timeout=30) as http:
            above = {"X": 0.0, "Y": 0.0, "Z": PLANE_Z + 2.0, "coords": "MCS"}
            assert http.post("/api/machine/goto", json=above).status_code == 200
            answer = http.post("/api/machine/probe", json={"direction": [0, 0, -1], "distance": 4.0, "feed": 600.0})
            assert answer.status_code == 200 and abs(answer.json()["mcs"]["Z"] - PLANE_Z) < 0.002
            # a measuring move that would run 30 s (no contact upwards) ends at SIGTERM: aborted, not run out
            answers: list = []
            running = threading.Thread(target=lambda: answers.append(_long_probe(url)), daemon=True)
            running.start()
            wait_until(lambda: http.get("/api/machine").json()["busy"], "the measuring move runs", 20.0)
            t0 = time.monotonic()
            second.send_signal(signal.SIGTERM)
            running.join(timeout=60)
            print(f"\nthe measurement ended {time.monotonic() - t0:.2f} s after SIGTERM: {answers}")
            assert answers and answers[0] != 200            # aborted (409 alarm, or the connection closed)
    finally:
        second.send_signal(signal.SIGTERM)
        second.wait(timeout=60)
    assert not Path("/tmp/linuxcnc.lock").exists()


def _long_probe(url: str):
    with httpx.Client(base_url=url, timeout=60) as http:
        try:
            return http.post("/api/machine/probe", json={"direction": [0, 0, 1], "distance": 50.0,
                                                         "feed": 100.0}).status_code
        except httpx.TransportError as exc:
            return type(exc).__name__

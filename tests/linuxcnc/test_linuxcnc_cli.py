"""``python -m app --machine linuxcnc --scenario PATH`` serves the API on LinuxCNC and stops it
with the HMI; a LinuxCNC that cannot come up is one clear line."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import httpx
from flowkit import CAL_SCENARIO

ROOT = Path(__file__).resolve().parent.parent.parent


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _linuxcnc_processes() -> list[str]:
    names = ("linuxcncsvr", "milltask", "rtapi_app")
    found = []
    for proc in Path("/proc").iterdir():
        try:
            if proc.name.isdigit() and (proc / "comm").read_text().strip() in names \
                    and ") Z" not in (proc / "stat").read_text():
                found.append(proc.name)
        except OSError:
            continue
    return found


def _run(tmp_path: Path, scenario: dict, port: int) -> subprocess.Popen:
    path = tmp_path / "scenario.json"
    path.write_text(json.dumps(scenario))
    env = dict(os.environ, HMI_LINUXCNC_DIR=str(tmp_path / "linuxcnc"))
    return subprocess.Popen([sys.executable, "-m", "app", "--machine", "linuxcnc", "--scenario", str(path),
                             "--db", str(tmp_path / "hmi.db"), "--port", str(port)], cwd=ROOT, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)


def test_serves_the_api_on_linuxcnc_and_stops_it_with_the_hmi(tmp_path):
    port = _free_port()
    t0 = time.monotonic()
    app = _run(tmp_path, CAL_SCENARIO, port)
    try:
        with httpx.Client(base_url=f"http://127.0.0.1:{port}", timeout=5) as http:
            while True:
                assert app.poll() is None, app.stdout.read()
                try:
                    if http.get("/api/health").status_code == 200:
                        break
                except httpx.TransportError:
                    pass
                assert time.monotonic() - t0 < 60
                time.sleep(0.1)
            print(f"\nserving on LinuxCNC after {time.monotonic() - t0:.1f} s")
            state = http.get("/api/machine").json()
            assert state["controller"] == "linuxcnc" and state["alarms"] == []
            assert state["mcs"] == {"X": 400.0, "Y": 300.0, "Z": 0.0}            # homed at the start
            moved = http.post("/api/machine/jog", json={"axis": "X", "distance": -2.5})
            assert moved.status_code == 200 and moved.json()["mcs"]["X"] == 397.5
            assert http.post("/api/sim/scenario", json=CAL_SCENARIO).status_code == 409   # not simulated
        assert _linuxcnc_processes()
    finally:
        app.send_signal(signal.SIGINT)
        app.wait(timeout=30)
    assert not _linuxcnc_processes()                  # LinuxCNC stopped with the HMI
    assert not Path("/tmp/linuxcnc.lock").exists()


def test_a_linuxcnc_that_cannot_come_up_is_one_clear_line(tmp_path):
    scenario = {**CAL_SCENARIO, "rotary_axes": {"C": {}}}
    app = _run(tmp_path, scenario, _free_port())
    out, _ = app.communicate(timeout=60)
    assert app.returncode != 0
    last = out.strip().splitlines()[-1]
    assert last.startswith("python -m app: ") and "X, Y, Z only" in last and "Traceback" not in out

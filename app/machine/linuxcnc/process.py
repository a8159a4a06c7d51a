"""Starting and stopping LinuxCNC headless with the project's configuration.

``LinuxCncProcess.start()`` builds the probe comparator (``halcompile``, once per source
version), writes the configuration (config.py) and runs Debian's ``linuxcnc`` script with
the ``dummy`` display: that display waits for a line on the script's standard input, which
this process holds as a pipe. LinuxCNC is up when the script prints the dummy display's line
(HAL, motion, task and io are running then). ``stop()`` writes that line: the script shuts
LinuxCNC down in its own order. Should the HMI die, the pipe closes and LinuxCNC shuts down
the same way: it never outlives the HMI.

Decisions:
- As root, the realtime server (``rtapi_app``) refuses to run without a fallback user:
  ``RTAPI_UID`` is the invoking user (``SUDO_UID``) or ``nobody``, and ``RTAPI_FIFO_PATH``
  names a socket in a folder that user may reach and write (a fresh ``/tmp/jogmeasure-rtapi-*``,
  removed at stop: a data folder under a private home would not be reachable).
- The comparator is a realtime module; LinuxCNC's uspace server loads modules only from its
  own folder (``/usr/lib/linuxcnc/modules``), so it is compiled there under the name
  ``jogprobe`` (like ``halcompile --install``), again only when the source changed.
- One LinuxCNC per machine (its lock file ``/tmp/linuxcnc.lock``, fixed shared memory keys):
  a running one that is not ours is an error, never killed; a stale lock file is removed.
- Anything that keeps LinuxCNC from coming up is one ``LinuxCncStartError`` whose message is
  one line naming the cause (the script's last error line).
"""

from __future__ import annotations

import collections
import hashlib
import os
import pwd
import shutil
import subprocess
import tempfile
import threading
import time
from pathlib import Path

from ..registry import MachineUnavailable
from ..scenario import Scenario
from .config import COMPONENT, write_config

COMP_SOURCE = Path(__file__).resolve().parent / "hal" / f"{COMPONENT}.comp"
MODULE_DIR = Path("/usr/lib/linuxcnc/modules")
LOCK_FILE = Path("/tmp/linuxcnc.lock")
READY_LINE = "DUMMY DISPLAY MODULE"
START_TIMEOUT_S = 30.0
STOP_TIMEOUT_S = 20.0


class LinuxCncStartError(MachineUnavailable):
    """LinuxCNC could not be started (one line: why)."""


def _running(names=("linuxcncsvr", "milltask", "rtapi_app")) -> list[str]:
    found = []
    for proc in Path("/proc").iterdir():
        if not proc.name.isdigit():
            continue
        try:
            comm = (proc / "comm").read_text().strip()
            state = (proc / "stat").read_text().split(") ", 1)[1][:1]
        except (OSError, IndexError):
            continue
        if comm in names and state != "Z":
            found.append(comm)
    return found


def ensure_component() -> Path:
    """The comparator module in LinuxCNC's module folder, compiled when its source changed."""
    digest = hashlib.sha256(COMP_SOURCE.read_bytes()).hexdigest()[:16]
    target = MODULE_DIR / f"{COMPONENT}.so"
    stamp = MODULE_DIR / f"{COMPONENT}.source-sha256"
    if target.exists() and stamp.exists() and stamp.read_text().strip() == digest:
        return target
    if shutil.which("halcompile") is None:
        raise LinuxCncStartError("halcompile is missing: apt-get install linuxcnc-uspace-dev")
    with tempfile.TemporaryDirectory(prefix="jogprobe-") as tmp:
        shutil.copy(COMP_SOURCE, tmp)
        build = subprocess.run(["halcompile", "--compile", f"{COMPONENT}.comp"], cwd=tmp,
                               capture_output=True, text=True, check=False)
        if build.returncode != 0:
            last = (build.stderr or build.stdout).strip().splitlines()[-1:] or ["?"]
            raise LinuxCncStartError(f"halcompile failed for {COMP_SOURCE.name}: {last[0]}")
        try:
            shutil.copy(Path(tmp) / f"{COMPONENT}.so", target)
            stamp.write_text(digest + "\n")
        except OSError as exc:
            raise LinuxCncStartError(f"cannot install the probe comparator into {MODULE_DIR} ({exc.strerror}): "
                                     f"run as root once, or `halcompile --install {COMP_SOURCE}`") from None
    return target


def _fallback_uid() -> int:
    sudo = os.environ.get("SUDO_UID")
    if sudo and sudo.isdigit() and int(sudo) != 0:
        return int(sudo)
    try:
        return pwd.getpwnam("nobody").pw_uid
    except KeyError:
        return 65534


class LinuxCncProcess:
    """One headless LinuxCNC run of the project's configuration in ``folder``."""

    def __init__(self, scenario: Scenario, folder: Path) -> None:
        self._scenario = scenario
        self.folder = Path(folder)
        self._proc: subprocess.Popen | None = None
        self._lines: collections.deque[str] = collections.deque(maxlen=200)
        self._ready = threading.Event()
        self._reader: threading.Thread | None = None
        self.started_in_s: float | None = None
        self._rtapi_dir: Path | None = None

    @property
    def alive(self) -> bool:
        return self._proc is not None and self._proc.poll() is None

    def output(self) -> list[str]:
        return list(self._lines)

    def start(self) -> None:
        if shutil.which("linuxcnc") is None:
            raise LinuxCncStartError("LinuxCNC is not installed: apt-get install linuxcnc-uspace linuxcnc-uspace-dev")
        t0 = time.monotonic()
        ensure_component()
        if LOCK_FILE.exists():
            others = _running()
            if others:
                raise LinuxCncStartError(f"another LinuxCNC is running on this machine ({', '.join(sorted(set(others)))})"
                                         "; stop it first")
            LOCK_FILE.unlink(missing_ok=True)            # stale: left by a LinuxCNC that died
        ini = write_config(self._scenario, self.folder)
        env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
        if os.geteuid() == 0:
            uid = _fallback_uid()
            # the socket's folder must be reachable for that user: not under a private data folder
            self._rtapi_dir = Path(tempfile.mkdtemp(prefix="jogmeasure-rtapi-"))
            os.chown(self._rtapi_dir, uid, -1)
            env.update(RTAPI_UID=str(uid), RTAPI_FIFO_PATH=str(self._rtapi_dir / "fifo"))
        self._proc = subprocess.Popen(["linuxcnc", "-r", str(ini)], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                      stderr=subprocess.STDOUT, cwd=self.folder, env=env, text=True, bufsize=1,
                                      start_new_session=True)
        self._reader = threading.Thread(target=self._read, name="linuxcnc-output", daemon=True)
        self._reader.start()
        deadline = time.monotonic() + START_TIMEOUT_S
        while not self._ready.wait(0.01):
            if self._proc.poll() is not None or time.monotonic() > deadline:
                why = self._why()
                self.stop()
                raise LinuxCncStartError(f"LinuxCNC did not come up: {why}")
        self.started_in_s = time.monotonic() - t0

    def _read(self) -> None:
        proc = self._proc
        assert proc is not None and proc.stdout is not None
        for line in proc.stdout:
            self._lines.append(line.rstrip())
            if READY_LINE in line:
                self._ready.set()

    def _why(self) -> str:
        lines = [ln for ln in self._lines if ln.strip() and "terminated with an error" not in ln
                 and "more information in the log" not in ln and not ln.startswith(" ")]
        errors = [ln for ln in lines if any(w in ln.lower() for w in ("error", "fail", "cannot", "can't", "refus"))]
        if self._proc is not None and self._proc.poll() is None:
            return f"no answer within {START_TIMEOUT_S:g} s" + (f" ({errors[-1].strip()})" if errors else "")
        return (errors or lines or ["the linuxcnc script ended without a message"])[-1].strip()

    def stop(self) -> None:
        """Shut LinuxCNC down (the dummy display's line) and wait for it; idempotent."""
        proc, self._proc = self._proc, None
        if proc is None:
            return
        try:
            if proc.poll() is None and proc.stdin is not None:
                proc.stdin.write("\n")
                proc.stdin.close()
            proc.wait(timeout=STOP_TIMEOUT_S)
        except (OSError, ValueError):
            pass
        except subprocess.TimeoutExpired:
            proc.terminate()
            try:
                proc.wait(timeout=5.0)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        if self._reader is not None:
            self._reader.join(timeout=2.0)
        if self._rtapi_dir is not None:
            shutil.rmtree(self._rtapi_dir, ignore_errors=True)
            self._rtapi_dir = None

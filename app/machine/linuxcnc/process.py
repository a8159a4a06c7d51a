"""Starting and stopping LinuxCNC headless: the project's configuration or the machine's own INI.

``LinuxCncProcess.start()`` writes (or copies) the configuration through its ``prepare``
callable and runs Debian's ``linuxcnc`` script with the ``dummy`` display: that display waits
for a line on the script's standard input, which this process holds as a pipe. LinuxCNC is up
when the script prints the dummy display's line (HAL, motion, task and io are running then).
``stop()`` writes that line: the script shuts LinuxCNC down in its own order.

Lifetime (issue 34 §4):
- Should the HMI die (even SIGKILL), the pipe closes, the dummy display's ``read`` ends and
  the script shuts LinuxCNC down the same way. Its output goes to a file (``linuxcnc.log`` in
  the data folder), never to a pipe of the HMI: a script writing its shutdown messages into a
  pipe nobody reads any more dies of SIGPIPE half-way and leaves LinuxCNC running.
- A start that finds a LinuxCNC running asks the record ``/tmp/jogmeasure-linuxcnc.json``
  (next to LinuxCNC's own lock file): an instance this HMI product started from a process that
  is gone is stale and is shut down (its script first, then, if it is gone too, LinuxCNC's own
  clean-up commands with that instance's realtime socket); every other running LinuxCNC is
  refused with a message, never touched.

Decisions:
- As root, the realtime server (``rtapi_app``) refuses to run without a fallback user:
  ``RTAPI_UID`` is the invoking user (``SUDO_UID``) or ``nobody``, and ``RTAPI_FIFO_PATH``
  names a socket in a folder that user may reach and write (a fresh ``/tmp/jogmeasure-rtapi-*``,
  removed at stop: a data folder under a private home would not be reachable).
- The headless display also replaces AXIS's manual tool change window (a configuration made
  for AXIS loads ``hallib/axis_manualtoolchange.hal``): ``linuxcnc -H`` puts a folder first in
  the HAL library path whose ``axis_manualtoolchange.hal`` loads ``headless/hal_manualtoolchange``
  (same pins; the operator confirms the change at the HMI).
- One LinuxCNC per computer (its lock file ``/tmp/linuxcnc.lock``, fixed shared memory keys).
- Anything that keeps LinuxCNC from coming up is one ``LinuxCncStartError`` whose message is
  one line naming the cause (the script's last error line).
"""

from __future__ import annotations

import collections
import contextlib
import hashlib
import json
import os
import pwd
import shutil
import signal
import subprocess
import tempfile
import threading
import time
from collections.abc import Callable
from pathlib import Path

from ..registry import MachineUnavailable
from .config import COMPONENT

COMP_SOURCE = Path(__file__).resolve().parent / "hal" / f"{COMPONENT}.comp"
HEADLESS_TOOLCHANGE = Path(__file__).resolve().parent / "headless" / "hal_manualtoolchange"
MODULE_DIR = Path("/usr/lib/linuxcnc/modules")
LOCK_FILE = Path("/tmp/linuxcnc.lock")
RECORD_FILE = Path("/tmp/jogmeasure-linuxcnc.json")
LOG = "linuxcnc.log"
READY_LINE = "DUMMY DISPLAY MODULE"
START_TIMEOUT_S = 30.0
STOP_TIMEOUT_S = 20.0
STALE_EXIT_S = 8.0              # a stale script whose HMI died shuts down by itself (stdin closed)
LINUXCNC_PROCESSES = ("linuxcncsvr", "milltask", "rtapi_app")


class LinuxCncStartError(MachineUnavailable):
    """LinuxCNC could not be started (one line: why)."""


def running(names=LINUXCNC_PROCESSES) -> list[tuple[int, str]]:
    """(pid, name) of LinuxCNC's processes that run (zombies left out)."""
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
            found.append((int(proc.name), comm))
    return found


def _proc_stat(pid: int) -> list[str] | None:
    """The fields of /proc/<pid>/stat after the command name (index 0 = state), None when gone."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(") ", 1)[1].split()
    except (OSError, IndexError):
        return None
    return None if fields[0] == "Z" else fields


def _start_ticks(pid: int) -> str | None:
    fields = _proc_stat(pid)
    return fields[19] if fields else None        # field 22 of stat: start time in clock ticks


def _session(pid: int) -> int | None:
    fields = _proc_stat(pid)
    return int(fields[3]) if fields else None    # field 6 of stat: session id


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


def _read_record() -> dict | None:
    try:
        record = json.loads(RECORD_FILE.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return record if isinstance(record, dict) else None


def _alive(pid, ticks) -> bool:
    return isinstance(pid, int) and pid > 0 and _start_ticks(pid) is not None and _start_ticks(pid) == ticks


def stale_instance(running: list[tuple[int, str]]) -> dict | None:
    """The record of the running LinuxCNC when this HMI product started it from a process that is
    gone and every running LinuxCNC process belongs to that start's session; else None."""
    record = _read_record()
    if record is None or _alive(record.get("hmi_pid"), record.get("hmi_ticks")):
        return None
    sid = record.get("sid")
    if not isinstance(sid, int) or not running or any(_session(pid) != sid for pid, _ in running):
        return None
    return record


def _wait_gone(pids: list[int], timeout: float) -> bool:
    deadline = time.monotonic() + timeout
    while any(_proc_stat(p) is not None for p in pids):
        if time.monotonic() > deadline:
            return False
        time.sleep(0.05)
    return True


def _linuxcnc_env(record: dict | None = None) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    if record and record.get("rtapi_fifo"):
        env.update(RTAPI_UID=str(record.get("rtapi_uid", _fallback_uid())), RTAPI_FIFO_PATH=record["rtapi_fifo"])
    return env


def shut_down_stale(record: dict, running: list[tuple[int, str]]) -> None:
    """Shut down a stale instance this HMI product started (``stale_instance``)."""
    pids = [pid for pid, _ in running]
    script = record.get("script_pid")
    if isinstance(script, int) and _alive(script, record.get("script_ticks")):
        # its HMI is gone, so its standard input is closed: it is shutting down already, or it
        # waits in a state where a TERM (its own trap: clean-up, exit) ends it
        if not _wait_gone([script], STALE_EXIT_S):
            with contextlib.suppress(OSError):
                os.kill(script, signal.SIGTERM)
        if _wait_gone([script, *pids], STOP_TIMEOUT_S):
            _remove_record(record)
            return
    # the script is gone but LinuxCNC is not: LinuxCNC's own clean-up, with that instance's socket
    env = _linuxcnc_env(record)
    for pid in pids:
        with contextlib.suppress(OSError):
            os.kill(pid, signal.SIGTERM)
    _wait_gone(pids, 5.0)
    for command in (["halcmd", "stop"], ["halcmd", "unload", "all"], ["/usr/lib/linuxcnc/realtime", "stop"]):
        with contextlib.suppress(OSError, subprocess.TimeoutExpired):
            subprocess.run(command, env=env, capture_output=True, timeout=15.0, check=False)
    for pid in pids:
        with contextlib.suppress(OSError):
            os.kill(pid, signal.SIGKILL)
    _wait_gone(pids, 5.0)
    LOCK_FILE.unlink(missing_ok=True)
    _remove_record(record)


def _remove_record(record: dict) -> None:
    if record.get("rtapi_dir"):
        shutil.rmtree(record["rtapi_dir"], ignore_errors=True)
    if _read_record() == record:
        RECORD_FILE.unlink(missing_ok=True)


def clear_the_way() -> None:
    """Before a start: a stale lock file goes, a stale instance of this product is shut down,
    any other running LinuxCNC is refused (never touched)."""
    if not LOCK_FILE.exists():
        return
    found = running()
    if not found:
        LOCK_FILE.unlink(missing_ok=True)             # stale: left by a LinuxCNC that died
        return
    record = stale_instance(found)
    if record is None:
        names = ", ".join(sorted({name for _, name in found}))
        raise LinuxCncStartError(f"another LinuxCNC is running on this machine ({names}); stop it first")
    shut_down_stale(record, found)
    still = running()
    if still:
        raise LinuxCncStartError("a LinuxCNC this HMI had started did not shut down "
                                 f"({', '.join(sorted({n for _, n in still}))}); stop it first")


class LinuxCncProcess:
    """One headless LinuxCNC run; ``prepare(folder)`` writes what it runs and returns the INI."""

    def __init__(self, folder: Path, prepare: Callable[[Path], Path], component: bool = True) -> None:
        self.folder = Path(folder)
        self._prepare = prepare
        self._component = component
        self._proc: subprocess.Popen | None = None
        self._lines: collections.deque[str] = collections.deque(maxlen=200)
        self._ready = threading.Event()
        self._done = threading.Event()
        self._reader: threading.Thread | None = None
        self.started_in_s: float | None = None
        self._rtapi_dir: Path | None = None
        self._record: dict | None = None
        self.ini: Path | None = None

    @property
    def alive(self) -> bool:
        return self._proc is not None and self._proc.poll() is None

    def output(self) -> list[str]:
        return list(self._lines)

    def _headless_dir(self) -> Path:
        """The HAL library folder put first (``linuxcnc -H``): the headless tool change."""
        folder = self.folder / "headless"
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "axis_manualtoolchange.hal").write_text(
            "# generated by the Measure-in-JOG HMI: AXIS's manual tool change, headless (same pins)\n"
            f"loadusr -W {HEADLESS_TOOLCHANGE}\n"
            "unlinkp iocontrol.0.tool-change\nunlinkp iocontrol.0.tool-changed\n"
            "net tool-change hal_manualtoolchange.change iocontrol.0.tool-change\n"
            "net tool-changed hal_manualtoolchange.changed iocontrol.0.tool-changed\n"
            "net tool-prep-number hal_manualtoolchange.number iocontrol.0.tool-prep-number\n", encoding="utf-8")
        return folder

    def start(self) -> None:
        if shutil.which("linuxcnc") is None:
            raise LinuxCncStartError("LinuxCNC is not installed: apt-get install linuxcnc-uspace linuxcnc-uspace-dev")
        t0 = time.monotonic()
        if self._component:
            ensure_component()
        clear_the_way()
        self.folder.mkdir(parents=True, exist_ok=True)
        ini = self.ini = self._prepare(self.folder)
        env = _linuxcnc_env()
        uid = None
        if os.geteuid() == 0:
            uid = _fallback_uid()
            # the socket's folder must be reachable for that user: not under a private data folder
            self._rtapi_dir = Path(tempfile.mkdtemp(prefix="jogmeasure-rtapi-"))
            os.chown(self._rtapi_dir, uid, -1)
            env.update(RTAPI_UID=str(uid), RTAPI_FIFO_PATH=str(self._rtapi_dir / "fifo"))
        log_path = self.folder / LOG
        log = open(log_path, "w", encoding="utf-8")            # noqa: SIM115 - handed to the child
        try:
            self._proc = subprocess.Popen(["linuxcnc", "-r", "-H", str(self._headless_dir()), str(ini)],
                                          stdin=subprocess.PIPE, stdout=log, stderr=subprocess.STDOUT,
                                          cwd=ini.parent, env=env, text=True, start_new_session=True)
        finally:
            log.close()
        self._record = {"hmi_pid": os.getpid(), "hmi_ticks": _start_ticks(os.getpid()),
                        "script_pid": self._proc.pid, "script_ticks": _start_ticks(self._proc.pid),
                        "sid": self._proc.pid, "ini": str(ini), "rtapi_uid": uid,
                        "rtapi_dir": str(self._rtapi_dir) if self._rtapi_dir else None,
                        "rtapi_fifo": env.get("RTAPI_FIFO_PATH")}
        with contextlib.suppress(OSError):
            RECORD_FILE.write_text(json.dumps(self._record), encoding="utf-8")
        self._reader = threading.Thread(target=self._read, args=(log_path,), name="linuxcnc-output", daemon=True)
        self._reader.start()
        deadline = time.monotonic() + START_TIMEOUT_S
        while not self._ready.wait(0.01):
            if self._proc.poll() is not None or time.monotonic() > deadline:
                time.sleep(0.1)                        # the last lines into the log
                why = self._why()
                self.stop()
                raise LinuxCncStartError(f"LinuxCNC did not come up: {why}")
        self.started_in_s = time.monotonic() - t0

    def _read(self, path: Path) -> None:
        """Follow the script's log (a file, see the module docstring) until the script ends."""
        with open(path, encoding="utf-8", errors="replace") as log:
            partial = ""
            while not self._done.is_set():
                chunk = log.readline()
                if not chunk:
                    proc = self._proc
                    if proc is None or proc.poll() is not None:
                        break
                    time.sleep(0.01)
                    continue
                partial += chunk
                if not partial.endswith("\n"):
                    continue
                line, partial = partial.rstrip(), ""
                self._lines.append(line)
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
        self._done.set()
        if self._reader is not None:
            self._reader.join(timeout=2.0)
        if self._record is not None:
            _remove_record(self._record)
            self._record = None
        elif self._rtapi_dir is not None:
            shutil.rmtree(self._rtapi_dir, ignore_errors=True)
        self._rtapi_dir = None

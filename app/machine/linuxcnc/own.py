"""The machine's own LinuxCNC configuration (``--linuxcnc-ini PATH``, design.md §10.7, issue 34).

``OwnIni`` reads what the HMI needs from the user's INI (LinuxCNC's INI format: ``[SECTION]``,
``KEY = value``, ``#``/``;`` comment lines, repeated keys): the axes and their limits, speeds and
accelerations, the servo period, the parameter and tool table files. ``headless_copy`` writes
the INI once more next to it (same folder: every relative path in it and in its HAL files stays
what it was) with only ``[DISPLAY] DISPLAY`` replaced by ``dummy``.

Decisions:
- Trivial kinematics with the coordinates X Y Z (joints 0, 1, 2) in mm: the HMI's MCS is the
  joint positions, as on the generated configuration. Anything else is refused at the start
  with a message naming the INI entry (inch machines, gantries, rotary axes: not yet).
- The probe's hardware latch (issue 34 §2): ``[HMI] PROBE_LATCH_X/_Y/_Z`` name HAL pins that hold
  the axis positions latched by the hardware at the probe's switching instant (e.g. a Mesa
  encoder's ``position-latched``), ``[HMI] PROBE_LATCH_VALID`` optionally a bit pin that is true
  while the latch holds a fresh value. Without them the HMI corrects LinuxCNC's probed position
  from two feeds (adapter.py).
"""

from __future__ import annotations

import re
from pathlib import Path

from ..scenario import GEOMETRY_AXES, Scenario
from .process import LinuxCncStartError

HEADLESS_PREFIX = "."
HEADLESS_SUFFIX = ".hmi-headless.ini"
_SECTION = re.compile(r"^\s*\[([^\]]+)\]\s*$")
_ENTRY = re.compile(r"^\s*([^=#;\s][^=]*?)\s*=\s*(.*?)\s*$")


def parse_ini(text: str) -> dict[str, dict[str, list[str]]]:
    """``{section: {key: [values in order]}}`` of LinuxCNC's INI text."""
    sections: dict[str, dict[str, list[str]]] = {}
    current: dict[str, list[str]] | None = None
    for line in text.splitlines():
        if line.lstrip().startswith(("#", ";")):
            continue
        header = _SECTION.match(line)
        if header:
            current = sections.setdefault(header.group(1).strip(), {})
            continue
        entry = _ENTRY.match(line)
        if entry and current is not None:
            current.setdefault(entry.group(1), []).append(entry.group(2))
    return sections


class OwnIni:
    """What the HMI takes from the machine's own INI file (read once, at the start)."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path).expanduser().resolve()
        try:
            self.text = self.path.read_text(encoding="utf-8", errors="replace")
        except OSError as exc:
            raise LinuxCncStartError(f"--linuxcnc-ini {path}: cannot read it ({exc.strerror})") from None
        self.sections = parse_ini(self.text)
        kins = self.get("KINS", "KINEMATICS") or ""
        coordinates = (self.get("TRAJ", "COORDINATES") or "").replace(" ", "").upper()
        if not kins.split()[:1] == ["trivkins"] or coordinates != "XYZ":
            raise LinuxCncStartError(f"--linuxcnc-ini {self.path.name}: the HMI drives trivial kinematics with the "
                                     f"axes X Y Z ([KINS] KINEMATICS = {kins or '?'}, [TRAJ] COORDINATES = "
                                     f"{coordinates or '?'})")
        units = (self.get("TRAJ", "LINEAR_UNITS") or "mm").lower()
        if units not in ("mm", "metric"):
            raise LinuxCncStartError(f"--linuxcnc-ini {self.path.name}: the HMI works in mm; [TRAJ] LINEAR_UNITS = "
                                     f"{units}")

    def get(self, section: str, key: str) -> str | None:
        values = self.sections.get(section, {}).get(key)
        return values[0] if values else None

    def number(self, section: str, key: str, default: float) -> float:
        value = self.get(section, key)
        try:
            return float(value) if value is not None else default
        except ValueError:
            raise LinuxCncStartError(f"--linuxcnc-ini {self.path.name}: [{section}] {key} = {value} is not a "
                                     "number") from None

    @property
    def servo_period_s(self) -> float:
        return self.number("EMCMOT", "SERVO_PERIOD", 1_000_000.0) * 1e-9

    def limits(self) -> dict[str, tuple[float, float]]:
        out = {}
        for axis in GEOMETRY_AXES:
            lo = self.number(f"AXIS_{axis}", "MIN_LIMIT", -1e9)
            hi = self.number(f"AXIS_{axis}", "MAX_LIMIT", 1e9)
            out[axis] = (lo, hi)
        return out

    def max_velocity(self) -> float:
        """mm/s: the slowest axis's maximum (a rapid along any direction reaches it)."""
        speeds = [self.number(f"AXIS_{a}", "MAX_VELOCITY", 0.0) for a in GEOMETRY_AXES]
        traj = self.number("TRAJ", "MAX_LINEAR_VELOCITY", 0.0)
        known = [v for v in (*speeds, traj) if v > 0.0]
        return min(known) if known else 10.0

    def max_acceleration(self) -> float:
        """mm/s²: the smallest axis acceleration (braking along any direction is at least this)."""
        accels = [self.number(f"AXIS_{a}", "MAX_ACCELERATION", 0.0) for a in GEOMETRY_AXES]
        known = [a for a in accels if a > 0.0]
        return min(known) if known else 100.0

    def latch_pins(self) -> tuple[dict[str, str], str | None]:
        pins = {a: self.get("HMI", f"PROBE_LATCH_{a}") for a in GEOMETRY_AXES}
        named = {a: p for a, p in pins.items() if p}
        if named and len(named) != len(GEOMETRY_AXES):
            raise LinuxCncStartError(f"--linuxcnc-ini {self.path.name}: [HMI] PROBE_LATCH_X, _Y and _Z name the "
                                     "latch pins of all three axes, or none")
        return named, self.get("HMI", "PROBE_LATCH_VALID")

    def file(self, section: str, key: str) -> Path | None:
        """A file the INI names, relative to the INI's folder (as LinuxCNC resolves it)."""
        value = self.get(section, key)
        if not value:
            return None
        path = Path(value).expanduser()
        return path if path.is_absolute() else self.path.parent / path

    def headless_copy(self) -> Path:
        """The INI with ``[DISPLAY] DISPLAY = dummy``, next to it; nothing else changed."""
        lines, section, done = [], None, False
        for line in self.text.splitlines():
            header = _SECTION.match(line)
            if header:
                if section == "DISPLAY" and not done:
                    lines.append("DISPLAY = dummy")
                    done = True
                section = header.group(1).strip()
            entry = _ENTRY.match(line)
            if section == "DISPLAY" and entry and entry.group(1) == "DISPLAY" \
                    and not line.lstrip().startswith(("#", ";")):
                if not done:
                    lines.append("DISPLAY = dummy")
                    done = True
                continue
            lines.append(line)
        if not done:
            lines += ["[DISPLAY]", "DISPLAY = dummy"] if section != "DISPLAY" else ["DISPLAY = dummy"]
        target = self.path.parent / f"{HEADLESS_PREFIX}{self.path.stem}{HEADLESS_SUFFIX}"
        try:
            target.write_text("\n".join(lines) + "\n", encoding="utf-8")
        except OSError as exc:
            raise LinuxCncStartError(f"--linuxcnc-ini: cannot write the headless copy {target.name} next to the INI "
                                     f"({exc.strerror})") from None
        return target

    def scenario(self, base: Scenario) -> Scenario:
        """``base`` (the HMI's probe number and nominal data) with this machine's limits, speeds and
        braking: what the adapter checks targets and timeouts against. Its part is never used."""
        machine = base.machine.model_copy(update={
            "limits": self.limits(), "rapid": self.max_velocity() * 60.0,
            "decel": self.max_acceleration() / 1000.0, "latency_s": 0.0, "rotary_table": None, "kinematics": None})
        return base.model_copy(update={"machine": machine, "rotary_axes": {}, "start": None})

"""What the SHDR adapter reports (docs/opcua.md "MTConnect"): the HMI's machine status and stored
zero offsets as MTConnect data items, keyed by the ids of docs/mtconnect-device.xml.

SHDR (MTConnect Part 1, adapter protocol): ``<timestamp>|<id>|<value>|<id>|<value>...``; a
condition takes its own line ``<timestamp>|<id>|<LEVEL>|<native code>|<severity>|<qualifier>|<text>``
and so does a table ``<timestamp>|<id>|<key>={<k>=<v> ...} ...``.
"""

from __future__ import annotations

from datetime import UTC, datetime

UNAVAILABLE = "UNAVAILABLE"
# ControllerMode and Execution (MTConnect Part 2, §Events) from the HMI's mode and program state
CONTROLLER_MODE = {"JOG": "MANUAL", "MDA": "MANUAL_DATA_INPUT", "AUTO": "AUTOMATIC"}
EXECUTION = {"active": "ACTIVE", "interrupted": "INTERRUPTED", "reset": "READY"}
SYSTEM = "system"          # the controller's system condition: one FAULT per active alarm


def timestamp(now: datetime | None = None) -> str:
    now = now or datetime.now(UTC)
    return now.strftime("%Y-%m-%dT%H:%M:%S.") + f"{now.microsecond // 1000:03d}Z"


def clean(text: str) -> str:
    """A value may not hold the field separator nor a line break."""
    return str(text).replace("|", "/").replace("\n", " ").replace("\r", " ")


def number(value: float) -> str:
    return f"{float(value):.4f}"


def samples(status: dict) -> dict[str, str]:
    """The one-line data items: ``avail``, ``mode``, ``execution``, ``<axis>act`` (machine
    position), ``<axis>wrk`` (work position), ``Fovr``, ``tool``, ``woffset`` (the active frame)."""
    items = {"avail": "AVAILABLE",
             "mode": CONTROLLER_MODE.get(status["mode"] or "", UNAVAILABLE),
             "execution": EXECUTION.get(status["program_state"], UNAVAILABLE)}
    for axis, value in status["mcs"].items():
        items[f"{axis}act"] = number(value)
    for axis, value in status["wcs"].items():
        items[f"{axis}wrk"] = number(value)
    items["Fovr"] = number(status["feed_override"])
    items["tool"] = str(status["tool"]) if status["tool"] is not None else UNAVAILABLE
    items["woffset"] = clean(status["active_offset"])
    return items


def offsets_table(offsets: dict[str, dict]) -> str:
    """The ``woffsets`` table (WORK_OFFSET, representation TABLE): each stored frame's translation
    (coarse + fine, as the NC adds them) and rotation, e.g. ``G54={X=250.1 Y=-150.5 Z=-120 C=0}``."""
    entries = []
    for name, frame in offsets.items():
        trans, fine, rot = (frame.get(k) or {} for k in ("trans", "fine", "rot"))
        cells = [f"{axis}={number(value + fine.get(axis, 0.0))}" for axis, value in trans.items()]
        cells += [f"{axis}ROT={number(value)}" for axis, value in rot.items() if value]
        entries.append(f"{clean(name).replace(' ', '_')}={{{' '.join(cells)}}}")
    return " ".join(entries)


def _fault(code: int, text: str) -> str:
    """A FAULT with the alarm number as native code. The qualifier stays empty: MTConnect allows
    only HIGH or LOW there (a value above or below its limits), which an NC alarm is not; the
    native severity stays empty too (the control's alarms carry none)."""
    return f"{SYSTEM}|FAULT|{code}|||{clean(text)}"


def conditions(active: set[tuple[int, str]], before: set[tuple[int, str]] | None) -> list[str]:
    """Condition lines (without timestamp) for the change from ``before`` to ``active``: a FAULT
    for each new alarm, NORMAL with its code for each gone one, a plain NORMAL when none is left."""
    if before is None:                     # a new agent: the whole state
        lines = [_fault(code, text) for code, text in sorted(active)]
        return lines or [f"{SYSTEM}|NORMAL||||"]
    lines = [_fault(code, text) for code, text in sorted(active - before)]
    gone = sorted(before - active)
    if gone and not active:
        lines.append(f"{SYSTEM}|NORMAL||||")
    else:
        lines += [f"{SYSTEM}|NORMAL|{code}|||" for code, _text in gone]
    return lines

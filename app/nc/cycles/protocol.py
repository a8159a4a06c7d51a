"""Logging measuring results: CYCLE100, 101, 105, 106, 113, 118 (manual §7.1, spec measuring-math §15).

    CYCLE100        logging on: deletes a file of the name _PROTNAME[1] (and its continuation
                    files), writes the header
    CYCLE101        logging off
    CYCLE105(PAR1)  0: the header, 1: a value block (the cycle line "CYCLE978 , _MVAR , 100"
                    unless _CBIT[6]=1, then _PROTFORM[4] lines from _PROTVAL[2..5])
    CYCLE106(PAR1)  1: a new page (header), 2: the file and page checks (continuation file, page)
    CYCLE113(PAR1, PAR2)   1: the date "yy/mm/dd", 2: the time "hh:mm:ss" into PAR2
    CYCLE118(PAR1, PAR2, PAR3[, PAR4, PAR5])   a real with PAR2 decimals into PAR3; with PAR4 > 1
                    the R parameters R[PAR5] .. into _TXT[0..PAR4-1]

While logging is on, every measuring cycle writes its value block after it ends (the manual:
the measuring cycles call CYCLE105 themselves).

The file: a program of the name _PROTNAME[1] in the program store (the "directory of the calling
program", the program screen lists it); header per measuring-math §15: 1 ``Date: yy/mm/dd  Time:
hh:mm:ss  Page: n``, 2 empty, 3 ``Program: <_PROTNAME[0]>``, 4 empty, 5–7 _HEADLINE[0..2]
(_PROTFORM[3] lines; _CBIT[11]=1: _HEADLINE[0..] only), 8 dashes, 9 _PROTVAL[0], 10
_PROTVAL[1], 11 dashes (dashes: _PROTFORM[1] characters). Columns: each item of a value line
left-aligned in the column width _PROTFORM[5] (0: the widths of the fields of _PROTVAL[0]),
joined by " <_PROTSYM[0]> "; a value wider than its column wins (warning 62309). A value block
of a cycle that ended with a tolerance warning (_OVI[9] = 62303..62306) ends with _PROTSYM[1].
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field
from datetime import datetime
from typing import Protocol

from app.nc.interpreter import CycleContext
from app.nc.variables import VariableError
from engine import alarms

LEN_PROTOCOL_FILE = 100_000       # MD 11420 LEN_PROTOCOL_FILE of this control: characters per file
MAX_CONTINUATIONS = 9             # manual §7.1.2: at most 9 continuation files
MAX_LINE = 200                    # _PROTFORM[1] at most 200 characters (62310)
TOLERANCE_WARNINGS = (62303, 62304, 62305, 62306)
NAME = re.compile(r"^([A-Za-z]{2}|[A-Za-z]_)[A-Za-z0-9_]*$")
MA_AXES = {1: "X", 2: "Y", 3: "Z"}
_ITEM_REF = re.compile(r"^(?:(_OVR|_OVI|_TXT|R)\[(\d+)\]|R(\d+))$", re.IGNORECASE)


class ProtocolFiles(Protocol):
    """Where protocol files live (implemented by app.services.protocols)."""

    def write(self, name: str, text: str, program: str | None) -> None:
        """Create or replace the file ``name``."""

    def delete(self, name: str) -> None:
        """Remove the file ``name`` if it exists."""


class ProtocolHost(Protocol):
    protocol_files: ProtocolFiles


@dataclass
class _State:
    on: bool = False
    base: str = ""
    name: str = ""
    program: str = ""
    continuations: int = 0
    lines: list[str] = field(default_factory=list)
    page: int = 1
    page_lines: int = 0
    last_cycle: tuple[str, int] | None = None       # (name, _MVAR) of the last measuring cycle


def fixed(value: float, decimals: int) -> str:
    """CYCLE118: ``value`` with ``decimals`` places ("-0.013", "31.83")."""
    text = f"{float(value):.{max(0, int(decimals))}f}"
    return "0" + text[2:] if text.startswith("-0") and float(text) == 0.0 else text


class ProtocolLog:
    """The logging state of one channel and its cycles."""

    def __init__(self, host: ProtocolHost, now: Callable[[], datetime] = datetime.now):
        self._host = host
        self._now = now
        self.state = _State()

    def handlers(self) -> dict[str, Callable[[CycleContext], None]]:
        return {"CYCLE100": self.cycle100, "CYCLE101": self.cycle101, "CYCLE105": self.cycle105,
                "CYCLE106": self.cycle106, "CYCLE113": self.cycle113, "CYCLE118": self.cycle118}

    def logged(self, name: str, handler: Callable[[CycleContext], None]) -> Callable[[CycleContext], None]:
        """A measuring cycle that writes its value block while logging is on."""
        def run(ctx: CycleContext) -> None:
            self.state.last_cycle = (name, _int(ctx.variables.get("_MVAR")))
            handler(ctx)
            if self.state.on:
                self._value_block(ctx)
        return run

    # --- the cycles -------------------------------------------------------------------------------
    def cycle100(self, ctx: CycleContext) -> None:
        v = ctx.variables
        base = str(v.get("_PROTNAME", (1,))).strip()
        if not base:
            raise ctx.alarm(alarms.PROTOCOL_NO_FILE, "CYCLE100: no log file name in _PROTNAME[1]")
        if not NAME.match(base) or len(base) > 32:
            raise ctx.alarm(alarms.PROTOCOL_FILE_TYPE, f"CYCLE100: {base!r} is not a file name (letters, digits, _; "
                            "starting with two letters or a letter and _)")
        files = self._host.protocol_files
        for k in range(MAX_CONTINUATIONS + 1):            # the old file and its continuation files
            files.delete(base + "_" * k)
        s = self.state
        s.on, s.base, s.name, s.continuations = True, base, base, 0
        s.program = str(v.get("_PROTNAME", (0,))).strip()
        s.lines, s.page, s.page_lines = [], _int(v.get("_PROTFORM", (2,))) or 1, 0
        self._check_format(ctx)
        self._header(ctx)
        self._flush()

    def cycle101(self, ctx: CycleContext) -> None:
        if self.state.on:
            self._flush()
        self.state.on = False

    def cycle105(self, ctx: CycleContext) -> None:
        part = _int(ctx.args[0]) if ctx.args else 1
        self._need_on(ctx, "CYCLE105")
        if part == 0:
            self._header(ctx)
        elif part == 1:
            self._value_block(ctx)
        else:
            raise ctx.alarm(alarms.PROTOCOL_JOB, f"CYCLE105({part}): 0 (header) or 1 (value block)")
        self._flush()

    def cycle106(self, ctx: CycleContext) -> None:
        part = _int(ctx.args[0]) if ctx.args else 0
        self._need_on(ctx, "CYCLE106")
        if part == 1:
            self._new_page(ctx)
        elif part == 2:
            self._make_room(ctx, 0)
        else:
            raise ctx.alarm(alarms.PROTOCOL_JOB, f"CYCLE106({part}): 1 (new page) or 2 (file and page check)")
        self._flush()

    def cycle113(self, ctx: CycleContext) -> None:
        which = _int(ctx.args[0]) if ctx.args else 0
        if which not in (1, 2) or len(ctx.args) < 2:
            raise ctx.alarm(alarms.PROTOCOL_JOB, "CYCLE113(1|2, text variable): 1 date, 2 time")
        now = self._now()
        ctx.set_argument(1, now.strftime("%y/%m/%d") if which == 1 else now.strftime("%H:%M:%S"))

    def cycle118(self, ctx: CycleContext) -> None:
        args = ctx.args
        if len(args) < 3:
            raise ctx.alarm(alarms.NC_SYNTAX, "CYCLE118(value, decimals, text variable[, count, first R])")
        decimals = _int(args[1])
        count = _int(args[3]) if len(args) > 3 and args[3] else 1
        if count > 10 or count < 1:
            raise ctx.alarm(alarms.PROTOCOL_COUNT, f"CYCLE118: {count} values (at most 10)")
        if count == 1:
            ctx.set_argument(2, fixed(_number(ctx, args[0]), decimals))
            return
        first = _int(args[4]) if len(args) > 4 else 0
        text = ""
        for i in range(count):
            text = fixed(float(ctx.variables.get("R", (first + i,))), decimals)
            ctx.variables.set("_TXT", text, (i,))
        ctx.set_argument(2, text)

    # --- writing ------------------------------------------------------------------------------------
    def _need_on(self, ctx: CycleContext, name: str) -> None:
        if not self.state.on:
            raise ctx.alarm(alarms.PROTOCOL_JOB, f"{name}: logging is off (switch it on with CYCLE100)")

    def _format(self, ctx: CycleContext) -> tuple[int, int, int, int, int, int]:
        v = ctx.variables
        return tuple(_int(v.get("_PROTFORM", (i,))) for i in range(6))  # type: ignore[return-value]

    def _check_format(self, ctx: CycleContext) -> None:
        width = self._format(ctx)[1]
        if width > MAX_LINE:
            ctx.warn(alarms.PROTOCOL_LINE_LIMIT, f"_PROTFORM[1]={width}: at most {MAX_LINE} characters per line")

    def _line_width(self, ctx: CycleContext) -> int:
        return min(max(self._format(ctx)[1], 1), MAX_LINE)

    def _header_lines(self, ctx: CycleContext) -> list[str]:
        v = ctx.variables
        now = self._now()
        user_lines = max(0, min(10, self._format(ctx)[3]))
        headlines = [str(v.get("_HEADLINE", (i,))) for i in range(user_lines)]
        dashes = "-" * self._line_width(ctx)
        if _int(v.get("_CBIT", (11,))):          # a user header: _HEADLINE only
            return [*headlines, dashes]
        return [f"Date: {now:%y/%m/%d}  Time: {now:%H:%M:%S}  Page: {self.state.page}", "",
                f"Program: {self.state.program}", "", *headlines, dashes,
                str(v.get("_PROTVAL", (0,))), str(v.get("_PROTVAL", (1,))), dashes]

    def _header(self, ctx: CycleContext) -> None:
        lines = self._header_lines(ctx)
        self._make_room(ctx, len(lines), header=True)
        self._append(lines)

    def _new_page(self, ctx: CycleContext) -> None:
        if self.state.lines:
            self.state.page += 1
        self.state.page_lines = 0
        self._append(self._header_lines(ctx))

    def _make_room(self, ctx: CycleContext, count: int, header: bool = False) -> None:
        """Continuation file when the file would grow beyond LEN_PROTOCOL_FILE; a new page
        (header again) when the page would exceed _PROTFORM[0] lines (0: one header only)."""
        s = self.state
        if len("\n".join(s.lines)) >= LEN_PROTOCOL_FILE:
            if s.continuations >= MAX_CONTINUATIONS:
                s.on = False
                raise ctx.alarm(alarms.PROTOCOL_NEW_NAME, "please give a new log name: "
                                f"{s.base} and its {MAX_CONTINUATIONS} continuation files are full")
            self._flush()
            s.continuations += 1
            s.name = s.base + "_" * s.continuations
            if len(s.name) > 32:
                raise ctx.alarm(alarms.PROTOCOL_FILE_TYPE, f"{s.name}: a continuation name longer than 32 characters")
            s.lines, s.page_lines = [], 0
            s.page += 1
            ctx.warn(alarms.PROTOCOL_CONTINUED, f"new log file created: {s.name}")
            if not header:
                self._append(self._header_lines(ctx))
            return
        per_page = self._format(ctx)[0]
        if not header and per_page > 0 and s.page_lines + count > per_page:
            self._new_page(ctx)

    def _value_block(self, ctx: CycleContext) -> None:
        v = ctx.variables
        sep = str(v.get("_PROTSYM", (0,))) or ";"
        widths = self._widths(ctx)
        lines = []
        with_cycle = not _int(v.get("_CBIT", (6,))) and self.state.last_cycle is not None
        if with_cycle and self.state.last_cycle is not None:
            cycle, variant = self.state.last_cycle
            lines.append(self._join(ctx, [cycle, "_MVAR", str(variant)], widths, sep))
        count = max(1, min(4, self._format(ctx)[4]))
        for i in range(count):
            spec = str(v.get("_PROTVAL", (2 + i,)))
            items = [self._item(ctx, item) for item in spec.split(",")]
            lines.append(self._join(ctx, items, widths, sep))
        if lines and _int(v.get("_OVI", (9,))) in TOLERANCE_WARNINGS:
            lines[1 if with_cycle else 0] += " " + (str(v.get("_PROTSYM", (1,))) or "#")
        self._make_room(ctx, len(lines))
        self._append(lines)

    def _widths(self, ctx: CycleContext) -> list[int] | int:
        width = self._format(ctx)[5]
        if width > 0:
            return width
        titles = str(ctx.variables.get("_PROTVAL", (0,)))
        if not titles.strip():
            ctx.warn(alarms.PROTOCOL_VARIABLE_WIDTH, "variable column width without titles in _PROTVAL[0]: 12")
            return 12
        return [len(t) for t in titles.split(",")]

    def _join(self, ctx: CycleContext, items: list[str], widths: list[int] | int, sep: str) -> str:
        cells = []
        for k, text in enumerate(items):
            w = widths if isinstance(widths, int) else (widths[k] if k < len(widths) else 12)
            if len(text) > w:
                ctx.warn(alarms.PROTOCOL_COLUMN_WIDTH, f"{text!r} is wider than its column ({w})")
            cells.append(text.ljust(w))
        line = f" {sep} ".join(cells).rstrip()
        if len(line) > self._line_width(ctx):
            ctx.warn(alarms.PROTOCOL_LINE_LONG, f"a line of {len(line)} characters (_PROTFORM[1])")
        return line

    def _item(self, ctx: CycleContext, item: str) -> str:
        """One item of _PROTVAL[2..5]: _OVR[n], _OVI[n], R<n>, _TXT[n], _TIME, _AXIS, _AXIS1..3, text."""
        v = ctx.variables
        text = item.strip()
        upper = text.upper()
        digits = _int(v.get("_DIGIT"))
        if upper == "_TIME":
            return f"{self._now():%H:%M:%S}"
        if upper == "_AXIS":
            return MA_AXES.get(_int(v.get("_MA")), "?")
        if upper in ("_AXIS1", "_AXIS2", "_AXIS3"):
            return ctx.plane_axes[int(upper[-1]) - 1]
        ref = _ITEM_REF.match(upper)
        if ref:
            name, index = (ref.group(1), int(ref.group(2))) if ref.group(1) else ("R", int(ref.group(3)))
            try:
                value = v.get(name, (index,))
            except VariableError:       # not defined, or no such element
                raise ctx.alarm(alarms.PROTOCOL_VALUE, f"{text}: this variable cannot be logged") from None
            if name == "_TXT":
                return str(value)
            if name == "_OVI":
                return str(_int(value))
            return fixed(float(value), digits)
        if text.startswith(("_", "$")):
            raise ctx.alarm(alarms.PROTOCOL_VALUE, f"{text}: this variable cannot be logged")
        return text

    def _append(self, lines: list[str]) -> None:
        self.state.lines.extend(lines)
        self.state.page_lines += len(lines)

    def _flush(self) -> None:
        s = self.state
        self._host.protocol_files.write(s.name, "\n".join(s.lines) + "\n", s.program or None)


def _int(value) -> int:
    if isinstance(value, str):
        return int(float(value)) if value.strip() else 0
    return int(value)


def _number(ctx: CycleContext, value) -> float:
    if isinstance(value, str):
        raise ctx.alarm(alarms.NC_VALUE_RANGE, "CYCLE118: the value to format must be a number")
    return float(value)

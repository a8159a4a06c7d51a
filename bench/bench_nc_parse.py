"""How long the NC takes to read a 200 KB part program (issue 24 item 5, target <= 1 s):
python bench/bench_nc_parse.py

Four 200 KB programs: positioning blocks, expression-heavy blocks with labels and jumps,
measuring-cycle calls, and a jump back to the start in every block. Each is parsed alone (``parse_program``) and loaded as the channel loads
it (``Interpreter.load``: parse + the names checked against the variables and cycles), best of
three in wall time, and the parse's CPU time (on a loaded machine the wall time grows with the
load); and loading the same text again (the channel keeps its last two readings: the check when
a program is stored, the load when it is selected, NC Start after its end). The largest program
the API accepts (1 MiB) is timed too.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from app.nc import Interpreter, Variables  # noqa: E402
from app.nc.parser import MAX_PROGRAM_BYTES, forget_programs, parse_program  # noqa: E402
from tests.nc.nc_runtimes import FakeRuntime  # noqa: E402

SIZE = 200_000


def _fill(block, size: int = SIZE) -> str:
    lines: list[str] = []
    total = 0
    i = 0
    while total < size:
        i += 1
        line = block(i)
        lines.append(line)
        total += len(line) + 1
    return "\n".join(lines)[:size]


def _positioning(i: int) -> str:
    return f"N{i * 10} G1 X{i % 100}.5 Y-{i % 37}.25 Z=R1+{i % 7}*2 F500 ; point {i}"


def _expressions(i: int) -> str:
    if i % 50 == 0:
        return f"LBL{i}: IF R2 > {i} GOTOF END"
    return f"R{i % 90 + 1}=(R1*{i % 13}+SIN(R2*{i % 9}))/({i % 5}+1.5) - ABS(R3-{i}) * SQRT({i % 17}+1)"


def _cycles(i: int) -> str:
    return (f"N{i * 10} _MVAR=101 _SETVAL={20 + i % 5} _KNUM=1 _FA=5 _TSA=0.5 _PRNUM=1\n"
            f"N{i * 10 + 5} CYCLE977")


def _jumps(i: int) -> str:
    return f"N{i} IF R1 > {i} GOTOB START" if i > 1 else "START: R1=0"


def _program(kind) -> str:
    text = _fill(kind).rsplit("\n", 1)[0]          # no block cut in half
    return text + ("\nEND: M30" if kind is _expressions else "\nM30")


def _best(call, repeats: int = 3) -> float:
    times = []
    for _ in range(repeats):
        forget_programs()                   # the reading itself, not the channel's cache of the last texts
        t0 = time.perf_counter()
        call()
        times.append(time.perf_counter() - t0)
    return min(times)


def _best_cpu(call, repeats: int = 3) -> float:
    """The process's CPU time: what the parse costs when other programs share the cores (the
    wall time then grows with the machine's load, not with the parser)."""
    times = []
    for _ in range(repeats):
        forget_programs()
        t0 = time.process_time()
        call()
        times.append(time.process_time() - t0)
    return min(times)


def main() -> None:
    cycles = {"CYCLE977": lambda ctx: None}
    for kind in (_positioning, _expressions, _cycles, _jumps):
        text = _program(kind)
        blocks = text.count("\n") + 1
        parse = _best(lambda text=text: parse_program(text))
        interp = Interpreter(FakeRuntime(), Variables(axes=("X", "Y", "Z")), cycles)
        load = _best(lambda text=text, interp=interp: interp.load(text))
        cpu = _best_cpu(lambda text=text: parse_program(text))
        t0 = time.perf_counter()
        interp.load(text)                   # read before: the same text again (check, select, NC Start)
        again = time.perf_counter() - t0
        print(f"{kind.__name__[1:]:12s} {len(text) / 1000:6.0f} KB {blocks:6d} blocks: parse {parse:.3f} s, "
              f"load {load:.3f} s, parse CPU {cpu:.3f} s, load again {again:.3f} s  (target <= 1 s)")
    big = _fill(_positioning, MAX_PROGRAM_BYTES - 10).rsplit("\n", 1)[0] + "\nM30"
    print(f"largest program accepted ({len(big) / 1024:.0f} KiB): parse {_best(lambda: parse_program(big), 1):.3f} s")


if __name__ == "__main__":
    main()

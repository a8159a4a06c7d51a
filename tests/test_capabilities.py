"""Optional machine interfaces are asked with ``isinstance`` against the Protocols of
app/machine/protocol.py (Lathe, SwivelHead, ProtectedSpace, FrameCapacity, OwnConfiguration,
KinematicData, SimulatorControl), never probed with ``getattr(machine, "…")`` (issue 27 item 2)."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PROBE = re.compile(r"getattr\(\s*[\w.]*machine\b")


def test_the_pattern_finds_a_probe():
    assert PROBE.search('lathe = getattr(machine, "kind", "mill") == "lathe"')
    assert PROBE.search('holds = getattr(self._machine, "holds", None)')
    assert not PROBE.search('isinstance(self._machine, FrameCapacity)')


def test_no_module_probes_the_machine_with_getattr():
    found = [f"{path.relative_to(ROOT)}:{n}: {line.strip()}"
             for path in sorted((ROOT / "app").rglob("*.py"))
             for n, line in enumerate(path.read_text().splitlines(), 1) if PROBE.search(line)]
    assert not found, "ask the capability Protocol with isinstance instead:\n" + "\n".join(found)

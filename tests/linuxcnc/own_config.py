"""The machine's own LinuxCNC configuration for the tests (issue 34): LinuxCNC's shipped sample
``sim/axis/axis_mm.ini`` copied with its tool table, plus a probe made of LinuxCNC's standard HAL
components: ``wcomp`` switches ``motion.probe-input`` while the machine Z (``joint.2.pos-fb``) is
below a plane; optionally a ``debounce`` stage, or contact bounce (``oneshot``, ``siggen`` square wave, ``and2``, ``not``):
the input opens and closes for some ms after each contact."""

from __future__ import annotations

import shutil
from pathlib import Path

SAMPLE = Path("/usr/share/doc/linuxcnc/examples/sample-configs/sim")
PLANE_Z = -20.0               # mm, machine Z at which the probe switches (joint.2.pos-fb < PLANE_Z)

PROBE_HAL = """# a probe on a plane from LinuxCNC's standard components (the tests, issue 34)
loadrt wcomp names=probe_plane
addf probe_plane servo-thread
net z-machine joint.2.pos-fb => probe_plane.in
setp probe_plane.min -1000
setp probe_plane.max {plane!r}
"""

PLAIN = "net probe-in probe_plane.out => motion.probe-input\n"

DEBOUNCED = """loadrt debounce cfg=1
addf debounce.0 servo-thread
setp debounce.0.delay {cycles}
net probe-raw probe_plane.out => debounce.0.0.in
net probe-in debounce.0.0.out => motion.probe-input
"""

CHATTER = """# contact bounce: for {burst_ms:g} ms after the contact closes it opens and closes at {hz:g} Hz
loadrt oneshot names=bounce_burst
loadrt siggen names=chatter
loadrt and2 names=chatter_and,probe_and
loadrt not names=chatter_not
addf bounce_burst servo-thread
addf chatter.update servo-thread
addf chatter_and servo-thread
addf chatter_not servo-thread
addf probe_and servo-thread
setp bounce_burst.width {burst_s!r}
setp bounce_burst.retriggerable 0
setp chatter.frequency {hz!r}
net contact probe_plane.out => bounce_burst.in probe_and.in1
net bouncing bounce_burst.out => chatter_and.in0
net chatter-clock chatter.clock => chatter_and.in1
net chatter-open chatter_and.out => chatter_not.in
net chatter-closed chatter_not.out => probe_and.in0
net probe-in probe_and.out => motion.probe-input
"""


def own_config(folder: Path, probe: str = "plain", plane: float = PLANE_Z, debounce_cycles: int = 3,
               burst_s: float = 0.008, chatter_hz: float = 500.0) -> Path:
    """The sample configuration with the probe in ``folder``; returns its INI."""
    folder.mkdir(parents=True, exist_ok=True)
    shutil.copy(SAMPLE / "axis" / "axis_mm.ini", folder / "axis_mm.ini")
    shutil.copy(SAMPLE / "sim_mm.tbl", folder / "sim_mm.tbl")
    hal = PROBE_HAL.format(plane=plane)
    if probe == "plain":
        hal += PLAIN
    elif probe == "debounce":
        hal += DEBOUNCED.format(cycles=int(debounce_cycles))
    elif probe == "chatter":
        hal += CHATTER.format(burst_ms=burst_s * 1000.0, burst_s=burst_s, hz=chatter_hz)
    else:
        raise ValueError(probe)
    (folder / "probe.hal").write_text(hal, encoding="utf-8")
    ini = folder / "axis_mm.ini"
    text = ini.read_text(encoding="utf-8").replace("HALFILE = simulated_home.hal",
                                                   "HALFILE = simulated_home.hal\nHALFILE = probe.hal")
    ini.write_text(text, encoding="utf-8")
    return ini

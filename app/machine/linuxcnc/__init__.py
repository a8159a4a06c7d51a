"""LinuxCNC behind the Machine Protocol (design.md §9.6): ``python -m app --machine linuxcnc``.

- ``adapter.LinuxCncMachine``: the Protocol over LinuxCNC's python module;
- ``process``: LinuxCNC started headless with the project's configuration, stopped with the HMI;
- ``config``: that configuration (INI, HAL, tool table, var file) generated from the scenario;
- ``modules``: Debian's ``linuxcnc``/``hal`` modules found from any environment;
- ``hal/jogprobe.comp``: the realtime probe comparator with its encoder-like latch.
"""

from __future__ import annotations

from .adapter import LinuxCncMachine
from .modules import available

__all__ = ["LinuxCncMachine", "available"]

"""The machines the HMI can drive, by name: the setting ``machine`` (``HMI_MACHINE``, ``--machine``).

Each entry names a factory ``"module:callable"`` that takes the scenario (design.md §4, the
truth the simulator plays and a real controller's probe input is fed from) and returns a
``Machine`` (protocol.py). The module is imported only when that machine is built, so an
entry whose controller is not installed costs nothing. A controller adds itself with one line
here plus its module, e.g.::

    "linuxcnc": "app.machine.linuxcnc:LinuxCncMachine",

An unknown name is refused with ``UnknownMachine`` listing the known ones.

Lathes (turning.md §10.2): a scenario with ``machine.kind: "lathe"`` is built by the entry of
the same name in ``LATHES`` (``--machine sim`` plays a lathe scenario on the simulated lathe,
a milling scenario on the simulated milling machine); a controller without a lathe entry
refuses a lathe scenario with ``UnknownMachine``.
"""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .lathe_scenario import LatheScenario
    from .protocol import Machine
    from .scenario import Scenario

DEFAULT = "sim"
MACHINES: dict[str, str] = {
    "sim": "app.machine.sim:SimulatedMachine",
    "linuxcnc": "app.machine.linuxcnc:LinuxCncMachine",
}


LATHES: dict[str, str] = {
    "sim": "app.machine.lathe:LatheMachine",
}


class UnknownMachine(ValueError):
    """The setting names no registered machine."""


class MachineUnavailable(UnknownMachine):
    """The machine is registered but cannot be built here: its controller is not installed or
    does not come up. ``python -m app`` prints it as one line (an ``UnknownMachine``)."""


def names() -> tuple[str, ...]:
    return tuple(MACHINES)


def factory(name: str, kind: str = "mill"):
    """The factory registered as ``name`` for machines of ``kind`` ("mill", "lathe"; imported now)."""
    if name not in MACHINES:
        raise UnknownMachine(f"unknown machine {name!r}; known machines: {', '.join(names())}")
    table = LATHES if kind == "lathe" else MACHINES
    if name not in table:
        raise UnknownMachine(f"machine {name!r} cannot play a {kind} scenario; "
                             f"lathes: {', '.join(LATHES) or 'none'}")
    module, _, attribute = table[name].partition(":")
    return getattr(import_module(module), attribute)


def build_machine(name: str, scenario: Scenario | LatheScenario, options: dict | None = None) -> Machine:
    """The machine registered as ``name``, built for ``scenario`` (its ``kind`` picks the table);
    ``options`` are the controller's own keyword arguments (LinuxCNC: ``ini``, ``db_path``)."""
    return factory(name, getattr(scenario, "kind", "mill"))(scenario, **(options or {}))

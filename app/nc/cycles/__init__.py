"""The measuring cycles as NC calls (design.md §9.4, measuring-math §7–measuring-math §14).

    cycles = measuring_cycles(host)                 # {"CYCLE977": handler, ...}
    Interpreter(runtime, variables, cycles=cycles)

Each handler reads its parameters from the variable store (SW 6.3 style: set before the call),
runs the JOG task that measures the same feature through the JOG workflow on the environment the
``host`` (``base.CycleHost``, implemented by app.services.nc) gives it, and writes ``_OVR``/``_OVI``.
"""

from __future__ import annotations

from app.nc.cycles import calibration, kinematics, lathe, protocol, sphere, workpiece
from app.nc.cycles.base import CycleHost, NcMeasuring
from app.nc.cycles.hooks import hooked

CYCLE_NAMES = ("CYCLE976", "CYCLE977", "CYCLE978", "CYCLE979", "CYCLE998", "CYCLE961", "CYCLE997", "CYCLE971")
# logging measuring results (manual §7.1): registered when the host keeps protocol files
# the lathe's (manual ch. 6): registered everywhere, refused by name on the milling machine (app.nc.scope)
LATHE_CYCLE_NAMES = lathe.LATHE_CYCLE_NAMES
PROTOCOL_CYCLES = ("CYCLE100", "CYCLE101", "CYCLE105", "CYCLE106", "CYCLE113", "CYCLE118")


def measuring_cycles(host: CycleHost) -> dict:
    handlers = {**workpiece.handlers(host), **sphere.handlers(host), **calibration.handlers(host),
                **lathe.handlers(host)}
    if hasattr(host, "user_hook"):             # CYCLE198 / CYCLE199 around every measuring cycle (manual §3.2)
        handlers = {name: hooked(host, handler) for name, handler in handlers.items()}  # type: ignore[arg-type]
    product = kinematics.handlers(host)     # CYCLE996-like (design.md §10.6): a product cycle, no form
    if getattr(host, "protocol_files", None) is None:
        return {**{name: handlers[name] for name in (*CYCLE_NAMES, *LATHE_CYCLE_NAMES)}, **product}
    log = protocol.ProtocolLog(host)        # type: ignore[arg-type]
    return {**{name: log.logged(name, handlers[name]) for name in (*CYCLE_NAMES, *LATHE_CYCLE_NAMES)},
            **log.handlers(), **product}


__all__ = ["CYCLE_NAMES", "LATHE_CYCLE_NAMES", "PROTOCOL_CYCLES", "CycleHost", "NcMeasuring", "measuring_cycles"]

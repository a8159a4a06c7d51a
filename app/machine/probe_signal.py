"""What the probes tell the control besides a switch during MEAS (design.md §10.4): armed, deflected,
battery, for the workpiece probe and the tool probe alike.

A cable probe is always ready and has no battery (``armed``/``battery`` None); a radio or optical
probe (scenario ``probe.radio`` / ``tool_probe.radio``, ``{"battery": 0..1}``) is armed while it
is switched on and its battery is not flat. Deflected is the stylus pushed out of its seat: by the
operator's hand (``POST /api/sim/probe``) or by a solid the ball (the cutter, on the tool probe)
presses into; the facade asks its contact object for the latter.

Decisions (where the spec leaves room):
- A radio workpiece probe is armed only while it is the tool in the spindle (it switches on with
  the spindle, as the M-function of a real one does) and its battery is above 0.
- A hand deflection stays until it is released by hand; a deflection by a solid ends when the
  axes leave the contact.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from pydantic import BaseModel, ConfigDict, Field

from .protocol import ProbeState

WORKPIECE = "workpiece"
TOOL = "tool"
PROBES = (WORKPIECE, TOOL)


class Radio(BaseModel):
    """Scenario ``probe.radio`` / ``tool_probe.radio``: a radio or optical probe and its battery."""

    model_config = ConfigDict(extra="forbid")
    battery: float = Field(1.0, ge=0.0, le=1.0, allow_inf_nan=False)     # charge 0..1


@dataclass(frozen=True)
class _Signal:
    radio: bool                    # a radio/optical probe (has a battery and is armed); False: cable
    battery: float | None          # 0..1, None for a cable probe
    switched_on: bool = True       # the simulator's "switch off" (radio probes)
    by_hand: bool = False          # deflected by the operator's hand


class ProbeSignals:
    """The hand-made part of both probes' state; the facade holds it under its lock."""

    def __init__(self, workpiece: Radio | None, tool: Radio | None, has_tool_probe: bool) -> None:
        self._signals = {which: _Signal(radio is not None, None if radio is None else radio.battery)
                         for which, radio in ((WORKPIECE, workpiece), (TOOL, tool))}
        self._has_tool_probe = has_tool_probe

    def has(self, which: str) -> bool:
        return which == WORKPIECE or self._has_tool_probe

    def set(self, which: str, deflect: bool | None = None, battery: float | None = None,
            armed: bool | None = None) -> None:
        """The operator's hand (``deflect``), a battery change, switching a radio probe on/off.

        Bad values raise ValueError naming the field; nothing changes then."""
        if which not in PROBES:
            raise ValueError(f"probe: {which!r} is not one of {', '.join(PROBES)}")
        if not self.has(which):
            raise ValueError("probe: this machine has no tool probe")
        signal = self._signals[which]
        if deflect is not None and not isinstance(deflect, bool):
            raise ValueError("deflect: must be true or false")
        if armed is not None and not isinstance(armed, bool):
            raise ValueError("armed: must be true or false")
        if battery is not None:
            if isinstance(battery, bool) or not isinstance(battery, int | float) or not math.isfinite(battery) \
                    or not 0.0 <= battery <= 1.0:
                raise ValueError("battery: a charge 0..1")
            if not signal.radio:
                raise ValueError("battery: a cable probe has no battery (scenario probe.radio)")
        if armed is not None and not signal.radio:
            raise ValueError("armed: a cable probe is always armed (scenario probe.radio)")
        self._signals[which] = replace(
            signal, by_hand=signal.by_hand if deflect is None else deflect,
            battery=signal.battery if battery is None else float(battery),
            switched_on=signal.switched_on if armed is None else armed)

    def state(self, which: str, present: bool, touching: bool) -> ProbeState:
        """``which`` probe's state; ``present``: the probe is where it works (the workpiece probe in
        the spindle), ``touching``: a solid deflects it now."""
        signal = self._signals[which]
        armed = None
        if signal.radio:
            armed = present and signal.switched_on and (signal.battery or 0.0) > 0.0
        return ProbeState(in_spindle=present, armed=armed, deflected=signal.by_hand or touching,
                          battery=signal.battery)

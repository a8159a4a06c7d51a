"""Machine alarms as OPC UA events (design.md §9.7): an alarm that appears in the machine status
raises an ``HmiAlarmEventType`` event (``AlarmCode``, ``Active`` true, severity 700), one that goes
(Reset) another with ``Active`` false (severity 100). Emitted by ``JogMeasure/Machine`` and by the
``Server`` object, where generic clients subscribe."""

from __future__ import annotations

from asyncua import Node, Server, ua

EVENT_TYPE = "HmiAlarmEventType"
RAISED_SEVERITY, CLEARED_SEVERITY = 700, 100


class AlarmEvents:
    def __init__(self):
        self._generators = []
        self._active: set[tuple[int, str]] | None = None     # None: not yet seen (no events for the start state)

    async def setup(self, server: Server, idx: int, machine: Node) -> None:
        etype = await server.create_custom_event_type(
            idx, EVENT_TYPE, ua.ObjectIds.BaseEventType,
            [("AlarmCode", ua.VariantType.Int32), ("Active", ua.VariantType.Boolean)])
        for emitter in (machine, server.nodes.server):
            self._generators.append(await server.get_event_generator(etype, emitter.nodeid))

    async def show(self, active: set[tuple[int, str]]) -> None:
        if self._active is not None:
            for code, text in sorted(active - self._active):
                await self._trigger(code, text, True)
            for code, text in sorted(self._active - active):
                await self._trigger(code, text, False)
        self._active = set(active)

    async def _trigger(self, code: int, text: str, raised: bool) -> None:
        for generator in self._generators:
            event = generator.event
            event.AlarmCode = code
            event.Active = raised
            event.Severity = RAISED_SEVERITY if raised else CLEARED_SEVERITY
            event.SourceName = "CHAN1"
            await generator.trigger(message=f"{code} {text}" if raised else f"{code} {text} (cleared)")

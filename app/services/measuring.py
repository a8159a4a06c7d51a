"""The workflow's environment: measuring context from machine + db, one-transaction commits."""

from __future__ import annotations

from app.machine.protocol import Alarm, Machine
from app.services.machine_service import G500, MachineService, basic_frame_names, frame_chain
from app.services.settings import SettingsService
from app.workflow.service import MeasuringContext
from db import Database
from db.repository import LOG_FIELDS
from engine.frames import Frame
from engine.types import ProbeRecord

PROBE_TYPES = (710,)


def probe_record_from(data: dict | None, tool: dict | None, length_to_tip: bool) -> ProbeRecord:
    """ProbeRecord from the stored _WP record and the tool data of the probe in the spindle."""
    data = data or {}
    ball = 2.0 * float(tool["radius"]) if tool and tool.get("radius") else float(data.get("ball_diameter", 4.0))
    return ProbeRecord(
        number=int(data.get("number", 1)),
        ball_diameter=ball,
        effective_diameter=float(data.get("effective_diameter", 0.0) or 0.0),
        trigger={k: float(v) for k, v in (data.get("trigger") or {}).items()},
        skew=tuple(float(v) for v in (data.get("skew") or (0.0, 0.0))),
        length_to_tip=bool(length_to_tip),
        calibrated_radius=bool(data.get("calibrated_radius", False)),
        calibrated_length=bool(data.get("calibrated_length", False)),
        calibration_feed=data.get("calibration_feed"),
        calibration_override=data.get("calibration_override"),
    )


def probe_number_for(records: list[dict], spindle_tool: int | None, gud_probe_number: int) -> int:
    """The active _WP record follows the tool in the spindle: the record calibrated with (bound
    to) that T; else _JM_I[1] (_PRNUM: the last two digits are the probe number, spec §8.1)."""
    if spindle_tool is not None:
        for record in records:
            if record.get("tool") == spindle_tool:
                return int(record["number"])
    return int(gud_probe_number) % 100 or 1


class MeasuringEnv:
    """Implements ``app.workflow.service.WorkflowEnv`` with the app's services."""

    def __init__(self, db: Database, machine_service: MachineService, settings: SettingsService):
        self._db = db
        self._ms = machine_service
        self._settings = settings

    @property
    def machine(self) -> Machine:
        return self._ms.machine

    def measuring_context(self) -> MeasuringContext:
        st = self._ms.machine.status()
        gud = self._settings.get()
        with self._db.unit(readonly=True) as unit:
            offsets = {n: Frame.from_api(f) for n, f in unit.list_offsets().items()}
            tool = unit.get_tool(st.tool) if st.tool is not None else None
            probe_no = probe_number_for(unit.list_probes(), st.tool, int(gud.probe_number))
            probe_data = unit.get_probe(probe_no)
            tool_probe = unit.get_tool_probe(int(gud.tool_probe_number))
        is_probe = bool(tool) and int(tool.get("type", 0)) in PROBE_TYPES
        probe = probe_record_from(probe_data, tool, gud.length_to_tip) if is_probe else None
        active = self._ms.active_offset
        return MeasuringContext(
            active_offset=active,
            offsets=offsets,
            frame_chain=frame_chain(offsets, active),
            basic_names=basic_frame_names(offsets),
            plane=self._ms.plane(),
            tool_length=float(st.tool_length),
            tool=tool,
            spindle_angle=float(st.spindle_angle),
            feed_override=float(st.feed_override),
            settings=gud.model_dump(),
            probe=probe,
            probe_data=probe_data,
            extra={"tool_probe": tool_probe, "tool_probe_number": int(gud.tool_probe_number),
                   "probe_number": probe_no, "active_is_g500": active == G500},
        )

    def commit_measurement(self, *, offset=None, log_entry: dict, probe_update=None, tool_update=None,
                           tool_probe_update=None) -> int:
        """Offset + audit + log (+ probe/tool records) in one transaction (design.md §6)."""
        entry = {k: v for k, v in log_entry.items() if k in LOG_FIELDS}
        with self._db.unit() as unit:
            if offset is not None:
                name, _before, after, detail = offset
                unit.put_offset(name, after, source="measure", detail=detail)
            if probe_update is not None:
                unit.put_probe(probe_update[0], probe_update[1])
            if tool_update is not None:
                unit.put_tool(tool_update[0], tool_update[1])
            if tool_probe_update is not None:
                unit.put_tool_probe(tool_probe_update[0], tool_probe_update[1])
            log_id = unit.add_log(entry)
        if tool_update is not None:
            self._ms.refresh_tool_offset()
        return log_id

    def activate(self, name: str) -> None:
        self._ms.activate(name)

    def refresh_frames(self) -> None:
        self._ms.refresh_frame()

    def post_alarm(self, code: int, text: str) -> None:
        post = getattr(self._ms.machine, "post_alarm", None)
        if callable(post):
            post(Alarm(code, text))

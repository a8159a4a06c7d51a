"""The workflow's environment: measuring context from machine + db, one-transaction commits."""

from __future__ import annotations

import copy
import math

from pydantic import ValidationError

from app.access.checks import check_actor
from app.errors import AlarmError, InvalidInput
from app.machine.protocol import Alarm, KinematicData, Machine
from app.machine.scenario import Scenario
from app.records import ToolData, frame_out_of_range, is_probe_tool
from app.services.lathe_data import STATE_GROOVES
from app.services.machine_service import MachineService
from app.services.results import ResultsService
from app.services.settings import SettingsService
from app.workflow.context import (
    MeasuringContext,
    MeasuringSetup,
    OffsetChange,
    OffsetOutcome,
    ToolOffsetChange,
    ToolOffsetOutcome,
)
from db import Actor, Database, acting_as, current_actor
from db.repository import LOG_FIELDS
from engine import alarms
from engine.frames import G500, Frame, basic_frame_names, chain_of
from engine.lobing import lobing_map_from_json
from engine.types import MeasuringError, ProbeRecord


def probe_record_from(data: dict | None, tool: dict | None, length_to_tip: bool) -> ProbeRecord:
    """ProbeRecord from the stored _WP record and the tool data of the probe in the spindle."""
    data = data or {}
    skew = data.get("skew") or (0.0, 0.0)          # (x, y): a stored record is checked (app.records)
    ball = 2.0 * float(tool["radius"]) if tool and tool.get("radius") else float(data.get("ball_diameter", 4.0))
    if data.get("calibrated_radius") and data.get("measured_ball_diameter"):
        ball = float(data["measured_ball_diameter"])     # the ring chords measured it (engine.calibration)
    return ProbeRecord(
        number=int(data.get("number", 1)),
        ball_diameter=ball,
        effective_diameter=float(data.get("effective_diameter", 0.0) or 0.0),
        trigger={k: float(v) for k, v in (data.get("trigger") or {}).items()},
        skew=(float(skew[0]), float(skew[1])),
        length_to_tip=bool(length_to_tip),
        calibrated_radius=bool(data.get("calibrated_radius", False)),
        calibrated_length=bool(data.get("calibrated_length", False)),
        calibration_feed=data.get("calibration_feed"),
        calibration_override=data.get("calibration_override"),
        lobing=lobing_map_from_json(data["lobing"]) if data.get("lobing") else None,
    )


def probe_number_for(records: list[dict], spindle_tool: int | None, gud_probe_number: int) -> int:
    """The active _WP record follows the tool in the spindle: the record calibrated with (bound
    to) that T; else _JM_I[1] (_PRNUM: the last two digits are the probe number, jog-measuring §8.1)."""
    if spindle_tool is not None:
        for record in records:
            if record.get("tool") == spindle_tool:
                return int(record["number"])
    return int(gud_probe_number) % 100 or 1


def lathe_records(unit) -> dict:
    """The lathe's data records as stored: _TP/_TPW (tool probe records), _WP (probe records),
    _KB (reference grooves) and the EV/MV memories (turning.md §0.7, turning §10.2)."""
    return {"tool_probes": unit.list_tool_probes(), "probes": unit.list_probes(),
            "grooves": unit.get_state(STATE_GROOVES, None) or [],
            "memories": {"EV": unit.list_memories("EV"), "MV": unit.list_memories("MV")}}


TILT_TASK = "plane.align"        # orient plane (jog-measuring §6): its frame turns about X/Y


def tilt_deg(frame: dict) -> float:
    """The angle between a frame's Z and the machine's Z, from its rotation about X and Y (degrees;
    RPY: cos(tilt) = cos(rx)·cos(ry))."""
    rot = frame.get("rot") or {}
    rx, ry = math.radians(float(rot.get("X", 0.0))), math.radians(float(rot.get("Y", 0.0)))
    return math.degrees(math.acos(max(-1.0, min(1.0, math.cos(rx) * math.cos(ry)))))


class MeasuringEnv:
    """Implements ``app.workflow.service.WorkflowEnv`` with the app's services."""

    def __init__(self, db: Database, machine_service: MachineService, settings: SettingsService):
        self._db = db
        self._ms = machine_service
        self._settings = settings
        self._cache: tuple | None = None
        self._start_actor: Actor | None = None      # who pressed NC Start (for a measurement that runs on in a thread)
        self.results: ResultsService | None = None   # links log entries to the job's part (design.md §10.3)
        # issue 34 §5: a tilt "orient plane" measured that the NC refused to hold (LinuxCNC: no rotation
        # about X/Y): (target, tilt in degrees) until an orient plane is stored again
        self._unaligned_tilt: tuple[str, float] | None = None

    @property
    def machine(self) -> Machine:
        return self._ms.machine

    def unaligned_tilt_warning(self) -> str | None:
        """The warning for a measurement in the machine's plane while the part is tilted and the NC
        could not hold the orient-plane frame (issue 34 §5): its result is off by the tilt."""
        if self._unaligned_tilt is None:
            return None
        target, tilt = self._unaligned_tilt
        return (f"Tilted part: orient plane measured {tilt:.3f}° for {target}, which the control cannot hold "
                "(61321): a measurement in the machine's plane is off by the tilt; align the part on the table")

    def interlock(self, action: str) -> None:
        self._ms.interlock(action)

    def release_jog(self) -> None:
        """NC Start begins a measurement: forget a held jog, so that its dead-man watchdog cannot
        stop the measurement's motion (a late renewal may have restarted the jog)."""
        self._ms.release_jog()

    def _stored(self, tool_no: int | None, gud, probe_number: int | None = None) -> tuple:
        """(frames, tool row, probe number, probe record, tool-probe record) as stored; read once
        per database generation (nothing written since: the same values). ``probe_number``: the
        record a cycle names (_PRNUM), else the one bound to the tool in the spindle."""
        key = (self._db.generation, tool_no, int(gud.probe_number), int(gud.tool_probe_number), probe_number)
        cached = self._cache
        if cached is not None and cached[0] == key:
            return cached[1]
        with self._db.unit(readonly=True) as unit:
            offsets = {n: Frame.from_api(f) for n, f in unit.list_offsets().items()}
            tool = unit.get_tool(tool_no) if tool_no is not None else None
            probe_no = probe_number or probe_number_for(unit.list_probes(), tool_no, int(gud.probe_number))
            probe_data = unit.get_probe(probe_no)
            tool_probe = unit.get_tool_probe(int(gud.tool_probe_number))
            lathe = lathe_records(unit) if self._ms.is_lathe else None
        value = (offsets, tool, probe_no, probe_data, tool_probe, lathe)
        self._cache = (key, value)
        return value

    def measuring_context(self, probe_number: int | None = None) -> MeasuringContext:
        """``probe_number``: the probe record a measuring cycle names with _PRNUM (read and written)."""
        if current_actor() is not None:     # NC Start asks for the context in the request's thread
            self._start_actor = current_actor()
        st = self._ms.machine.status()
        gud = self._settings.get()
        offsets, tool, probe_no, probe_data, tool_probe, lathe = self._stored(st.tool, gud, probe_number)
        tool = dict(tool) if tool is not None else None            # callers may not change the cache
        probe_data = dict(probe_data) if probe_data is not None else None
        is_probe = is_probe_tool(tool)
        probe = probe_record_from(probe_data, tool, gud.length_to_tip) if is_probe else None
        active = self._ms.active_offset
        return MeasuringContext(
            active_offset=active,
            offsets=dict(offsets),
            frame_chain=chain_of(offsets, active),
            basic_names=basic_frame_names(offsets),
            plane=self._ms.plane(),
            tool_length=float(st.tool_length),
            tool=tool,
            spindle_angle=float(st.spindle_angle),
            feed_override=float(st.feed_override),
            settings=gud,
            probe=probe,
            probe_data=probe_data,
            extra={"tool_probe": tool_probe, "tool_probe_number": int(gud.tool_probe_number),
                   "kinematics": self.kinematic_facts(),
                   "probe_number": probe_no, "active_is_g500": active == G500,
                   **({"lathe": self._lathe_extra(st, lathe)} if lathe is not None else {})},
        )

    def _lathe_extra(self, st, records: dict) -> dict:
        """What the turning cycles read besides the tool (app.workflow.finish_lathe.lathe_context):
        the NC's lengths of the active tool, DIAMON, Y, SPOS capability, the records."""
        machine = self._ms.machine
        return {**copy.deepcopy(records), "tool_lengths": tuple(getattr(st, "tool_lengths", (0.0, 0.0))),
                "diamon": self._ms.diameter_programming, "has_y": "Y" in tuple(machine.axes),
                "spos": self._ms.spos_capable}

    def measuring_setup(self) -> MeasuringSetup:
        return MeasuringSetup(self._ms.plane(), self._ms.active_offset, tuple(self._db.offset_names()),
                              self._settings.get())

    def commit_measurement(self, *, offset: OffsetChange | None = None, log_entry: dict, probe_update=None,
                           tool_update=None, tool_probe_update=None, tool_offset: ToolOffsetChange | None = None,
                           kinematics_update: dict | None = None
                           ) -> tuple[int, OffsetOutcome | ToolOffsetOutcome | None]:
        """Offset + audit + log (+ probe/tool records) in one transaction (design.md §6, §9.1).

        The offset is computed here, from the frames as stored inside the transaction; a result
        that is not finite or beyond the offset limits is refused (422 ``correction_out_of_range``)
        and nothing is written.

        Every write is audited naming who measured (the request's identity; for a measurement that
        runs on in the workflow's own thread, the one that pressed NC Start), and refused (403
        ``access_level``, nothing written) when that identity's level is too low for it."""
        calibration = probe_update is not None or tool_probe_update is not None
        functions = [f for f, writes in (("offsets", offset is not None),
                                         ("calibration", calibration),
                                         ("tools", (tool_update is not None or tool_offset is not None)
                                          and not calibration),
                                         # the control's kinematic data are machine data (design.md §10.6)
                                         ("settings", kinematics_update is not None)) if writes]
        with acting_as(current_actor() or self._start_actor):
            check_actor(self._settings, functions)
            return self._commit(offset, log_entry, probe_update, tool_update, tool_probe_update, tool_offset,
                                "calibration" if calibration else "measure", kinematics_update)

    def kinematic_facts(self) -> dict:
        """What ``kinematics.measure`` needs of the machine: the control's axis lines (with their
        unit), the rotary axes, their limits (app.workflow.kinematics_task)."""
        machine = self._ms.machine
        lines = machine.kinematic_data() if isinstance(machine, KinematicData) else {}
        scenario = self._ms.scenario
        limits = scenario.limits() if isinstance(scenario, Scenario) else {}
        return {"lines": lines, "rotary_axes": self._ms.rotary_axes,
                "limits": {a: tuple(v) for a, v in limits.items() if a in lines or a == "Z"}}

    def _commit(self, offset, log_entry, probe_update, tool_update, tool_probe_update, tool_offset, source,
                kinematics_update=None):
        entry = {k: v for k, v in log_entry.items() if k in LOG_FIELDS}
        outcome = stored_offset = None
        generation = self._db.generation
        with self._db.unit() as unit:
            if offset is not None:
                outcome, stored_offset = self._store_offset(unit, offset, generation, entry)
            detail = {"task": entry.get("task")}
            if tool_offset is not None:
                outcome = self._tool_offset(unit, tool_offset, entry)
                if outcome.after is not None:
                    tool_update = (outcome.tool, outcome.after)
            stored_tool = self._store_records(unit, entry, source, detail, probe_update, tool_update,
                                              tool_probe_update)
            log_id = self.results.add_log(unit, entry) if self.results is not None else unit.add_log(entry)
            lines = self._kinematics_audit(unit, kinematics_update, log_id)
        log_entry["calibration_id"] = entry.get("calibration_id")     # a calibration's new id, for the answer
        self._write_nc(generation, lines, stored_offset, stored_tool,
                       records=bool(probe_update or tool_update or tool_probe_update))
        return log_id, outcome

    def _store_offset(self, unit, offset, generation: int, entry: dict):
        """The corrected WO stored in ``unit`` once it is in range and the machine can hold it:
        (the outcome, (WO name, stored frame))."""
        outcome = offset.compute(self._frames_in(unit, generation))
        wrong = frame_out_of_range(outcome.after)
        if wrong:
            raise InvalidInput(f"The measured correction would make {offset.target} {wrong[1]}: "
                               "check the setpoints and the probe data", field=wrong[0],
                               code="correction_out_of_range")
        try:
            self._ms.check_holds(offset.target, outcome.after)
        except AlarmError:
            if entry.get("task") == TILT_TASK:
                self._unaligned_tilt = (offset.target, tilt_deg(outcome.after))
            raise
        if entry.get("task") == TILT_TASK:
            self._unaligned_tilt = None
        _before, after = unit.put_offset(offset.target, outcome.after, source="measure", detail=outcome.detail)
        entry["correction"] = outcome.answer.get("correction")
        return outcome, (offset.target, after)

    def _store_records(self, unit, entry: dict, source: str, detail: dict, probe_update, tool_update,
                       tool_probe_update) -> dict | None:
        """The probe record, the tool data and the tool probe record stored in ``unit``; the stored tool."""
        stored_tool = None
        if probe_update is not None:
            record = self._calibrated(unit, "workpiece", probe_update[0], probe_update[1], entry)
            unit.put_probe(probe_update[0], record, source=source, detail=detail)
        if tool_update is not None:
            stored_tool = unit.put_tool(tool_update[0], tool_update[1], source=source, detail=detail)
        if tool_probe_update is not None:
            record = self._calibrated(unit, "tool", tool_probe_update[0], tool_probe_update[1], entry)
            unit.put_tool_probe(tool_probe_update[0], record, source=source, detail=detail)
        return stored_tool

    def _write_nc(self, generation: int, lines: dict | None, stored_offset, stored_tool: dict | None, *,
                  records: bool) -> None:
        """The NC is given what was stored: kinematic data, the WO, the tool."""
        if lines is not None:                  # the NC holds what the audit says
            machine = self._ms.machine
            assert isinstance(machine, KinematicData), "kinematic_facts found the lines on this machine"
            machine.write_kinematic_data(lines)
        if stored_offset is not None and not records:
            self._written(generation, *stored_offset)
        if stored_offset is not None:          # the NC holds what was stored
            self._ms.write_offset(*stored_offset)
        if stored_tool is not None:
            self._ms.write_tool(stored_tool["t"], stored_tool)
            self._ms.refresh_tool_offset()

    def _calibrated(self, unit, probe: str, n: int, record: dict, entry: dict) -> dict:
        """A calibration written: a new calibration id (its probe_events row), valid again, the
        probe it was made with (design.md §10.4); the log entry carries the new id."""
        data = {k: record.get(k) for k in ("calibrated_at", "calibrated_length", "calibrated_radius",
                                           "calibrated_diameter", "calibrated_directions", "trigger", "effective_diameter",
                                           "measured_ball_diameter") if k in record}
        event = unit.add_probe_event(probe, n, "calibration", {**data, "task": entry.get("task")})
        entry["calibration_id"] = event["id"]
        return {**record, "calibration_id": event["id"], "invalidated": None,
                "probe_identity": self._ms.probe_identity(probe)}

    def _kinematics_audit(self, unit, update: dict | None, log_id: int) -> dict | None:
        """The audit row of a kinematics write (kind "kinematics", undoable); the lines to write."""
        if update is None:
            return None
        machine = self._ms.machine
        if not isinstance(machine, KinematicData):
            raise MeasuringError(alarms.ROTARY_AXIS, "this controller holds no rotary-axis kinematic data")
        before = machine.kinematic_data()
        after = {a: ({**line, **update[a]} if a in update else line) for a, line in before.items()}
        unit.add_audit("kinematics", "kinematics", before, after, "measure",
                       {"task": "kinematics.measure", "log_id": log_id})
        return update

    def _frames_in(self, unit, generation: int) -> dict[str, Frame]:
        """The stored frames inside the write transaction: the cached ones when nothing was
        written since they were read (the write lock is held, so nothing can be meanwhile)."""
        unit.hold_write_lock()                    # no other writer from here until the commit
        cached = self._cache
        if cached is not None and cached[0][0] == generation == self._db.generation:
            return dict(cached[1][0])
        return {n: Frame.from_api(f) for n, f in unit.list_offsets().items()}

    def _written(self, generation: int, name: str, frame: dict) -> None:
        """Our own commit of one frame: the caches take it, nothing else changed."""
        if self._db.generation != generation + 1:
            return
        cached = self._cache
        if cached is not None and cached[0][0] == generation:
            key, (offsets, *rest) = cached
            self._cache = ((generation + 1, *key[1:]), ({**offsets, name: Frame.from_api(frame)}, *rest))
        self._ms.frames_written(generation, name, frame)

    @staticmethod
    def _tool_offset(unit, change: ToolOffsetChange, entry: dict) -> ToolOffsetOutcome:
        """The tool-offset decision from the tool data and memories as stored in this transaction."""
        tool = unit.get_tool(change.tool)
        if tool is None:
            raise MeasuringError(alarms.TOOL_NUMBER, f"T{change.tool} is not in the tool table")
        outcome = change.compute(tool, unit.get_memory)
        if outcome.after is not None:
            try:
                ToolData.model_validate({**tool, **outcome.after, "t": change.tool})
            except ValidationError as exc:
                first = exc.errors()[0]
                where = ".".join(str(p) for p in first["loc"])
                raise InvalidInput(f"The tool offset would make T{change.tool} {where} out of range "
                                   f"({first['msg']}): check the tolerance parameters", field=where,
                                   code="correction_out_of_range") from None
        for (kind, number), value in outcome.memories.items():
            unit.put_memory(kind, number, value, source="measure", detail={"task": entry.get("task")})
        entry["result"] = {**(entry.get("result") or {}), **outcome.result}
        entry["correction"] = outcome.correction
        return outcome

    def guard_off(self, task: str) -> None:
        """``params.guard: false`` (design.md §10.1): only at the ``settings`` level, audited."""
        check_actor(self._settings, ["settings"])
        with self._db.unit() as unit:
            unit.add_audit("guard", task, {"guard": True}, {"guard": False}, "measure", {"task": task})

    def activate(self, name: str) -> None:
        self._ms.make_active(name)

    def refresh_frames(self) -> None:
        self._ms.refresh_frame()

    def post_alarm(self, code: int, text: str) -> None:
        self._ms.machine.post_alarm(Alarm(code, text))

"""OPC 40001-101 Machinery Result Transfer: ``Objects/JogMeasure/ResultManagement`` (design.md §10.3).

An object of the node set's ``ResultManagementType`` (vendored unmodified from the npm package
``node-opcua-nodesets``, vendor/) with the methods ``GetLatestResult(Timeout)`` and
``GetResultById(ResultId, Timeout)`` → ``(ResultHandle, Result, Error)``. A result is a part
(``GET /api/parts/{id}``): ``ResultMetaDataType`` (ResultId = the part's id, ProductId = the part
number, PartId = the serial, JobId = the order, CreationTime, ResultEvaluation OK / NotOK /
NotDecidable, ResultEvaluationDetails = the verdict, IsPartial/ResultState: the job's open part is
partial and processing) and ``ResultContent``: one ``CharacteristicDataType`` (this product's
structure in the HMI's namespace) per characteristic. Error: 0 ok, -2 no such result (no result
yet, an unknown ResultId). After each new log entry of a part a ``ResultReadyEvent`` (this
product's concrete subtype of the abstract ``ResultReadyEventType``) carries the ResultId.
"""

from __future__ import annotations

import asyncio
from datetime import UTC, datetime
from pathlib import Path

from asyncua import Node, Server, ua
from asyncua.common.structures104 import new_struct, new_struct_field
from asyncua.server.event_generator import EventGenerator

from app.errors import NotFoundError
from app.services import Services

NODESET = Path(__file__).resolve().parents[2] / "vendor" / "node-opcua-nodesets-2.185.0" / \
    "Opc.Ua.Machinery_Result.NodeSet2.xml"
RESULT_URI = "http://opcfoundation.org/UA/Machinery/Result/"
RESULT_MANAGEMENT_TYPE, RESULT_READY_EVENT_TYPE, RESULT_EVALUATION_ENUM = 1004, 1002, 3002
EVALUATION = {"ok": 1, "rework": 2, "scrap": 2, "not_decidable": 3}     # ResultEvaluationEnum
ERROR_NONE, ERROR_NO_RESULT = 0, -2
STATE_COMPLETED, STATE_PROCESSING = 1, 2


def _time(iso: str | None) -> datetime | None:
    return datetime.fromisoformat(iso).astimezone(UTC) if iso else None


class ResultManagement:
    def __init__(self, server: Server, idx: int, services: Services):
        self._server = server
        self._idx = idx
        self._services = services
        self._event: Node | None = None
        self._generator: EventGenerator | None = None
        self._node: Node | None = None
        self._last_log_id: int | None = None

    async def setup(self, parent: Node) -> Node:
        from .umati import quiet_import

        with quiet_import():
            await self._server.import_xml(str(NODESET), strict_mode=False)
        rns = await self._server.get_namespace_index(RESULT_URI)
        idx = self._idx
        await new_struct(self._server, idx, "CharacteristicDataType", [
            new_struct_field("Name", ua.VariantType.String),
            new_struct_field("Nominal", ua.VariantType.Double),
            new_struct_field("LowerLimit", ua.VariantType.Double),
            new_struct_field("UpperLimit", ua.VariantType.Double),
            new_struct_field("Actual", ua.VariantType.Double),
            new_struct_field("Deviation", ua.VariantType.Double),
            new_struct_field("Unit", ua.VariantType.String),
            new_struct_field("Verdict", ua.VariantType.String),
            new_struct_field("Evaluation", _nid(RESULT_EVALUATION_ENUM, rns)),
            new_struct_field("LogId", ua.VariantType.Int64),
        ])
        await self._server.load_data_type_definitions()
        node = await parent.add_object(_nid("ResultManagement", idx), ua.QualifiedName("ResultManagement", idx),
                                       objecttype=_nid(RESULT_MANAGEMENT_TYPE, rns))
        handle, result, error = (ua.Argument(Name="ResultHandle", DataType=_nid(ua.ObjectIds.UInt32, 0), ValueRank=-1),
                                 ua.Argument(Name="Result", DataType=_nid(3008, rns), ValueRank=-1),
                                 ua.Argument(Name="Error", DataType=_nid(ua.ObjectIds.Int32, 0), ValueRank=-1))
        timeout = ua.Argument(Name="Timeout", DataType=_nid(ua.ObjectIds.Int32, 0), ValueRank=-1)
        result_id = ua.Argument(Name="ResultId", DataType=_nid(ua.ObjectIds.String, 0), ValueRank=-1)
        await self._method(node, rns, "GetLatestResult", self._latest, [timeout], [handle, result, error])
        await self._method(node, rns, "GetResultById", self._by_id, [result_id, timeout], [handle, result, error])
        self._event = await self._server.create_custom_event_type(
            idx, "JogMeasureResultReadyEventType", _nid(RESULT_READY_EVENT_TYPE, rns),
            [("ResultId", ua.VariantType.String), ("PartId", ua.VariantType.String),
             ("ResultEvaluation", ua.VariantType.Int32)])
        await self._server.get_node(ua.ObjectIds.Server).add_reference(node.nodeid, ua.ObjectIds.HasNotifier)
        self._generator = await self._server.get_event_generator(self._event, node.nodeid)
        self._node = node
        return node

    async def _method(self, node: Node, rns: int, name: str, func, inputs, outputs) -> None:
        """The type's method where the instance has it, else added under its browse name."""
        try:
            method = await node.get_child(f"{rns}:{name}")
            self._server.link_method(method, func)
        except ua.UaError:
            await node.add_method(_nid(f"ResultManagement.{name}", self._idx), ua.QualifiedName(name, rns),
                                  func, inputs, outputs)

    # --- the methods -----------------------------------------------------------------------------
    async def _latest(self, parent, timeout) -> list[ua.Variant]:
        part = await asyncio.to_thread(self._latest_part)
        return self._answer(part)

    async def _by_id(self, parent, result_id, timeout) -> list[ua.Variant]:
        text = str(result_id.Value if isinstance(result_id, ua.Variant) else result_id or "")
        part = await asyncio.to_thread(self._part, text)
        return self._answer(part)

    def _latest_part(self) -> dict | None:
        results = self._services.results
        assert results is not None
        parts = results.parts(limit=20)
        with_values = [p for p in parts if p["characteristics"]]
        return with_values[0] if with_values else (parts[0] if parts else None)

    def _part(self, text: str) -> dict | None:
        results = self._services.results
        assert results is not None
        if not (text.isascii() and text.isdigit()):     # int() would read '²' or other scripts' digits
            return None
        try:
            return results.part(int(text))
        except NotFoundError:           # no such part: the browse name reads nothing
            return None

    def _open_part_id(self) -> int | None:
        results = self._services.results
        return results.job().get("part_id") if results is not None else None

    def _answer(self, part: dict | None) -> list[ua.Variant]:
        handle = ua.Variant(0 if part is None else int(part["id"]), ua.VariantType.UInt32)
        if part is None:
            empty = _type("ResultDataType")(ResultMetaData=_type("ResultMetaDataType")(ResultId="NA"), ResultContent=[])
            return [handle, ua.Variant(empty), ua.Variant(ERROR_NO_RESULT, ua.VariantType.Int32)]
        return [handle, ua.Variant(self.result(part)), ua.Variant(ERROR_NONE, ua.VariantType.Int32)]

    def result(self, part: dict) -> object:
        status = self._services.machine.status()
        partial = part["id"] == self._open_part_id()
        meta = _type("ResultMetaDataType")(
            ResultId=str(part["id"]), IsPartial=partial, IsSimulated=status.get("controller", "sim") == "sim",
            ResultState=STATE_PROCESSING if partial else STATE_COMPLETED, PartId=part.get("serial"),
            ProductId=part.get("part_number"), JobId=part.get("order"), CreationTime=_time(part.get("started")),
            ResultEvaluation=EVALUATION.get(part["verdict"], 0),
            ResultEvaluationDetails=ua.LocalizedText(part["verdict"], "en"))
        content = [ua.Variant(_type("CharacteristicDataType")(
            Name=c["name"], Nominal=_real(c["nominal"]), LowerLimit=_real(c["lower"]), UpperLimit=_real(c["upper"]),
            Actual=_real(c["actual"]), Deviation=_real(c["deviation"]), Unit=c["unit"], Verdict=c["verdict"],
            Evaluation=EVALUATION.get(c["verdict"], 0), LogId=int(c["log_id"] or 0)))
            for c in part["characteristics"]]
        return _type("ResultDataType")(ResultMetaData=meta, ResultContent=content)

    # --- the event ------------------------------------------------------------------------------------
    async def notify(self, newest: dict | None) -> None:
        """A ResultReadyEvent when the newest log entry belongs to a part and is new."""
        if newest is None or newest.get("id") == self._last_log_id:
            return
        first = self._last_log_id is None
        self._last_log_id = newest.get("id")
        if first or not newest.get("part_id"):
            return
        part = await asyncio.to_thread(self._part, str(newest["part_id"]))
        if part is None or self._generator is None:
            return
        event = self._generator.event
        event.ResultId = str(part["id"])
        event.PartId = part.get("serial") or ""
        event.ResultEvaluation = EVALUATION.get(part["verdict"], 0)
        event.Message = ua.LocalizedText(f"result {part['id']} of {part['part_number']}: {part['verdict']}")
        await self._generator.trigger()


def _real(value) -> float:
    return float("nan") if value is None else float(value)


def _type(name: str):
    """A structure class that ``load_data_type_definitions`` made from the node sets."""
    return getattr(ua, name)


def _nid(identifier: int | str, namespace: int) -> ua.NodeId:
    """``ns=<namespace>;i=`` or ``;s=`` (asyncua types a node id's fields as its own classes)."""
    value = ua.String(identifier) if isinstance(identifier, str) else ua.Int32(identifier)
    return ua.NodeId(value, ua.Int16(namespace))

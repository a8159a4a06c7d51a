"""The umati MachineTool instance (OPC 40501-1 MachineTool 1.02, on DI, IA, Machinery and the
Machinery Jobs models): ``Objects/Machines/JogMeasureMachine``, a ``MachineToolType`` whose
mandatory parts show what the product knows (docs/opcua.md lists what cannot be mapped).

The node sets are the OPC Foundation's, vendored unmodified from the npm package
``node-opcua-nodesets`` (vendor/, pinned). asyncua imports them with ``strict_mode=False``
(asyncua issue #1869: the Jobs model's bit-mask structures) and skips 9 nodes of DI that hang on a
design-tool-only parent; neither is used by the instance.
"""

from __future__ import annotations

import logging
import socket
from contextlib import contextmanager
from importlib import metadata
from pathlib import Path

from asyncua import Node, Server, ua

from app.opcua.space import set_if_changed

log = logging.getLogger(__name__)
NODESETS = Path(__file__).resolve().parents[2] / "vendor" / "node-opcua-nodesets-2.185.0"
FILES = ("Opc.Ua.Di.NodeSet2.xml", "Opc.Ua.IA.NodeSet2.xml", "Opc.Ua.Machinery.NodeSet2.xml",
         "opc.ua.isa95-jobcontrol.nodeset2.xml", "Opc.Ua.Machinery.Jobs.Nodeset2.xml",
         "Opc.Ua.MachineTool.NodeSet2.xml")                   # in the order they depend on each other
DI, MACHINERY, MACHINE_TOOL = ("http://opcfoundation.org/UA/DI/", "http://opcfoundation.org/UA/Machinery/",
                               "http://opcfoundation.org/UA/MachineTool/")
MACHINES_FOLDER, MACHINE_TOOL_TYPE, CHANNEL_MONITORING_TYPE = 1001, 13, 16     # Machinery; MachineTool ids
INSTANCE = "JogMeasureMachine"

# OPC 40501-1 enumerations (MachineTool node set: ChannelMode i=67, ChannelState i=64,
# MachineOperationMode i=65) from the HMI's mode (JOG, MDA, AUTO) and program state
CHANNEL_MODE = {"AUTO": 0, "MDA": 1, "JOG": 2}
CHANNEL_MODE_OTHER = 7
CHANNEL_STATE = {"active": 0, "interrupted": 1, "reset": 2}
OPERATION_MODE = {"JOG": 0, "MDA": 1, "AUTO": 1}             # Manual, Automatic
# ProductionProgramStateMachineType states (MachineTool i=5039.. ): a reset channel waits for a start
PROGRAM_STATE = {"active": ("Running", 5041), "interrupted": ("Interrupted", 5040),
                 "reset": ("Initializing", 5039)}
# the feed override is a percentage within 0..120 % (the simulator's limits); UNECE code P1 is "%"
PERCENT = ua.EUInformation(NamespaceUri="http://www.opcfoundation.org/UA/units/un/cefact",
                           UnitId=(ord("P") << 8) | ord("1"), DisplayName=ua.LocalizedText("%"),
                           Description=ua.LocalizedText("percent"))
FEED_RANGE = ua.Range(Low=0.0, High=120.0)


@contextmanager
def quiet_import():
    """The import's warnings about the skipped nodes are known (see above): keep them out of the log."""
    names = ("asyncua.common.xmlimporter", "asyncua.common.structures104", "asyncua.ua.uatypes")
    loggers = [logging.getLogger(n) for n in names]
    levels = [lg.level for lg in loggers]
    for lg in loggers:
        lg.setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        for lg, level in zip(loggers, levels, strict=True):
            lg.setLevel(level)


def numeric_id(identifier: int, namespace: int) -> ua.NodeId:
    """``ns=<namespace>;i=<identifier>`` (asyncua types a node id's fields as its own int classes)."""
    return ua.NodeId(ua.Int32(identifier), ua.Int16(namespace))


def software_revision() -> str:
    try:
        return metadata.version("jog-measure-hmi")
    except metadata.PackageNotFoundError:
        return "0.1.0"


class MachineToolInstance:
    def __init__(self, server: Server, idx: int, controller: str):
        self._server = server
        self._idx = idx                  # the instance's nodes are in the HMI's namespace
        self._controller = controller
        self._variables: dict[str, Node] = {}
        self._shown: dict[str, object] = {}
        self._mt = 0
        self._state_numbers: dict[str, int] = {}

    def _id(self, path: str) -> ua.NodeId:
        return ua.NodeId(ua.String(f"umati.{INSTANCE}.{path}" if path else f"umati.{INSTANCE}"), ua.Int16(self._idx))

    async def load(self) -> None:
        with quiet_import():
            for name in FILES:
                await self._server.import_xml(str(NODESETS / name), strict_mode=False)
        di, machinery, mt = [await self._server.get_namespace_index(u) for u in (DI, MACHINERY, MACHINE_TOOL)]
        self._mt = mt
        folder = self._server.get_node(numeric_id(MACHINES_FOLDER, machinery))
        machine = await folder.add_object(self._id(""), ua.QualifiedName(INSTANCE, self._idx),
                                          objecttype=numeric_id(MACHINE_TOOL_TYPE, mt), instantiate_optional=False)
        await self._identification(machine, di, mt)
        monitoring = await machine.get_child(f"{mt}:Monitoring")
        channel = await monitoring.add_object(self._id("Monitoring.Channel1"), ua.QualifiedName("Channel1", mt),
                                              objecttype=numeric_id(CHANNEL_MONITORING_TYPE, mt),
                                              instantiate_optional=False)
        await (await channel.get_child(f"{mt}:Name")).write_value("CHAN1")
        feed = await channel.get_child(f"{mt}:FeedOverride")
        await (await feed.get_child("0:EngineeringUnits")).write_value(PERCENT)
        await (await feed.get_child("0:EURange")).write_value(FEED_RANGE)
        self._variables = {
            "ChannelMode": await channel.get_child(f"{mt}:ChannelMode"),
            "ChannelState": await channel.get_child(f"{mt}:ChannelState"),
            "FeedOverride": await channel.get_child(f"{mt}:FeedOverride"),
            "OperationMode": await monitoring.get_child([f"{mt}:MachineTool", f"{mt}:OperationMode"]),
            "ProgramState": await machine.get_child([f"{mt}:Production", f"{mt}:ActiveProgram", f"{mt}:State",
                                                     "0:CurrentState"]),
            "ProgramStateId": await machine.get_child([f"{mt}:Production", f"{mt}:ActiveProgram", f"{mt}:State",
                                                       "0:CurrentState", "0:Id"]),
        }
        current = self._variables["ProgramState"]
        try:                                     # CurrentState/Number: the state's StateNumber (Part 5)
            self._variables["ProgramStateNumber"] = await current.get_child("0:Number")
            for name, state_id in PROGRAM_STATE.values():
                state = self._server.get_node(numeric_id(state_id, mt))
                self._state_numbers[name] = int(await (await state.get_child("0:StateNumber")).read_value())
        except ua.UaError:
            log.warning("umati: CurrentState/Number not shown (no Number or StateNumber in the node set)")
            self._variables.pop("ProgramStateNumber", None)
        program = await machine.get_child([f"{mt}:Production", f"{mt}:ActiveProgram"])
        await (await program.get_child(f"{mt}:Name")).write_value("JOG measuring")
        await (await program.get_child("0:NumberInList")).write_value(ua.Variant(0, ua.VariantType.UInt16))

    async def _identification(self, machine: Node, di: int, mt: int) -> None:
        host = socket.gethostname()
        identification = await machine.get_child(f"{di}:Identification")      # DI's browse name (an add-in)
        values = {"Manufacturer": ua.LocalizedText(f"JOG Measure HMI ({self._controller} controller)"),
                  "SerialNumber": f"{self._controller}@{host}",
                  "ProductInstanceUri": f"urn:{host}:jog-measure-hmi:{INSTANCE}"}
        for name, value in values.items():
            await (await identification.get_child(f"{di}:{name}")).write_value(value)
        for name, value in (("Model", ua.LocalizedText("SINUMERIK 840D Measuring in JOG (web HMI)")),
                            ("SoftwareRevision", software_revision())):
            await identification.add_property(self._id(f"Identification.{name}"), ua.QualifiedName(name, di), value)

    async def show(self, status: dict) -> None:
        mode = status["mode"] or "JOG"
        state_name, state_id = PROGRAM_STATE[status["program_state"]]
        values = {
            "ChannelMode": ua.Variant(CHANNEL_MODE.get(mode, CHANNEL_MODE_OTHER), ua.VariantType.Int32),
            "ChannelState": ua.Variant(CHANNEL_STATE[status["program_state"]], ua.VariantType.Int32),
            "FeedOverride": ua.Variant(float(status["feed_override"]), ua.VariantType.Double),
            "OperationMode": ua.Variant(OPERATION_MODE.get(mode, 5), ua.VariantType.Int32),
            "ProgramState": ua.Variant(ua.LocalizedText(state_name), ua.VariantType.LocalizedText),
            "ProgramStateId": ua.Variant(numeric_id(state_id, self._mt), ua.VariantType.NodeId),
        }
        if "ProgramStateNumber" in self._variables:
            values["ProgramStateNumber"] = ua.Variant(self._state_numbers[state_name], ua.VariantType.UInt32)
        for name, variant in values.items():
            await set_if_changed(self._server, self._variables[name], variant, self._shown, name)

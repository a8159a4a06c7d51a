"""The umati MachineTool instance (``--opcua-umati``): typed as OPC 40501-1 asks, showing the
channel as ``GET /api/machine`` does."""

from __future__ import annotations

import asyncio
import time

import httpx
import pytest
from asyncua import Client, ua
from hmi_testdata import TEST_SCENARIO
from live import free_port, serve
from opc_kit import add_users, run
from waiting import wait_until

MT, MACHINERY, DI = ("http://opcfoundation.org/UA/MachineTool/", "http://opcfoundation.org/UA/Machinery/",
                     "http://opcfoundation.org/UA/DI/")


@pytest.fixture(scope="module")
def umati(tmp_path_factory):
    opc_port = free_port()
    built = {}

    def prepare(app):
        built["app"], built["token"] = app, add_users(app)

    with serve(tmp_path_factory.mktemp("umati"), TEST_SCENARIO, start_timeout_s=90.0,
               settings={"opcua_port": opc_port, "opcua_umati": True}, prepare=prepare) as url:
        endpoint = built["app"].state.endpoints[0]
        wait_until(lambda: endpoint.umati_state != "loading", "the umati model loads", 60.0)
        assert endpoint.umati_state == "loaded"
        with httpx.Client(base_url=url, headers={"Authorization": f"Bearer {built['token']}"}, timeout=10) as http:
            yield http, f"opc.tcp://127.0.0.1:{opc_port}"


async def machine_tool(client: Client):
    mt, machinery, di = [await client.get_namespace_index(u) for u in (MT, MACHINERY, DI)]
    idx = await client.get_namespace_index("urn:jog-measure-hmi")
    machine = await client.nodes.objects.get_child([f"{machinery}:Machines", f"{idx}:JogMeasureMachine"])
    return machine, mt, di


def test_the_instance_is_a_machine_tool_with_identification(umati):
    _http, url = umati

    async def read():
        async with Client(url, timeout=10) as client:
            machine, mt, di = await machine_tool(client)
            kind = await machine.read_type_definition()
            ident = await machine.get_child(f"{di}:Identification")
            manufacturer = await (await ident.get_child(f"{di}:Manufacturer")).read_value()
            serial = await (await ident.get_child(f"{di}:SerialNumber")).read_value()
            parts = {(await c.read_browse_name()).Name for c in await machine.get_children()}
            return kind, mt, manufacturer, serial, parts

    kind, mt, manufacturer, serial, parts = run(read())
    assert kind == ua.NodeId(13, mt)                     # MachineToolType in the MachineTool namespace
    assert {"Identification", "Monitoring", "Production", "Equipment", "Notification"} <= parts
    assert manufacturer.Text and serial.startswith("sim@")


def test_the_channel_shows_mode_state_and_override_of_the_json_api(umati):
    http, url = umati
    assert http.put("/api/machine/override", json={"feed": 75.0}).status_code == 200
    machine_json = http.get("/api/machine").json()
    assert machine_json["mode"] == "JOG" and machine_json["program_state"] == "reset"

    async def read():
        async with Client(url, timeout=10) as client:
            machine, mt, _di = await machine_tool(client)
            channel = await machine.get_child([f"{mt}:Monitoring", f"{mt}:Channel1"])
            deadline = time.monotonic() + 1.0
            feed = await channel.get_child(f"{mt}:FeedOverride")
            while await feed.read_value() != 75.0 and time.monotonic() < deadline:
                await asyncio.sleep(0.05)
            values = [await (await channel.get_child(f"{mt}:{n}")).read_value()
                      for n in ("ChannelMode", "ChannelState", "FeedOverride", "Name")]
            operation = await (await machine.get_child(
                [f"{mt}:Monitoring", f"{mt}:MachineTool", f"{mt}:OperationMode"])).read_value()
            current = await machine.get_child(
                [f"{mt}:Production", f"{mt}:ActiveProgram", f"{mt}:State", "0:CurrentState"])
            state = await current.read_value()
            # issue 25: Number is the StateNumber the node set gives the state that Id names
            state_node = client.get_node(await (await current.get_child("0:Id")).read_value())
            expected = await (await state_node.get_child("0:StateNumber")).read_value()
            assert await (await current.get_child("0:Number")).read_value() == expected
            return values, operation, state

    (mode, state, feed, name), operation, program = run(read())
    # OPC 40501-1 enumerations: ChannelMode 2 = JogManual, ChannelState 2 = Reset, OperationMode 0 = Manual
    assert (mode, state, feed, name, operation) == (2, 2, 75.0, "CHAN1", 0)
    assert program.Text == "Initializing"
    http.put("/api/machine/override", json={"feed": 100.0})

"""OPC 40001-101 result transfer (design.md §10.3): an asyncua client calls GetLatestResult and
GetResultById after a measurement of a job's part and receives the part and its characteristics
as the JSON API gives them; a ResultReadyEvent follows each measurement of a part."""

from __future__ import annotations

import asyncio

import pytest
from asyncua import ua
from hmi_testdata import PROBE_LENGTH
from opc_kit import opc_client, run

RESULT_URI = "http://opcfoundation.org/UA/Machinery/Result/"
LIMITS = {"position Z": {"nominal": -120.0, "lower": -120.5, "upper": -119.5}}


def ok(response, status: int = 200):
    assert response.status_code == status, response.text
    return response.json()


def measure_top_face(live) -> dict:
    """A set edge Z- on the block's top face (z = -120 in the MCS), measure only."""
    ok(live.http.post("/api/machine/goto", json={"Z": -116.0 + PROBE_LENGTH, "X": 350.0, "Y": 210.0,
                                                 "coords": "MCS"}))
    session = ok(live.http.post("/api/measure", json={"task": "edge.set", "target": "measure_only",
                                                      "params": {"axis": "Z", "direction": "-", "setpoint": -120.0}}))
    answer = ok(live.http.post(f"/api/measure/{session['id']}/start", json={}))
    ok(live.http.post("/api/machine/goto", json={"Z": 0.0, "coords": "MCS"}))
    return answer


async def result_management(client):
    idx = await client.get_namespace_index("urn:jog-measure-hmi")
    rns = await client.get_namespace_index(RESULT_URI)
    await client.load_data_type_definitions()
    node = await client.nodes.objects.get_child([f"{idx}:JogMeasure", f"{idx}:ResultManagement"])
    return node, rns


def test_get_latest_result_carries_the_part_and_its_characteristics(live):
    job = ok(live.http.put("/api/job", json={"part_number": "OPC-1", "order": "MES-7", "serial": "S-001",
                                             "characteristics": LIMITS}))
    answer = measure_top_face(live)
    part = ok(live.http.get(f"/api/parts/{job['part_id']}"))
    (expected,) = part["characteristics"]
    assert expected["log_id"] == answer["log_id"] and expected["verdict"] == "ok"

    async def call():
        async with opc_client(live.opc_url) as (client, _idx):
            node, rns = await result_management(client)
            type_definition = await node.read_type_definition()
            latest = await node.call_method(f"{rns}:GetLatestResult", ua.Variant(1000, ua.VariantType.Int32))
            by_id = await node.call_method(f"{rns}:GetResultById", str(part["id"]),
                                           ua.Variant(1000, ua.VariantType.Int32))
            unknown = await node.call_method(f"{rns}:GetResultById", "999999", ua.Variant(0, ua.VariantType.Int32))
            return type_definition, rns, latest, by_id, unknown

    type_definition, rns, latest, by_id, unknown = run(call())
    assert type_definition == ua.NodeId(1004, rns)                    # ResultManagementType
    for handle, result, error in (latest, by_id):
        assert error == 0 and handle == part["id"]
        meta = result.ResultMetaData
        assert (meta.ResultId, meta.ProductId, meta.PartId, meta.JobId) == (str(part["id"]), "OPC-1", "S-001", "MES-7")
        assert meta.ResultEvaluation == 1 and meta.IsPartial is True    # OK; the job's part is still open
        (content,) = result.ResultContent           # BaseDataType[]: Variants holding the structures
        characteristic = content.Value
        assert characteristic.Name == "position Z" and characteristic.Verdict == "ok"
        assert characteristic.Actual == pytest.approx(expected["actual"], abs=1e-12)
        assert characteristic.Actual == pytest.approx(answer["result"]["position"]["Z"], abs=1e-12)
        assert (characteristic.LowerLimit, characteristic.UpperLimit, characteristic.Nominal) == (-120.5, -119.5, -120.0)
        assert characteristic.Evaluation == 1 and characteristic.LogId == answer["log_id"]
    assert unknown[2] == -2
    assert live.http.delete("/api/job").status_code == 204


def test_a_result_ready_event_follows_a_measurement_of_a_part(live):
    job = ok(live.http.put("/api/job", json={"part_number": "OPC-2", "characteristics": LIMITS}))

    async def listen():
        async with opc_client(live.opc_url) as (client, _idx):
            node, _rns = await result_management(client)
            heard: asyncio.Queue = asyncio.Queue()

            class Handler:
                def event_notification(self, event):
                    heard.put_nowait(event)

            subscription = await client.create_subscription(50, Handler())
            await subscription.subscribe_events(node)
            await asyncio.to_thread(measure_top_face, live)
            while True:
                event = await asyncio.wait_for(heard.get(), timeout=10)
                fields = event.get_event_props_as_fields_dict()
                if fields["Message"].Value.Text.startswith("result "):
                    return fields

    fields = run(listen())
    assert f"result {job['part_id']} of OPC-2" in fields["Message"].Value.Text
    assert live.http.delete("/api/job").status_code == 204

"""Another scenario while clients are connected (here one without the rotary axis C): the
JogMeasure nodes follow the machine's axes; none is left that nobody updates."""

from __future__ import annotations

import asyncio
import time

import httpx
from asyncua import ua
from hmi_testdata import TEST_SCENARIO
from live import free_port, serve
from opc_kit import node, opc_client, run


async def children(client, idx, *path) -> dict:
    parent = await node(client, idx, *path)
    return {(await c.read_browse_name()).Name: await c.read_value() for c in await parent.get_children()}


def test_the_nodes_follow_a_scenario_with_other_axes(tmp_path):
    opc_port = free_port()
    with_c = {**TEST_SCENARIO, "rotary_axes": {"C": {}}}
    with serve(tmp_path, with_c, start_timeout_s=90.0, settings={"opcua_port": opc_port}) as url, \
            httpx.Client(base_url=url, timeout=20) as http:
        opc_url = f"opc.tcp://127.0.0.1:{opc_port}"
        assert "C" in http.get("/api/machine").json()["mcs"]

        async def read(expected_axes: set[str]):
            async with opc_client(opc_url) as (client, idx):
                deadline = time.monotonic() + 5.0
                while True:
                    try:            # while the server rebuilds, a browsed node may be gone at its read
                        found = (await children(client, idx, "Machine", "MCS"),
                                 await children(client, idx, "Machine", "WCS"),
                                 await children(client, idx, "ZeroOffsets", "G54", "Trans"))
                    except ua.UaStatusCodeError as rebuilding:
                        if time.monotonic() > deadline:
                            raise AssertionError("the nodes were not rebuilt within 5 s") from rebuilding
                        await asyncio.sleep(0.05)
                        continue
                    if set(found[0]) == set(found[2]) == expected_axes or time.monotonic() > deadline:
                        return found
                    await asyncio.sleep(0.05)

        mcs, _wcs, trans = run(read({"X", "Y", "Z", "C"}))
        assert "C" in mcs and "C" in trans
        assert http.post("/api/sim/scenario", json=TEST_SCENARIO).status_code == 200
        machine = http.get("/api/machine").json()
        assert set(machine["mcs"]) == {"X", "Y", "Z"}
        mcs, wcs, trans = run(read(set(machine["mcs"])))
        assert mcs == machine["mcs"] and set(wcs) == set(machine["wcs"]) and set(trans) == {"X", "Y", "Z"}

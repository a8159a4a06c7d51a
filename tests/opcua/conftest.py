"""A live HMI with its OPC UA endpoint (uvicorn in a thread, as tests/live.py) and the users of
opc_kit. One server per module: the start of asyncua's address space takes a second or more."""

from __future__ import annotations

import httpx
import pytest
from hmi_testdata import TEST_SCENARIO
from live import free_port, serve
from opc_kit import Live, add_users


@pytest.fixture(scope="module")
def live(tmp_path_factory):
    opc_port = free_port()
    built = {}

    def prepare(app):
        built["app"], built["token"] = app, add_users(app)

    with serve(tmp_path_factory.mktemp("opcua"), TEST_SCENARIO, start_timeout_s=90.0,
               settings={"opcua_port": opc_port}, prepare=prepare) as url:
        headers = {"Authorization": f"Bearer {built['token']}"}
        with httpx.Client(base_url=url, headers=headers, timeout=10) as http:
            yield Live(http, f"opc.tcp://127.0.0.1:{opc_port}", built["app"])

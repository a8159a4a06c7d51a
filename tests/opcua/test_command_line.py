"""``python -m app --opcua PORT [--opcua-umati] [--mtconnect PORT]`` (design.md §9.7): parsed,
refused in one line when a port cannot be served, and served by the real command."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import time
from pathlib import Path

import httpx
from asyncua import Client
from live import free_port
from opc_kit import run

from app.__main__ import endpoint_problem, parse_args, settings_from_args

ROOT = Path(__file__).resolve().parents[2]


def test_the_options_are_parsed():
    settings = settings_from_args(parse_args(["--opcua", "4840", "--opcua-umati", "--mtconnect", "7878"]))
    assert (settings.opcua_port, settings.opcua_umati, settings.mtconnect_port) == (4840, True, 7878)
    plain = settings_from_args(parse_args([]))
    assert (plain.opcua_port, plain.opcua_umati, plain.mtconnect_port) == (None, False, None)


def test_a_port_that_cannot_be_served_is_one_line():
    with socket.create_server(("127.0.0.1", 0)) as taken:
        port = taken.getsockname()[1]
        problem = endpoint_problem(settings_from_args(parse_args(["--opcua", str(port)])))
        assert problem == f"OPC UA port {port} on 127.0.0.1 is in use by another program; choose another with --opcua PORT"
        problem = endpoint_problem(settings_from_args(parse_args(["--mtconnect", str(port)])))
        assert "MTConnect port" in problem and "--mtconnect PORT" in problem
    assert "is the HTTP port" in endpoint_problem(settings_from_args(parse_args(["--port", "8123", "--opcua", "8123"])))
    assert "both ask for port 9000" in endpoint_problem(
        settings_from_args(parse_args(["--opcua", "9000", "--mtconnect", "9000"])))
    assert endpoint_problem(settings_from_args(parse_args(["--opcua", str(free_port())]))) is None


def test_the_command_serves_opc_ua_beside_http(tmp_path):
    http_port, opc_port = free_port(), free_port()
    env = {k: v for k, v in os.environ.items() if not k.startswith("HMI_")}
    server = subprocess.Popen([sys.executable, "-m", "app", "--port", str(http_port), "--opcua", str(opc_port),
                               "--db", str(tmp_path / "hmi.db")], cwd=ROOT, env=env,
                              stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        base = f"http://127.0.0.1:{http_port}"
        deadline = time.monotonic() + 90
        while True:
            assert server.poll() is None, server.stderr.read()
            try:
                if httpx.get(f"{base}/api/machine", timeout=2).status_code == 200:
                    break
            except httpx.HTTPError:
                pass
            assert time.monotonic() < deadline, "the HMI did not start"
            time.sleep(0.2)
        machine = httpx.get(f"{base}/api/machine").json()

        async def read():
            async with Client(f"opc.tcp://127.0.0.1:{opc_port}", timeout=10) as client:
                idx = await client.get_namespace_index("urn:jog-measure-hmi")
                leaf = await client.nodes.objects.get_child([f"{idx}:JogMeasure", f"{idx}:Machine",
                                                             f"{idx}:MCS", f"{idx}:Z"])
                return await leaf.read_value()

        assert run(read()) == machine["mcs"]["Z"]
    finally:
        server.terminate()
        server.wait(timeout=20)
    assert server.returncode in (0, -15)


def test_the_start_says_where_the_endpoints_listen():
    from app.__main__ import endpoint_lines

    settings = settings_from_args(parse_args(["--opcua", "4840", "--opcua-umati", "--mtconnect", "7878"]))
    assert endpoint_lines(settings) == [
        "OPC UA at opc.tcp://127.0.0.1:4840 with the umati MachineTool instance (loading), namespace urn:jog-measure-hmi",
        "MTConnect SHDR adapter at 127.0.0.1:7878"]
    assert endpoint_lines(settings_from_args(parse_args([]))) == []

"""The MTConnect SHDR adapter (``--mtconnect PORT``) as an agent sees it: the whole state on
connect, equal to the JSON API, a jog within a second, the heartbeat, alarms as conditions."""

from __future__ import annotations

import re
import socket
import threading
import time
from types import SimpleNamespace

import httpx
import pytest
from hmi_testdata import TEST_SCENARIO
from live import free_port, serve
from waiting import wait_until

from app.mtconnect.adapter import ShdrAdapter
from app.mtconnect.items import conditions, offsets_table


@pytest.fixture(scope="module")
def shdr(tmp_path_factory):
    port = free_port()
    with serve(tmp_path_factory.mktemp("mtconnect"), TEST_SCENARIO, settings={"mtconnect_port": port}) as url:
        with httpx.Client(base_url=url, timeout=10) as http:
            yield http, port


WHOLE_STATE = {"avail", "mode", "execution", "Xact", "system", "woffsets"}   # a few of each kind of line


class Agent:
    """A minimal agent: reads SHDR lines and keeps the newest value of each data item."""

    def __init__(self, port: int):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=5)
        self.buffer = b""
        self.values: dict[str, str] = {}
        self.lines: list[str] = []

    def read_until(self, predicate, timeout_s: float = 3.0) -> float:
        started = time.monotonic()
        while not predicate():
            left = timeout_s - (time.monotonic() - started)
            if left <= 0:
                raise AssertionError(f"not within {timeout_s} s; last lines {self.lines[-3:]}")
            self.sock.settimeout(left)
            try:
                data = self.sock.recv(65536)
            except TimeoutError:
                continue
            assert data, "the adapter closed the connection"
            self.buffer += data
            *whole, self.buffer = self.buffer.split(b"\n")
            for raw in whole:
                self._take(raw.decode())
        return time.monotonic() - started

    def _take(self, line: str) -> None:
        self.lines.append(line)
        if line.startswith("* "):
            return
        fields = line.split("|")[1:]
        if fields[0] in ("system", "woffsets"):     # a condition, a table: one item per line
            self.values[fields[0]] = "|".join(fields[1:])
            return
        for key, value in zip(fields[::2], fields[1::2], strict=True):
            self.values[key] = value

    def close(self):
        self.sock.close()


def test_an_agent_gets_the_state_of_the_json_api_and_a_jog_within_a_second(shdr):
    http, port = shdr
    agent = Agent(port)
    try:
        agent.read_until(lambda: WHOLE_STATE <= agent.values.keys())
        machine = http.get("/api/machine").json()
        for axis, value in machine["mcs"].items():
            assert float(agent.values[f"{axis}act"]) == pytest.approx(value, abs=1e-4)
        assert agent.values["mode"] == "MANUAL" and agent.values["execution"] == "READY"
        assert agent.values["avail"] == "AVAILABLE" and agent.values["system"] == "NORMAL||||"
        assert agent.values["woffset"] == machine["active_offset"]
        target = machine["mcs"]["Y"] - 3.0
        assert http.post("/api/machine/jog", json={"axis": "Y", "distance": -3.0}).status_code == 200
        agent.read_until(lambda: abs(float(agent.values["Yact"]) - target) < 1e-4, timeout_s=5.0)
    finally:
        agent.close()


class _Stalling:
    """Services whose machine cannot be read until ``ready`` is set (a controller still starting):
    counts the reads, so a test knows the adapter went round its loop."""

    def __init__(self):
        self.ready = threading.Event()
        self.reads = 0
        self.machine = self
        self.offsets = self
        self.db = SimpleNamespace(generation=1)

    def status(self) -> dict:
        self.reads += 1
        if not self.ready.is_set():
            raise ConnectionError("controller not up yet")
        return {"mode": "JOG", "program_state": "reset", "mcs": {"X": 1.0}, "wcs": {"X": 1.0},
                "feed_override": 100.0, "tool": None, "active_offset": "G54",
                "alarms": [{"code": 61302, "text": "collision"}]}

    def list(self) -> dict:
        return {"G54": {"trans": {"X": 2.0}}}


def test_an_agent_that_connects_before_the_first_read_gets_the_whole_state():
    services = _Stalling()
    adapter = ShdrAdapter(services, "127.0.0.1", free_port())
    adapter.start()
    try:
        agent = Agent(adapter._port)
        reads = services.reads
        wait_until(lambda: services.reads >= reads + 2, "the adapter's loop went round (accepting the agent)")
        services.ready.set()
        agent.read_until(lambda: WHOLE_STATE <= agent.values.keys())
        assert agent.values["system"] == "FAULT|61302|||collision"
        assert agent.values["woffsets"] == "G54={X=2.0000}" and agent.values["Xact"] == "1.0000"
        agent.close()
    finally:
        adapter.stop()


def test_the_heartbeat_is_answered(shdr):
    _http, port = shdr
    agent = Agent(port)
    try:
        agent.sock.sendall(b"* PING\n")
        agent.read_until(lambda: any(line.startswith("* PONG ") for line in agent.lines))
        pong = next(line for line in agent.lines if line.startswith("* PONG "))
        assert int(pong.split()[2]) > 0
    finally:
        agent.close()


def test_an_alarm_is_a_fault_condition_until_reset(shdr):
    http, port = shdr
    limit = TEST_SCENARIO["machine"]["limits"]["X"][1]
    agent = Agent(port)
    try:
        agent.read_until(lambda: "system" in agent.values)
        answer = http.post("/api/machine/jog", json={"axis": "X", "distance": 2 * limit})
        assert answer.status_code == 409
        code = answer.json()["error"]["message"].split()[0]
        agent.read_until(lambda: agent.values["system"].startswith(f"FAULT|{code}|"))
        http.post("/api/machine/reset")
        agent.read_until(lambda: agent.values["system"] == "NORMAL||||")
    finally:
        agent.close()


def test_a_g54_write_reaches_the_offsets_table(shdr):
    http, port = shdr
    assert http.put("/api/offsets/G54", json={"trans": {"X": 10.5, "Y": -2.0, "Z": 0.0},
                                              "fine": {"X": 0.25}}).status_code == 200
    agent = Agent(port)
    try:
        def g54() -> list[str]:
            return agent.values.get("woffsets", "G54={}").split("G54={")[1].split("}")[0].split()

        # the snapshot may precede the write by one period; the change follows it then
        agent.read_until(lambda: "X=10.7500" in g54())        # coarse + fine, as the NC adds them
        assert "Y=-2.0000" in g54()
    finally:
        agent.close()


def test_conditions_name_each_new_alarm_and_each_gone_one():
    assert conditions(set(), None) == ["system|NORMAL||||"]
    raised = conditions({(20070, "limit")}, set())
    assert raised == ["system|FAULT|20070|||limit"]
    both = {(20070, "limit"), (61303, "probe")}
    assert conditions({(61303, "probe")}, both) == ["system|NORMAL|20070|||"]
    assert conditions(set(), {(61303, "probe")}) == ["system|NORMAL||||"]
    assert offsets_table({"G54": {"trans": {"X": 1.0}, "fine": {"X": 0.5}, "rot": {"Z": 0.0}}}) == "G54={X=1.5000}"


# MTConnect Part 1 (adapter protocol, SHDR): a condition line is
# <timestamp>|<id>|<level>|<native code>|<native severity>|<qualifier>|<message>, the level one of
# UNAVAILABLE NORMAL WARNING FAULT, the qualifier empty or HIGH or LOW
SHDR_CONDITION = re.compile(r"^(?P<id>[^|]+)\|(?P<level>UNAVAILABLE|NORMAL|WARNING|FAULT)\|(?P<code>[^|]*)"
                            r"\|(?P<severity>[^|]*)\|(?P<qualifier>|HIGH|LOW)\|(?P<message>[^\n]*)$")


def test_condition_lines_follow_the_shdr_grammar():
    active = {(20070, "limit | X+"), (61302, "collision")}
    lines = conditions(active, None) + conditions(set(), active) + conditions(active, set()) \
        + conditions({(61302, "collision")}, active)
    for line in lines:
        match = SHDR_CONDITION.match(line)
        assert match, line
        assert match["message"].count("|") == 0
    faults = [SHDR_CONDITION.match(line) for line in conditions(active, None)]
    assert [(m["level"], m["code"], m["qualifier"]) for m in faults] == [("FAULT", "20070", ""), ("FAULT", "61302", "")]

"""The OPC UA endpoint against the JSON API of the same process (design.md §9.7): browse paths,
values equal to ``GET /api/machine`` / ``/api/offsets`` / ``/api/log``, live subscriptions,
writes guarded by the access levels, alarms as events."""

from __future__ import annotations

import asyncio
import json
import time
from pathlib import Path

import pytest
from asyncua import ua
from hmi_testdata import PROBE_LENGTH, TEST_SCENARIO
from opc_kit import USERS, node, opc_client, run, wait_for
from waiting import wait_until

from app.opcua.trust import TrustList


def ok(response, status: int = 200):
    assert response.status_code == status, response.text
    return response.json()


def test_browse_paths_and_values_equal_the_json_api(live):
    ok(live.http.put("/api/offsets/G54", json={"trans": {"X": 250.125, "Y": -150.5, "Z": -120.0},
                                                "fine": {"X": 0.002}, "rot": {"Z": 1.5}}))
    ok(live.http.post("/api/machine/activate", json={"offset": "G54"}))
    machine = ok(live.http.get("/api/machine"))
    g54 = ok(live.http.get("/api/offsets/G54"))
    names = list(ok(live.http.get("/api/offsets")))

    async def check():
        async with opc_client(live.opc_url) as (client, idx):
            root = await client.nodes.objects.get_child(f"{idx}:JogMeasure")
            children = {(await c.read_browse_name()).Name for c in await root.get_children()}
            assert {"Machine", "ZeroOffsets", "LastMeasurement"} <= children
            offsets = await node(client, idx, "ZeroOffsets")
            assert [(await c.read_browse_name()).Name for c in await offsets.get_children()] == names
            await asyncio.sleep(0.2)          # one update period after the activation
            for coords in ("MCS", "WCS"):
                for axis, value in machine[coords.lower()].items():
                    assert await (await node(client, idx, "Machine", coords, axis)).read_value() == value
            assert await (await node(client, idx, "Machine", "ActiveOffset")).read_value() == "G54"
            assert json.loads(await (await node(client, idx, "Machine", "Alarms")).read_value()) == []
            for part, key in (("Trans", "trans"), ("Fine", "fine"), ("Rot", "rot")):
                for axis, value in g54[key].items():
                    leaf = await node(client, idx, "ZeroOffsets", "G54", part, axis)
                    assert await leaf.read_value() == value, (part, axis)
                    assert await leaf.read_data_type_as_variant_type() == ua.VariantType.Double

    run(check())
    # the tip in G54 is where the frame puts it: x_wcs = Rz(-1.5°) (x_mcs - T), ball centre L below
    assert machine["wcs"]["Z"] == pytest.approx(machine["mcs"]["Z"] - PROBE_LENGTH - (-120.0))
    ok(live.http.post("/api/machine/activate", json={"offset": "G500"}))


def test_a_subscription_hears_a_jog_within_a_second(live):
    before = ok(live.http.get("/api/machine"))["mcs"]["X"]

    async def check():
        async with opc_client(live.opc_url) as (client, idx):
            heard: list[tuple[float, float]] = []

            class Handler:
                def datachange_notification(self, _node, value, _data):
                    heard.append((time.monotonic(), value))

            subscription = await client.create_subscription(50, Handler())
            await subscription.subscribe_data_change(await node(client, idx, "Machine", "MCS", "X"))
            await wait_for(lambda: heard)                 # the initial value
            assert heard[-1][1] == before
            jogged = time.monotonic()
            answer = await asyncio.to_thread(live.http.post, "/api/machine/jog", json={"axis": "X", "distance": 2.5})
            target = ok(answer)["mcs"]["X"]
            await wait_for(lambda: heard[-1][1] == target, timeout_s=1.0)
            return heard[-1][0] - jogged, target

    latency, target = run(check())
    assert target == pytest.approx(before + 2.5)
    assert latency < 1.0
    ok(live.http.post("/api/machine/jog", json={"axis": "X", "distance": -2.5}))


def test_a_zero_offset_write_needs_a_user_with_the_level(live):
    start = ok(live.http.get("/api/offsets/G55"))["trans"]["Y"]

    async def write(user=None, password=None, value=12.5):
        async with opc_client(live.opc_url, user, password) as (client, idx):
            leaf = await node(client, idx, "ZeroOffsets", "G55", "Trans", "Y")
            try:
                await leaf.write_value(ua.DataValue(ua.Variant(value, ua.VariantType.Double)))
            except ua.UaStatusCodeError as exc:
                return exc.code, await leaf.read_value()
            return ua.StatusCodes.Good, await leaf.read_value()

    # anonymous, and anna with level 3 where writing zero offsets needs 2: refused, nothing written
    assert run(write()) == (ua.StatusCodes.BadUserAccessDenied, start)
    assert run(write("anna", USERS["anna"][0])) == (ua.StatusCodes.BadUserAccessDenied, start)
    assert ok(live.http.get("/api/offsets/G55"))["trans"]["Y"] == start
    # a read-only node refuses everybody
    async def write_mcs():
        async with opc_client(live.opc_url, "serv", USERS["serv"][0]) as (client, idx):
            with pytest.raises(ua.UaStatusCodeError) as refused:
                await (await node(client, idx, "Machine", "MCS", "X")).write_value(1.0)
            return refused.value.code
    assert run(write_mcs()) == ua.StatusCodes.BadUserAccessDenied
    # serv (level 2): written through the offsets service, audited with their name
    assert run(write("serv", USERS["serv"][0])) == (ua.StatusCodes.Good, 12.5)
    assert ok(live.http.get("/api/offsets/G55"))["trans"]["Y"] == 12.5
    row = ok(live.http.get("/api/audit", params={"limit": 1, "kind": "offset"}))[0]
    assert (row["offset"], row["who"], row["level"], row["source"]) == ("G55", "user:serv", 2, "opcua")
    assert row["after"]["trans"]["Y"] == 12.5 and row["before"]["trans"]["Y"] == start
    # a value the offsets service refuses (out of range) is refused the same way, nothing written
    code, shown = run(write("serv", USERS["serv"][0], value=1e9))
    assert (code, shown) == (ua.StatusCodes.BadOutOfRange, 12.5)


def test_a_zero_offset_write_takes_numbers_only_as_the_json_api_does(live):
    """issue 25 item 3: an OPC UA write goes through the JSON API's number check (app/checks.py):
    no boolean, no text, nothing infinite or NaN, no integer beyond the range; nothing written."""
    start = ok(live.http.get("/api/offsets/G56"))["trans"]["Z"]

    async def write(variant):
        async with opc_client(live.opc_url, "serv", USERS["serv"][0]) as (client, idx):
            leaf = await node(client, idx, "ZeroOffsets", "G56", "Trans", "Z")
            try:
                await leaf.write_value(ua.DataValue(variant))
            except ua.UaStatusCodeError as exc:
                return exc.code
            return ua.StatusCodes.Good

    refused = {
        "boolean": (ua.Variant(True, ua.VariantType.Boolean), ua.StatusCodes.BadTypeMismatch),
        "text": (ua.Variant("12", ua.VariantType.String), ua.StatusCodes.BadTypeMismatch),
        "nan": (ua.Variant(float("nan"), ua.VariantType.Double), ua.StatusCodes.BadOutOfRange),
        "infinity": (ua.Variant(float("inf"), ua.VariantType.Double), ua.StatusCodes.BadOutOfRange),
        "1e300": (ua.Variant(1e300, ua.VariantType.Double), ua.StatusCodes.BadOutOfRange),
        "UInt64 max": (ua.Variant(2**64 - 1, ua.VariantType.UInt64), ua.StatusCodes.BadOutOfRange),
        "Int64 min": (ua.Variant(-2**63, ua.VariantType.Int64), ua.StatusCodes.BadOutOfRange),
    }
    answers = {what: run(write(variant)) for what, (variant, _code) in refused.items()}
    assert answers == {what: code for what, (_variant, code) in refused.items()}
    assert ok(live.http.get("/api/offsets/G56"))["trans"]["Z"] == start
    # a whole number within the range is a number: stored as the float it is
    assert run(write(ua.Variant(-42, ua.VariantType.Int32))) == ua.StatusCodes.Good
    assert ok(live.http.get("/api/offsets/G56"))["trans"]["Z"] == -42.0


def test_a_wrong_password_gets_no_session(live):
    async def connect():
        async with opc_client(live.opc_url, "serv", "not-the-password"):
            pass

    with pytest.raises(ua.UaStatusCodeError) as refused:
        run(connect())
    assert refused.value.code in (ua.StatusCodes.BadUserAccessDenied, ua.StatusCodes.BadIdentityTokenRejected)


def test_an_alarm_is_an_event_raised_and_cleared(live):
    limit = TEST_SCENARIO["machine"]["limits"]["X"][1]

    async def check():
        async with opc_client(live.opc_url) as (client, idx):
            events = []

            class Handler:
                def event_notification(self, event):
                    events.append(event.get_event_props_as_fields_dict())

            etype = await client.nodes.base_event_type.get_child(f"{idx}:HmiAlarmEventType")
            subscription = await client.create_subscription(50, Handler())
            await subscription.subscribe_events(client.nodes.server, etype)
            answer = await asyncio.to_thread(live.http.post, "/api/machine/jog", json={"axis": "X", "distance": 2 * limit})
            alarm = ok(answer, 409)["error"]
            await wait_for(lambda: events, timeout_s=1.0)
            raised = events[0]
            await asyncio.to_thread(live.http.post, "/api/machine/reset")
            await wait_for(lambda: len(events) >= 2, timeout_s=1.0)
            alarms_json = await (await node(client, idx, "Machine", "Alarms")).read_value()
            return alarm, raised, events[1], alarms_json

    alarm, raised, cleared, alarms_json = run(check())
    code = raised["AlarmCode"].Value
    assert alarm["message"].startswith(str(code))
    assert raised["Active"].Value is True and raised["Severity"].Value == 700
    assert raised["Message"].Value.Text == alarm["message"]
    assert cleared["AlarmCode"].Value == code and cleared["Active"].Value is False
    assert json.loads(alarms_json) == ok(live.http.get("/api/machine"))["alarms"] == []
    ok(live.http.post("/api/machine/goto", json={"X": 100.0, "coords": "MCS"}))


def test_last_measurement_is_the_newest_log_entry(live):
    # a set edge Z- on the block's top face, measure only (the part's top is z = -120 in the MCS)
    ok(live.http.post("/api/machine/goto", json={"Z": -116.0 + PROBE_LENGTH, "X": 350.0, "Y": 210.0,
                                                 "coords": "MCS"}))
    session = ok(live.http.post("/api/measure", json={"task": "edge.set", "target": "measure_only",
                                                      "params": {"axis": "Z", "direction": "-", "setpoint": 0.0}}))
    ok(live.http.post(f"/api/measure/{session['id']}/start", json={}))
    newest = ok(live.http.get("/api/log", params={"limit": 1}))[0]

    async def read():
        async with opc_client(live.opc_url) as (client, idx):
            leaf = await node(client, idx, "LastMeasurement")
            deadline = time.monotonic() + 1.0
            while json.loads(await leaf.read_value()) != newest and time.monotonic() < deadline:
                await asyncio.sleep(0.05)
            return json.loads(await leaf.read_value())

    assert run(read()) == newest
    ok(live.http.post("/api/machine/goto", json={"Z": 0.0, "coords": "MCS"}))


def test_the_endpoints_offer_the_documented_policies_and_an_encrypted_session_writes(live, tmp_path):
    from asyncua import Client

    async def check():
        probe = Client(live.opc_url, timeout=10)
        offered = {(e.SecurityPolicyUri.rsplit("#", 1)[1], e.SecurityMode.name)
                   for e in await probe.connect_and_get_server_endpoints()}
        client = Client(live.opc_url, timeout=10)
        client.application_uri = "urn:tests:opcua-client"
        cert, key = await client.setup_self_signed_certificate(tmp_path / "client_key.pem", tmp_path / "client_cert.der")
        TrustList(live.app.state.services.db.path.parent).add(Path(cert))        # the administrator trusted it
        await client.set_security_string(f"Aes256Sha256RsaPss,SignAndEncrypt,{cert},{key}")
        client.set_user("serv")
        client.set_password(USERS["serv"][0])
        async with client:
            idx = await client.get_namespace_index("urn:jog-measure-hmi")
            leaf = await node(client, idx, "ZeroOffsets", "G56", "Rot", "Z")
            await leaf.write_value(ua.DataValue(ua.Variant(-0.75, ua.VariantType.Double)))
        return offered

    offered = run(check())
    assert offered == {("None", "None_"), ("Basic256Sha256", "Sign"), ("Basic256Sha256", "SignAndEncrypt"),
                       ("Aes256_Sha256_RsaPss", "Sign"), ("Aes256_Sha256_RsaPss", "SignAndEncrypt")}
    assert ok(live.http.get("/api/offsets/G56"))["rot"]["Z"] == -0.75


def test_the_level_is_read_again_at_every_write(live):
    services = live.app.state.services

    async def write_twice():
        async with opc_client(live.opc_url, "serv", USERS["serv"][0]) as (client, idx):
            leaf = await node(client, idx, "ZeroOffsets", "G57", "Trans", "X")
            await leaf.write_value(ua.DataValue(ua.Variant(3.0, ua.VariantType.Double)))
            # the offsets level is raised to 1 (manufacturer) while serv (2) stays signed in
            await asyncio.to_thread(services.settings.put, {"level_offsets": 1}, "tests")
            with pytest.raises(ua.UaStatusCodeError) as refused:
                await leaf.write_value(ua.DataValue(ua.Variant(4.0, ua.VariantType.Double)))
            return refused.value.code

    try:
        assert run(write_twice()) == ua.StatusCodes.BadUserAccessDenied
    finally:
        services.settings.put({"level_offsets": 2}, source="tests")
    assert ok(live.http.get("/api/offsets/G57"))["trans"]["X"] == 3.0


def test_failed_opc_ua_sign_ins_hold_only_opc_ua_of_that_computer(live):
    """Issue 25 item 2: five wrong OPC UA passwords make this computer wait on OPC UA (the right
    password too, for a second), while HTTP sign-in of the same user from it goes on; the wait ends."""
    import httpx

    async def connect(password: str):
        async with opc_client(live.opc_url, "serv", password):
            return "session"

    for _ in range(5):
        with pytest.raises(ua.UaStatusCodeError):
            run(connect("not-the-password"))
    with pytest.raises(ua.UaStatusCodeError):
        run(connect(USERS["serv"][0]))                      # this computer waits now, right or wrong
    with httpx.Client(base_url=live.http.base_url) as browser:
        signed = browser.post("/api/session", json={"user": "serv", "password": USERS["serv"][0]})
        assert signed.status_code == 200 and signed.json()["name"] == "serv"

    def right_password_signs_in():
        try:
            return run(connect(USERS["serv"][0]))
        except ua.UaStatusCodeError:
            return None

    assert wait_until(right_password_signs_in, "the OPC UA wait ends", 30) == "session"


def test_an_untrusted_client_certificate_is_refused_and_kept_until_the_admin_trusts_it(live, tmp_path):
    """Issue 25 item 5: unknown client certificates are rejected (Basic256Sha256 SignAndEncrypt);
    the refused one waits in pki/rejected; ``python -m app opcua trust add`` lets it in."""
    import subprocess
    import sys

    from asyncua import Client

    data_dir = live.app.state.services.db.path.parent

    async def connect(cert, key):
        client = Client(live.opc_url, timeout=10)
        client.application_uri = "urn:tests:untrusted-client"
        await client.set_security_string(f"Basic256Sha256,SignAndEncrypt,{cert},{key}")
        async with client:
            return await (await node(client, await client.get_namespace_index("urn:jog-measure-hmi"),
                                     "Machine", "ActiveOffset")).read_value()

    async def make():
        client = Client(live.opc_url, timeout=10)
        client.application_uri = "urn:tests:untrusted-client"
        return await client.setup_self_signed_certificate(tmp_path / "key.pem", tmp_path / "cert.der")

    cert, key = run(make())
    with pytest.raises(Exception) as refused:            # the channel or the session is refused
        run(connect(cert, key))
    assert "Untrusted" in repr(refused.value) or "BadCertificate" in repr(refused.value) \
        or isinstance(refused.value, (ConnectionError, TimeoutError, asyncio.TimeoutError)), repr(refused.value)
    rejected = TrustList(data_dir).rejected
    kept = list(rejected.glob("*.der"))
    assert len(kept) == 1
    added = subprocess.run([sys.executable, "-m", "app", "--db", str(data_dir / "hmi.db"), "opcua", "trust", "add",
                            str(kept[0])], capture_output=True, text=True, timeout=60)
    assert added.returncode == 0 and added.stdout.startswith("trusted "), added.stderr
    assert isinstance(run(connect(cert, key)), str)
    listed = subprocess.run([sys.executable, "-m", "app", "--db", str(data_dir / "hmi.db"), "opcua", "trust",
                             "list"], capture_output=True, text=True, timeout=60)
    assert kept[0].stem in listed.stdout and not list(rejected.glob("*.der"))

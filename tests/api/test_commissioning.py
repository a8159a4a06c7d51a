"""The commissioning checks of the measuring cycles (manual ch. 9–10): GET /api/commissioning/checks
and the section on the PLC/service screen, against the manual's values.

Truth is the manual (seed 001_*.txt): §9.1.1 MD 18130 MM_NUM_GUD_NAMES_CHAN "采用JOG中测量：130"
(line ~24760), MD 28082 MM_SYSTEM_FRAME_MASK "位 5: 用于循环的1个系统框架（必须始终在循环时存在）",
§9.3.1 MD 20112 START_MODE_MASK "位6=0"; §9.2 _CVAL[1] = the number of workpiece probe records
_WP[] (3 by default, 61416 "匹配区大小 _TP[ ]/_CVAL"). A control commissioned wrongly in one datum
shows that check failing and every other one passing.
"""

from __future__ import annotations

import copy

from hmi_testdata import TEST_SCENARIO


def checks(client) -> dict[str, dict]:
    response = client.get("/api/commissioning/checks")
    assert response.status_code == 200, response.text
    return {c["id"]: c for c in response.json()["checks"]}


def load(client, machine_data: dict) -> None:
    scenario = copy.deepcopy(TEST_SCENARIO)
    scenario.setdefault("machine", {})["machine_data"] = machine_data
    response = client.post("/api/sim/scenario", json={**scenario, "reset_data": True})
    assert response.status_code == 200, response.text


def failing(found: dict[str, dict]) -> set[str]:
    return {k for k, c in found.items() if c["ok"] is not True}


def test_the_commissioned_simulator_passes_every_check_with_its_section(client):
    answer = client.get("/api/commissioning/checks").json()
    assert answer["ok"] is True and answer["failed"] == 0
    found = {c["id"]: c for c in answer["checks"]}
    assert found["md18130"] == {"id": "md18130", "group": "machine_data", "section": "§9.1.1",
                                "item": "MD 18130 MM_NUM_GUD_NAMES_CHAN", "value": 130, "rule": "at least 130",
                                "ok": True, "alarm": None}
    assert found["cval1"]["item"] == "_CVAL[1]" and found["cval1"]["value"] == 3
    assert found["cval1"]["rule"] == "= the records of _WP (3)" and found["cval1"]["section"] == "§9.2"
    assert {c["section"] for c in answer["checks"]} >= {"§9.1.1", "§9.1.2", "§9.2", "§9.3.1", "§10.3"}


def test_a_wrong_machine_datum_fails_only_its_check(client):
    """MD 18130 = 100 (the value without "Measure in JOG"), MD 28082 without bit 5 (21H -> 1),
    MD 20112 with bit 6 (400H -> 440H): these three fail, the others pass."""
    load(client, {"18130": 100, "28082": 1, "20112": 0x440})
    found = checks(client)
    assert failing(found) == {"md18130", "md28082", "md20112"}
    assert found["md18130"]["value"] == 100 and found["md18130"]["ok"] is False
    assert found["md28082"]["rule"] == "bit 5 = 1" and found["md28082"]["alarm"] == 61016
    assert found["md20112"]["rule"] == "bit 6 = 0"
    answer = client.get("/api/commissioning/checks").json()
    assert answer["ok"] is False and answer["failed"] == 3


def test_a_wrong_gud_fails_only_its_check(client):
    """_CVAL[1] = 2 with 3 records _WP and the JOG probe number _JM_I[1] = 3: _CVAL[1] fails (it
    must count the records) and so does the probe number (beyond _CVAL[1]); the rest pass."""
    assert client.put("/api/nc/variables/_CVAL[1]", json={"value": 2}).status_code == 200
    assert client.put("/api/settings", json={"probe_number": 3}).status_code == 200
    found = checks(client)
    assert failing(found) == {"cval1", "jm_probe"}
    assert found["cval1"]["value"] == 2 and found["cval1"]["rule"] == "= the records of _WP (3)"
    assert found["jm_probe"]["value"] == 3 and found["jm_probe"]["rule"] == "from 1 to _CVAL[1] = 2"
    assert client.put("/api/nc/variables/_CVAL[1]", json={"value": 3}).status_code == 200
    assert failing(checks(client)) == set()


def test_an_unknown_machine_datum_is_refused_and_nothing_changes(client):
    load(client, {"18130": 100})
    scenario = copy.deepcopy(TEST_SCENARIO)
    scenario.setdefault("machine", {})["machine_data"] = {"99999": 1}
    response = client.post("/api/sim/scenario", json={**scenario, "reset_data": True})
    assert 400 <= response.status_code < 500
    assert "machine_data.99999" in response.text
    assert failing(checks(client)) == {"md18130"}


def test_the_service_screen_lists_the_checks_in_chinese_and_german(client):
    load(client, {"18130": 100})
    html = client.get("/plc", params={"lang": "zh"}).text
    assert "开机调试" in html and "至少 130" in html and "未通过" in html and "通过" in html
    assert 'data-commissioning="md18130" data-ok="no"' in html
    assert 'data-commissioning="md18118" data-ok="yes"' in html
    html = client.get("/plc", params={"lang": "de"}).text
    assert "Inbetriebnahme" in html and "mindestens 130" in html and "nicht erfüllt" in html

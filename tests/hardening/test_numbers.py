"""Numbers that are numbers (issue 25 item 3): the cases the issue measured, each refused with a 422
naming the field and the stored data unchanged afterwards."""

from __future__ import annotations

import json

import pytest

from app import checks
from app.errors import InvalidInput

HUGE = 10**400                  # 400 digits: float(HUGE) raises OverflowError
BAD_NUMBERS = [HUGE, -HUGE, True, False, "12", "1e3", None, [1.0], {"v": 1.0}]


def _raw(value) -> str:
    """JSON text of a value, including the ints too long for a float."""
    return json.dumps(value)


def put_raw(client, url: str, body_text: str):
    return client.put(url, content=body_text, headers={"content-type": "application/json"})


@pytest.mark.parametrize("value", BAD_NUMBERS, ids=repr)
@pytest.mark.parametrize("part,axis", [("trans", "X"), ("rot", "Z"), ("fine", "Y")])
def test_offset_component_must_be_a_number(client, value, part, axis):
    before = client.get("/api/offsets/G54").json()
    audit_before = client.get("/api/audit").json()
    response = put_raw(client, "/api/offsets/G54", json.dumps({part: {axis: value}}))
    assert response.status_code == 422, response.text
    assert response.json()["error"]["field"] == f"{part}.{axis}"
    assert client.get("/api/offsets/G54").json() == before
    assert client.get("/api/audit").json() == audit_before


@pytest.mark.parametrize("key", ["measuring_feed", "fast_feed", "measuring_path", "tol_k", "probe_number",
                                 "attempts", "mt_ax"])
@pytest.mark.parametrize("value", [HUGE, True, "12", "1e3", 1e300, float("nan")], ids=repr)
def test_setting_must_be_a_number(client, key, value):
    before = client.get("/api/settings").json()
    text = json.dumps({key: value})          # NaN: Python's JSON extension, as a client may send it
    response = put_raw(client, "/api/settings", text)
    assert response.status_code == 422, response.text
    assert response.json()["error"]["field"] == key
    assert client.get("/api/settings").json() == before


def test_measuring_feed_true_is_not_one_mm_per_min(client):
    """The issue's case: ``{"measuring_feed": true}`` was stored as 1.0 mm/min."""
    response = client.put("/api/settings", json={"measuring_feed": True})
    assert response.status_code == 422
    assert client.get("/api/settings").json()["measuring_feed"] == 300.0      # the default (gud.py)


@pytest.mark.parametrize("name", ["R1", "_EV[9]", "_MV[0]", "_TUL"])
@pytest.mark.parametrize("value", [HUGE, -HUGE, True, 1e300, "1e3"], ids=repr)
def test_nc_variable_must_be_a_number_in_range(client, name, value):
    before = client.get("/api/nc/variables", params={"names": name}).json()
    memories_before = client.get("/api/memories").json()
    response = put_raw(client, f"/api/nc/variables/{name}", json.dumps({"value": value}))
    if value == 1e300 and name in ("R1", "_TUL"):        # a REAL holds 1e300 on the 840D (±1.8e308)
        assert response.status_code == 200
        return
    assert response.status_code == 422, response.text
    assert response.json()["error"]["field"] == "value"
    assert client.get("/api/nc/variables", params={"names": name}).json() == before
    assert client.get("/api/memories").json() == memories_before


def test_ev_memory_same_range_through_nc_and_api(client):
    """``_EV[9] = 1e300`` was stored while /api/memories refused it: both refuse now, both take 0.5."""
    assert client.put("/api/memories/ev/10", json={"value": 1e300}).status_code == 422
    assert client.put("/api/nc/variables/_EV[9]", json={"value": 1e300}).status_code == 422
    assert client.put("/api/nc/variables/_EV[9]", json={"value": 0.5}).status_code == 200
    assert client.get("/api/memories/ev/10").json()["value"] == 0.5


def test_nc_program_cannot_store_what_the_api_refuses(client):
    """An MDA program writing 1001 mm into ``_EV[9]`` (beyond the memories' ±1000 mm) ends in an
    alarm; the memory keeps its value."""
    answer = client.post("/api/nc/run", json={"mda": "_EV[9]=1001\nM30"}).json()
    assert answer["state"] == "alarm", answer
    assert client.get("/api/memories/ev/10").json()["value"] == 0.0


@pytest.mark.parametrize("value", [HUGE, True, "0.01", 1e300], ids=repr)
def test_memory_refuses(client, value):
    response = put_raw(client, "/api/memories/ev/1", json.dumps({"value": value}))
    assert response.status_code == 422
    assert client.get("/api/memories/ev/1").json()["value"] == 0.0


@pytest.mark.parametrize("body", [{"length": HUGE}, {"radius": True}, {"length": "12"}, {"type": 120.0},
                                  {"wear": {"length": HUGE}}, {"wear": {"radius": "1e3"}}], ids=repr)
def test_tool_refuses(client, body):
    before = client.get("/api/tools").json()
    response = put_raw(client, "/api/tools/7", json.dumps(body))
    assert response.status_code == 422, response.text
    assert client.get("/api/tools").json() == before


@pytest.mark.parametrize("body", [{"ball_diameter": HUGE}, {"ball_diameter": True}, {"ball_diameter": "4"},
                                  {"trigger": {"X+": HUGE}}, {"skew": [True, 0.0]}], ids=repr)
def test_probe_refuses(client, body):
    before = client.get("/api/probes/1").json()
    response = put_raw(client, "/api/probes/1", json.dumps(body))
    assert response.status_code == 422, response.text
    assert client.get("/api/probes/1").json() == before


def test_huge_path_numbers_are_a_4xx(client):
    for url in (f"/api/tools/{HUGE}", f"/api/probes/{HUGE}", f"/api/tool-probes/{HUGE}", f"/api/log/{HUGE}",
                f"/api/memories/ev/{HUGE}"):
        assert 400 <= client.get(url).status_code < 500, url


def test_integer_longer_than_python_reads_is_a_4xx(client):
    """5000 digits: beyond Python's int-from-text limit (4300), the JSON parser itself refuses."""
    before = client.get("/api/offsets/G54").json()
    response = put_raw(client, "/api/offsets/G54", '{"trans": {"X": ' + "9" * 5000 + "}}")
    assert 400 <= response.status_code < 500
    assert client.get("/api/offsets/G54").json() == before


# --- the validator itself ------------------------------------------------------------------------

@pytest.mark.parametrize("value", [True, "12", "1e3", None, float("nan"), float("inf"), HUGE, [1]], ids=repr)
def test_number_refuses(value):
    with pytest.raises(InvalidInput) as refused:
        checks.number(value, "f")
    assert refused.value.field == "f"


def test_number_range_and_openness():
    assert checks.number(5, "f", lo=0, hi=5) == 5.0
    with pytest.raises(InvalidInput, match="within 0..5"):
        checks.number(5, "f", lo=0, hi=5, hi_open=True)
    with pytest.raises(InvalidInput):
        checks.number(0, "f", lo=0, lo_open=True)


@pytest.mark.parametrize("value", [True, 3.0, "3", 2**63, HUGE], ids=repr)
def test_integer_refuses(value):
    with pytest.raises(InvalidInput):
        checks.integer(value, "n")


@pytest.mark.parametrize("text,expected", [("12", 12.0), (" -1,5 ", -1.5), ("1e3", 1000.0), ("\u22122", -2.0),
                                           (".5", 0.5)])
def test_parse_number_reads(text, expected):
    assert checks.parse_number(text, "f") == expected


@pytest.mark.parametrize("text", ["１２", "1 2a", "nan", "inf", "", "0x10", "1e999", "1_000", "٣"])
def test_parse_number_refuses(text):
    with pytest.raises(InvalidInput):
        checks.parse_number(text, "f")


def test_json_numbers_names_the_path():
    with pytest.raises(InvalidInput) as refused:
        checks.json_numbers({"a": [1.0, {"b": HUGE}]})
    assert refused.value.field == "a[1].b"

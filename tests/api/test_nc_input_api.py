"""Bounded NC input through the API (issue 24 item 5): a program beyond 1 MiB is 413, an
expression beyond the limits and a fullwidth digit are 422 with line and column; nothing is
stored, nothing moves."""

from __future__ import annotations

import pytest

from app.nc.parser import MAX_BLOCK_CHARS, MAX_PROGRAM_BYTES


def mcs(client):
    return client.get("/api/machine").json()["mcs"]


def test_a_program_beyond_1_mib_is_413_and_not_stored(client):
    text = ("G1 X10 F100\n" * (MAX_PROGRAM_BYTES // 12 + 1))
    answer = client.post("/api/programs", json={"name": "BIG", "text": text})
    assert answer.status_code == 413, answer.text
    assert answer.json()["error"]["code"] == "body_too_large"       # refused before it is read (http_limits)
    assert client.get("/api/programs").json() == []
    assert client.put("/api/programs/BIG", json={"text": text}).status_code == 413
    before = mcs(client)
    answer = client.post("/api/nc/run", json={"mda": text, "wait": False})
    assert answer.status_code == 413
    assert mcs(client) == before and client.get("/api/nc").json()["state"] == "idle"


def test_the_services_count_bytes_not_characters(app):
    """Below the HTTP body limit (a form, a call inside the HMI) the program's own bound holds."""
    from app.errors import TooLarge

    programs = app.state.services.programs
    text = "M30 ; " + "ä" * (MAX_PROGRAM_BYTES // 2)      # fewer characters than bytes
    with pytest.raises(TooLarge) as e:
        programs.create("UMLAUT", text)
    assert e.value.status == 413 and e.value.field == "text"
    assert programs.list() == []


def test_a_huge_expression_is_422_with_line_and_column_and_nothing_moves(client):
    before = mcs(client)
    mda = "G91 G0 X10\nR1=" + "+".join(["1"] * 20_000) + "\nM30"
    answer = client.post("/api/nc/run", json={"mda": mda})
    assert answer.status_code == 422, answer.text
    error = answer.json()["error"]
    assert (error["line"], error["column"]) == (2, MAX_BLOCK_CHARS + 1)
    assert mcs(client) == before


def test_deep_nesting_is_422_with_line_and_column(client):
    mda = "R1=" + "(" * 40 + "1" + ")" * 40
    error = client.post("/api/nc/run", json={"mda": mda}).json()["error"]
    assert (error["line"], error["column"]) == (1, 36)


def test_fullwidth_digits_are_refused_before_anything_moves(client):
    before = mcs(client)
    answer = client.post("/api/nc/run", json={"mda": "G91 G0 X１２"})
    assert answer.status_code == 422, answer.text
    assert (answer.json()["error"]["line"], answer.json()["error"]["column"]) == (1, 9)
    assert mcs(client) == before


def test_a_stored_program_with_a_fullwidth_digit_shows_the_alarm_and_does_not_start(client):
    """The same ASCII rule for a stored program: saved with its syntax alarm (12080, line and
    column of the character), refused at NC Start with nothing moved."""
    stored = client.post("/api/programs", json={"name": "FW", "text": "G91\nG0 Z１\nM30"})
    assert stored.status_code == 201, stored.text
    assert (stored.json()["syntax"]["code"], stored.json()["syntax"]["line"], stored.json()["syntax"]["column"]) \
        == (12080, 2, 5)
    before = mcs(client)
    answer = client.post("/api/nc/run", json={"program": "FW"})
    assert answer.status_code == 422 and answer.json()["error"]["code"] == "nc_syntax"
    assert answer.json()["error"]["alarm"]["code"] == 12080 and "U+FF11" in answer.json()["error"]["message"]
    assert mcs(client) == before

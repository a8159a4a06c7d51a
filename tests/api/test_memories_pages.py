"""The EV/MV memories screen (app/web/memories.py): cells typed in mm, refused text changes nothing,
and the simulator's "Next part" softkey clamps the next part of the series."""

from __future__ import annotations

import pytest


def test_the_screen_lists_twenty_memories_of_each_kind(client):
    page = client.get("/memories").text
    for n in (1, 10, 20):
        assert f'data-memory="ev{n}"' in page and f'data-memory="mv{n}"' in page
    assert 'data-memory="ev21"' not in page


@pytest.mark.parametrize("typed,stored", [("0.004", 0.004), ("-0,0125", -0.0125), (" 1 ", 1.0)])
def test_a_typed_value_is_stored_in_mm(client, typed, stored):
    cell = client.post("/memories/mv/7", data={"value": typed}).text
    assert client.get("/api/memories/mv/7").json()["value"] == pytest.approx(stored, abs=1e-15)
    assert 'aria-invalid' not in cell
    audit = client.get("/api/audit").json()[0]
    assert audit["offset"] == "MV7" and audit["source"] == "screen"


@pytest.mark.parametrize("typed,message", [("", "enter a number"), ("abc", "enter a number"),
                                           ("5000", "1000 mm"), ("nan", "finite")])
def test_refused_text_stays_in_the_cell_and_changes_nothing(client, typed, message):
    audit_before = client.get("/api/audit").json()
    cell = client.post("/memories/ev/3", data={"value": typed}).text
    assert 'aria-invalid="true"' in cell and message in cell
    assert client.get("/api/memories/ev/3").json()["value"] == 0.0
    assert client.get("/api/audit").json() == audit_before


def test_next_part_clamps_the_next_part_of_the_series(client):
    page = client.post("/memories/next-part").text
    assert "Part 1 clamped" in page
    assert "Part 2 clamped" in client.post("/memories/next-part").text

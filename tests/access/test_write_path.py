"""One write path for stored data (issue 24 item 7): the EV/MV memories are written with the
same access level, the same range and the same audit row whichever route writes them: the JSON
API (/api/memories, /api/nc/variables), the memories screen, an MDA program and a stored program
run in AUTOMATIC. A route below the level is refused before anything moves and nothing is
written. (OPC UA offers no memory node to write: the zero offsets are its only writable data.)"""

from __future__ import annotations

import pytest

# (NC name, /api/memories kind, memory number): _EV[9] is memory 10 (manual §2.3.14, _EVNUM)
PROTECTED = [("_EV[9]", "ev", 10), ("_MV[0]", "mv", 1)]
VALUE = 0.25


def memory(c, headers, kind, n) -> float:
    return c.get(f"/api/memories/{kind}/{n}", headers=headers).json()["value"]


def mcs(c, headers):
    return c.get("/api/machine", headers=headers).json()["mcs"]


def write_api_memories(c, headers, name, kind, n):
    return c.put(f"/api/memories/{kind}/{n}", json={"value": VALUE}, headers=headers)


def write_api_variables(c, headers, name, kind, n):
    return c.put(f"/api/nc/variables/{name}", json={"value": VALUE}, headers=headers)


def write_screen(c, headers, name, kind, n):
    return c.post(f"/memories/{kind}/{n}", data={"value": str(VALUE)}, headers=headers)


def write_mda(c, headers, name, kind, n):
    # a motion first: a refusal must come before it
    return c.post("/api/nc/run", json={"mda": f"G91 G0 X10\n{name}={VALUE}\nG90"}, headers=headers)


def write_auto(c, headers, name, kind, n):
    program = f"W{kind.upper()}{n}"
    text = f"G91 G0 X10\n{name}={VALUE}\nG90\nM30"
    assert c.put(f"/api/programs/{program}", json={"text": text}, headers=headers).status_code in (200, 201)
    assert c.post("/api/nc/select", json={"program": program}, headers=headers).status_code == 200
    return c.post("/api/nc/start", json={}, headers=headers)


ROUTES = [write_api_memories, write_api_variables, write_screen, write_mda, write_auto]


@pytest.mark.parametrize("route", ROUTES, ids=lambda r: r.__name__)
@pytest.mark.parametrize("name, kind, n", PROTECTED)
def test_every_route_needs_the_memories_level(signin_client, tokens, route, name, kind, n):
    c, low, allowed = signin_client, tokens[7], tokens[5]
    before_position = mcs(c, low)
    refused = route(c, low, name, kind, n)
    assert refused.status_code == 403, refused.text
    assert "Write zero offsets needs access level 5" in refused.text
    assert memory(c, low, kind, n) == 0.0                       # nothing written
    assert mcs(c, low) == before_position                       # nothing moved
    assert c.get("/api/audit", params={"name": f"{kind.upper()}{n}"}, headers=allowed).json() == []
    c.post("/api/nc/reset", headers=low)
    done = route(c, allowed, name, kind, n)
    assert done.status_code == 200, done.text
    if route in (write_mda, write_auto):
        assert done.json()["state"] == "done", done.json()
    assert memory(c, allowed, kind, n) == VALUE
    audit = c.get("/api/audit", params={"name": f"{kind.upper()}{n}"}, headers=allowed).json()
    assert len(audit) == 1 and audit[0]["who"] == "token:mes5", audit
    assert audit[0]["after"] == {"value": VALUE}


def test_a_program_writing_beyond_the_memories_range_is_refused_like_the_api(signin_client, tokens):
    c, allowed = signin_client, tokens[5]
    assert c.put("/api/memories/ev/10", json={"value": 1e300}, headers=allowed).status_code == 422
    answer = c.post("/api/nc/run", json={"mda": "_EV[9]=1E300"}, headers=allowed)
    assert answer.status_code == 422                       # no exponent in the NC language: a syntax error
    answer = c.post("/api/nc/run", json={"mda": "_EV[9]=1001"}, headers=allowed).json()
    assert answer["state"] == "alarm"
    assert memory(c, allowed, "ev", 10) == 0.0

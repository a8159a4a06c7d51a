"""Part programs under the access levels (design.md §9.2, §9.4): running needs ``measure``; a
cycle that writes a zero offset or tool data needs the level of that write, checked against
whoever started the program (an alarm at the call, nothing written); NC Stop/Reset are ``jog``."""

from __future__ import annotations

BORE = "G500 G0 Z-100\nX291 Y179.5\nZ-128\n_MVAR={mvar} _SETVAL=20 _KNUM={knum}\nCYCLE977\nG0 Z-100"


def test_running_needs_credentials_and_cycle_writes_need_their_level(signin_client, tokens):
    c = signin_client
    assert c.post("/api/nc/run", json={"mda": "M30"}).status_code == 401
    low, offsets = tokens[7], tokens[5]
    # measure only at level 7: allowed
    answer = c.post("/api/nc/run", json={"mda": BORE.format(mvar=1, knum=0)}, headers=low).json()
    assert answer["state"] == "done", answer
    # into G54 at level 7: the cycle alarms (17070 write-protected), G54 unchanged
    before = c.get("/api/offsets/G54", headers=low).json()
    answer = c.post("/api/nc/run", json={"mda": BORE.format(mvar=101, knum=1)}, headers=low).json()
    assert answer["state"] == "alarm" and answer["alarm"]["code"] == 17070, answer
    assert "Write zero offsets needs access level 5" in answer["alarm"]["message"]
    assert c.get("/api/offsets/G54", headers=low).json() == before
    assert c.post("/api/nc/reset", headers=low).status_code == 200
    # at level 5 it writes, and the audit names the token
    answer = c.post("/api/nc/run", json={"mda": BORE.format(mvar=101, knum=1)}, headers=offsets).json()
    assert answer["state"] == "done", answer
    audit = c.get("/api/audit", params={"name": "G54"}, headers=offsets).json()[0]
    assert audit["who"] == "token:mes5" and audit["source"] == "measure"
    # the EV/MV memories through the variables need the zero-offset level too
    assert c.put("/api/nc/variables/_EV[9]", json={"value": 0.1}, headers=low).status_code == 403
    assert c.put("/api/nc/variables/R1", json={"value": 0.1}, headers=low).status_code == 200

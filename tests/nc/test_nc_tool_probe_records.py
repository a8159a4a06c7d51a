"""_TP / _TPW in a program are the HMI's tool-probe records (app/services/nc_records.py): a program
reads what was calibrated or entered, and what it assigns is stored, validated and audited as
PUT /api/tool-probes/{n}. Layouts: milling jog-measuring.md §9.2 (_TP[k,0..9]: −X +X −Y +Y −Z +Z,
disc diameter, axes, type, distance to the upper edge), turning turning.md §0.7 (−Z +Z −X +X).
Truth: the records as the API stored them, and the lathe's tool probe as the scenario places it
(tests/lathe/lathe_kit.py TRUE_FACES, calibrated with CYCLE982's JOG task)."""

from __future__ import annotations

import pytest
from lathe_kit import TRUE_FACES, Lathe
from lathe_kit import make_client as lathe_client

MILL_RECORD = {"trigger": {"X-": 50.0, "X+": 28.0, "Y-": 42.0, "Y+": 20.0, "Z-": -310.25},
               "disc_diameter": 22.0, "axes": 133, "type": 101, "dz": 3.0}


def run(client, text: str) -> dict:
    answer = client.post("/api/nc/run", json={"mda": text})
    assert answer.status_code == 200, answer.text
    return answer.json()


def variables(client, names: str) -> dict:
    answer = client.get("/api/nc/variables", params={"names": names})
    assert answer.status_code == 200, answer.text
    return answer.json()


def test_a_program_reads_the_stored_record_in_the_milling_layout(client):
    assert client.put("/api/tool-probes/2", json=MILL_RECORD).status_code == 200
    assert run(client, "R1=_TP[1,0] R2=_TP[1,1] R3=_TP[1,2] R4=_TP[1,3] R5=_TP[1,4]\n"
                       "R6=_TP[1,6] R7=_TP[1,7] R8=_TP[1,8] R9=_TP[1,9]")["state"] == "done"
    r = variables(client, "R1,R2,R3,R4,R5,R6,R7,R8,R9")
    assert [r[f"R{i}"] for i in range(1, 10)] == [50.0, 28.0, 42.0, 20.0, -310.25, 22.0, 133, 101, 3.0]
    # the manual's centre of the probe (jog-measuring.md §9.2): ((_TP[k,0]+_TP[k,1])/2, ...)
    assert run(client, "R10=(_TP[1,0]+_TP[1,1])/2")["state"] == "done"
    assert variables(client, "R10")["R10"] == 39.0


def test_a_program_writes_the_record_and_the_audit_says_nc(client):
    assert client.put("/api/tool-probes/1", json=MILL_RECORD).status_code == 200
    assert run(client, "_TP[0,4]=-305.5 _TP[0,6]=25")["state"] == "done"
    record = client.get("/api/tool-probes/1").json()
    assert record["trigger"] == {**MILL_RECORD["trigger"], "Z-": -305.5}
    assert record["disc_diameter"] == 25.0
    assert client.get("/api/tool-probes/2").json()["trigger"] == {}          # the other records stay
    audit = client.get("/api/audit", params={"limit": 5}).json()
    rows = audit if isinstance(audit, list) else audit.get("entries", audit.get("items", []))
    assert any(row.get("offset") == "TP1" and row.get("source") == "nc" for row in rows)


def test_a_value_the_record_refuses_is_an_alarm_and_changes_nothing(client):
    assert client.put("/api/tool-probes/1", json=MILL_RECORD).status_code == 200
    refused = run(client, "_TP[0,8]=55")                      # a probe type the manual does not have
    assert refused["state"] == "alarm" and "_TP[0,8]" in refused["alarm"]["message"]
    assert client.get("/api/tool-probes/1").json()["type"] == 101


def test_a_fractional_code_is_refused_not_truncated(client):
    """The axes code and the type are codes (jog-measuring.md §9.2): 133.5 is refused by name,
    the record keeps 133 and 101."""
    assert client.put("/api/tool-probes/1", json=MILL_RECORD).status_code == 200
    for word in ("_TP[0,7]=133.5", "_TP[0,8]=101.25"):
        refused = run(client, word)
        assert refused["state"] == "alarm", refused
        assert word.split("=")[0] in refused["alarm"]["message"] and "whole number" in refused["alarm"]["message"]
    record = client.get("/api/tool-probes/1").json()
    assert (record["axes"], record["type"]) == (133, 101)
    assert run(client, "_TP[0,7]=132.0")["state"] == "done"         # a whole number written as a real is one
    assert client.get("/api/tool-probes/1").json()["axes"] == 132


def test_on_the_lathe_the_calibrated_faces_read_in_the_turning_layout(tmp_path):
    with lathe_client(tmp_path) as client:
        lathe = Lathe(client)
        lathe.calibrate_tool_probe()
        stored = client.get("/api/tool-probes/1").json()["trigger"]
        assert run(client, "R1=_TP[0,0] R2=_TP[0,1] R3=_TP[0,2] R4=_TP[0,3]")["state"] == "done"
        r = variables(client, "R1,R2,R3,R4")
        assert [r["R1"], r["R2"], r["R3"], r["R4"]] == [stored[k] for k in ("Z-", "Z+", "X-", "X+")]
        for value, face in zip((r["R1"], r["R2"], r["R3"], r["R4"]), ("Z-", "Z+", "X-", "X+"), strict=True):
            assert value == pytest.approx(TRUE_FACES[face], abs=0.002)
        refused = run(client, "_TP[0,6]=20")                   # no meaning for turning
        assert refused["state"] == "alarm" and "lathe" in refused["alarm"]["message"]

"""Jobs, parts and verdicts through the API against the simulator's truth (design.md §10.3).

Each part of the series is a bore whose true diameter the test chooses; the probe is ideal, so
the measured diameter is the bore's and the verdicts follow from the tolerance the test set
(docs/results.md: a bore under its lower limit keeps material, rework; over its upper limit,
scrap)."""

from __future__ import annotations

import copy

import pytest
from truthkit import Operator, scenario

CENTRE = (100.0, 100.0)
DEPTH = -8.0
NOMINAL = 40.0
TOLERANCE = {"setpoint": NOMINAL, "upper": 0.03, "lower": -0.02}


def bore_part(diameter: float) -> dict:
    data = scenario(rot=(0.0, 0.0, 0.0))
    data["workpiece"]["features"] = [{"type": "block", "size": [200.0, 200.0, 60.0]},
                                     {"type": "hole", "center": list(CENTRE), "diameter": diameter, "depth": 25.0}]
    return copy.deepcopy(data)


@pytest.fixture
def op(client):
    operator = Operator(client, bore_part(NOMINAL))
    operator.load()
    operator.activate("G500")
    return operator


def measure_bore(op: Operator, diameter: float, target: str = "measure_only", tolerance: bool = True) -> dict:
    op.scen = bore_part(diameter)
    op.ok(op.c.post("/api/sim/scenario", json=op.scen))        # the next part on the table; data stays
    op.ball_to(op.part.mcs(*CENTRE, DEPTH))
    params = {"diameter": NOMINAL, **({"tolerance": TOLERANCE} if tolerance else {})}
    session = op.create("hole.1", params, target)
    return op.ok(op.c.post(f"/api/measure/{session['id']}/start", json={}))


# true diameters at and beyond each band edge, and the verdict the rule gives
SERIES = [(40.0, "ok"), (40.03, "ok"), (40.031, "scrap"), (39.98, "ok"), (39.979, "rework")]


def test_a_series_of_parts_with_verdicts_at_the_band_edges(op):
    job = op.ok(op.c.put("/api/job", json={"part_number": "4711-A", "order": "A-100", "serial": "auto",
                                           "operator": "anna", "program": "BORE40"}))
    assert job["active"] and job["serial"] == "1" and job["part"]["characteristics"] == []
    part_ids = []
    for index, (diameter, _verdict) in enumerate(SERIES):
        if index:
            job = op.ok(op.c.post("/api/job/next-part"))
            assert job["serial"] == str(index + 1)
        answer = measure_bore(op, diameter)
        part_ids.append(job["part_id"])
        assert op.ok(op.c.get(f"/api/log/{answer['log_id']}"))["part_id"] == job["part_id"]

    parts = op.ok(op.c.get("/api/parts", params={"part_number": "4711-A"}))
    assert [p["id"] for p in parts] == part_ids[::-1]          # newest first
    for part_id, (diameter, expected) in zip(part_ids, SERIES, strict=True):
        part = op.ok(op.c.get(f"/api/parts/{part_id}"))
        assert (part["part_number"], part["order"], part["operator"]) == ("4711-A", "A-100", "anna")
        (bore,) = part["characteristics"]
        assert bore["name"] == "diameter" and bore["unit"] == "mm"
        assert bore["actual"] == pytest.approx(diameter, abs=1e-9)
        assert bore["nominal"] == NOMINAL
        assert (bore["lower"], bore["upper"]) == pytest.approx((39.98, 40.03), abs=1e-12)
        assert bore["deviation"] == pytest.approx(diameter - NOMINAL, abs=1e-9)
        assert bore["verdict"] == expected and part["verdict"] == expected, diameter


def test_the_job_limits_and_the_scrap_rule(op):
    op.ok(op.c.put("/api/settings", json={"verdict_rule": "scrap"}))
    op.ok(op.c.put("/api/job", json={"part_number": "P2", "serial": "SN-0099",
                                     "characteristics": {"diameter": {"nominal": 40.0, "lower": 39.99,
                                                                      "upper": 40.01}}}))
    measure_bore(op, 39.985)         # under the job's own lower limit; the rule makes it scrap
    job = op.ok(op.c.get("/api/job"))
    assert job["serial"] == "SN-0099" and job["part"]["verdict"] == "scrap"
    assert job["part"]["characteristics"][0]["lower"] == 39.99
    assert op.ok(op.c.post("/api/job/next-part"))["serial"] == "SN-0100"


def test_measured_again_in_the_same_part_the_newest_counts(op):
    op.ok(op.c.put("/api/job", json={"part_number": "P3"}))
    measure_bore(op, 39.97)
    measure_bore(op, 40.0)
    part = op.ok(op.c.get("/api/job"))["part"]
    assert [(c["actual"], c["verdict"]) for c in part["characteristics"]] == [(pytest.approx(40.0, abs=1e-9), "ok")]


def test_without_a_job_a_measurement_belongs_to_no_part(op):
    answer = measure_bore(op, 40.0)
    assert op.ok(op.c.get(f"/api/log/{answer['log_id']}"))["part_id"] is None
    assert op.ok(op.c.get("/api/job")) == {"active": False, "part": None}
    assert op.ok(op.c.get("/api/parts")) == []


def test_a_zero_offset_measurement_gives_sizes_but_not_the_datum(op):
    limits = {"diameter": {"lower": 39.9, "upper": 40.1}, "center X": {"nominal": 0.0, "lower": -1, "upper": 1}}
    op.ok(op.c.put("/api/job", json={"part_number": "P4", "characteristics": limits}))
    measure_bore(op, 40.0, target="G54", tolerance=False)
    (diameter,) = op.ok(op.c.get("/api/job"))["part"]["characteristics"]
    assert diameter["name"] == "diameter" and diameter["verdict"] == "ok" and diameter["nominal"] == NOMINAL


def test_positions_with_the_jobs_limits_measure_only(op):
    limits = {"center X": {"nominal": CENTRE[0], "lower": CENTRE[0] - 0.01, "upper": CENTRE[0] + 0.01}}
    op.ok(op.c.put("/api/job", json={"part_number": "P5", "characteristics": limits}))
    op.put_offset("G54", trans=tuple(op.part.mcs(0.0, 0.0, 0.0)))      # the part's true origin
    op.activate("G54")
    measure_bore(op, 40.0, tolerance=False)
    chars = {c["name"]: c for c in op.ok(op.c.get("/api/job"))["part"]["characteristics"]}
    assert set(chars) == {"diameter", "center X"}
    assert chars["center X"]["actual"] == pytest.approx(CENTRE[0], abs=1e-9)
    assert chars["center X"]["verdict"] == "ok"
    assert chars["diameter"]["verdict"] == "not_decidable"        # no band for it


@pytest.mark.parametrize("body, field", [
    ({"order": "x"}, "part_number"),
    ({"part_number": "x" * 65}, "part_number"),
    ({"part_number": "a", "colour": "red"}, "colour"),
    ({"part_number": "a", "characteristics": {"d": {"lower": 2, "upper": 1}}}, "characteristics.d.lower"),
    ({"part_number": "a", "characteristics": {"d": {"upper": True}}}, "characteristics.d.upper"),
])
def test_a_bad_job_is_refused_naming_the_field_and_nothing_changes(op, body, field):
    error = op.ok(op.c.put("/api/job", json=body), 422)["error"]
    assert error["field"] == field
    assert op.ok(op.c.get("/api/job"))["active"] is False


def test_next_part_without_a_job_is_refused(op):
    assert op.ok(op.c.post("/api/job/next-part"), 422)["error"]["code"] == "no_job"
    assert op.ok(op.c.get("/api/parts/99"), 404)["error"]["field"] == "part_id"

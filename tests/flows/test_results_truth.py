"""Jobs, parts and verdicts through the API against the simulator's truth (design.md §10.3).

Each part of the series is a bore whose true diameter the test chooses; the probe is ideal, so
the measured diameter is the bore's and the verdicts follow from the tolerance the test set
(docs/results.md: a bore under its lower limit keeps material, rework; over its upper limit,
scrap)."""

from __future__ import annotations

import copy
from datetime import datetime

import numpy as np
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


# --- a machined series: SPC and the DFQ export (the tool-offset simulator, design.md §9.3) -----------

SERIES_TOLERANCE = {"setpoint": NOMINAL, "upper": 0.02, "lower": -0.02, "zero_range": 0.002, "mean_range": 0.013,
                    "dim_difference": 0.06, "safe_area": 1.0, "k": 1}
TOOL = {"tool": 20, "edge": 1, "correct": "radius", "mode": "wear"}
PARTS = 8


def series_part() -> dict:
    data = bore_part(NOMINAL)
    data["workpiece"]["features"][1]["machined_by"] = {"t": 20}
    data["tools"] = [*data["tools"], {"t": 20, "type": 120, "length": 90.0, "radius": 10.0,
                                      "wear_per_part": {"radius": 0.004}}]
    return data


@pytest.fixture
def series(client):
    """PARTS parts machined and measured with the mean-value strategy: (operator, log entries)."""
    op = Operator(client, series_part())
    op.load()
    op.activate("G500")
    op.ok(op.c.put("/api/job", json={"part_number": "SHAFT-7", "order": "O-1", "operator": "li"}))
    entries = []
    for index in range(PARTS):
        if index:
            op.ok(op.c.post("/api/job/next-part"))
        op.ok(op.c.post("/api/sim/machine-part", json={"scatter_sigma": 0.001}))
        op.ball_to(op.part.mcs(*CENTRE, DEPTH))
        session = op.create("hole.1", {"diameter": NOMINAL, "tolerance": SERIES_TOLERANCE}, TOOL)
        answer = op.ok(op.c.post(f"/api/measure/{session['id']}/start", json={}))
        entries.append(op.ok(op.c.get(f"/api/log/{answer['log_id']}")))
    return op, entries


def test_spc_of_the_series_against_the_log(series):
    op, entries = series
    spc = op.ok(op.c.get("/api/spc", params={"part_number": "SHAFT-7", "characteristic": "diameter"}))
    values = np.array([e["result"]["diameter"] for e in entries])
    assert spc["n"] == PARTS and spc["values"] == pytest.approx(values.tolist(), abs=1e-12)
    assert spc["mean"] == pytest.approx(values.mean()) and spc["sigma"] == pytest.approx(values.std(ddof=1))
    within = np.abs(np.diff(values)).mean() / 1.128
    assert (spc["lcl"], spc["ucl"]) == pytest.approx((values.mean() - 3 * within, values.mean() + 3 * within))
    assert spc["cp"] == pytest.approx(0.04 / (6 * within))
    assert spc["cpk"] == pytest.approx(min(40.02 - values.mean(), values.mean() - 39.98) / (3 * within))
    compensated = [bool(e["result"]["compensation"]) for e in entries]
    assert any(compensated), "the strategy corrected the wearing tool at least once"
    assert [p["compensation"] is not None for p in spc["points"]] == compensated
    parts = op.ok(op.c.get("/api/parts", params={"part_number": "SHAFT-7"}))[::-1]
    for part, entry in zip(parts, entries, strict=True):
        (c,) = part["characteristics"]
        assert c["log_id"] == entry["id"] and entry["part_id"] == part["id"]
        d = entry["result"]["diameter"] - NOMINAL
        assert c["verdict"] == ("ok" if abs(d) <= 0.02 else "scrap" if d > 0 else "rework")   # a bore


def test_the_dfq_export_read_back_with_an_independent_reader(series, tmp_path):
    from aqdefreader import read_dfq_file

    op, entries = series
    response = op.c.get("/api/parts/export.dfq", params={"part_number": "SHAFT-7"})
    assert response.status_code == 200
    assert response.headers["content-disposition"] == 'attachment; filename="SHAFT-7.dfq"'
    raw = response.content
    assert b"\r\n" in raw and raw.decode("cp1252").count("\r\n") == raw.count(b"\n")
    path = tmp_path / "series.dfq"
    path.write_bytes(raw)
    dfq = read_dfq_file(str(path))
    assert dfq.part_count() == 1
    part = dfq.get_part(0)
    assert part.get_part_no() == "SHAFT-7" and part.get_data("K1002") == "SHAFT-7"
    (diameter,) = part.get_characteristics()
    assert diameter.get_data("K2002") == "diameter"
    assert float(diameter.get_data("K2101")) == NOMINAL
    assert float(diameter.get_data("K2110")) == pytest.approx(39.98, abs=1e-9)
    assert float(diameter.get_data("K2111")) == pytest.approx(40.02, abs=1e-9)
    read = diameter.get_measurements()
    assert len(read) == PARTS
    for measurement, entry in zip(read, entries, strict=True):
        assert float(measurement.value) == pytest.approx(entry["result"]["diameter"], abs=1e-6)   # 6 decimals
        logged = datetime.fromisoformat(entry["time"]).astimezone()
        read_time = measurement.datetime           # the reader takes dd.mm as mm.dd where both fit
        assert (read_time.hour, read_time.minute, read_time.second) == (logged.hour, logged.minute, logged.second)
        assert {read_time.day, read_time.month} == {logged.day, logged.month}
    text = raw.decode("cp1252")
    serials = [line.split(" ", 1)[1] for line in text.split("\r\n") if line.startswith("K0006/1 ")]
    assert serials == [str(n) for n in range(1, PARTS + 1)]
    assert all(line == "K0008/1 li" for line in text.split("\r\n") if line.startswith("K0008/"))
    assert "K1053 O-1" in text.split("\r\n")


def test_spc_and_dfq_refuse_bad_queries(client):
    assert client.get("/api/spc", params={"part_number": "X"}).json()["error"]["field"] == "characteristic"
    assert client.get("/api/spc", params={"characteristic": "d"}).status_code == 422
    missing = client.get("/api/parts/export.dfq", params={"part_number": "none"})
    assert missing.status_code == 404 and missing.json()["error"]["field"] == "part_number"

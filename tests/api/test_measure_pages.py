"""Measuring input screens and the log screen over HTTP: full page vs htmx blocks, field errors,
NC Start through the screen, Back, export. Expected values come from tests/hmi_testdata.py."""

from __future__ import annotations

import csv
import io
import re
from datetime import UTC, datetime, timedelta

import pytest
from hmi_testdata import BLOCK_TOP_Z, PROBE_LENGTH, TEST_SCENARIO

from app.web.task_screens import PAGES

HTMX = {"HX-Request": "true"}
HOLE = TEST_SCENARIO["workpiece"]["features"][1]
PART_T = TEST_SCENARIO["workpiece"]["pose"]["trans"]
HOLE_MCS = (PART_T[0] + HOLE["center"][0], PART_T[1] + HOLE["center"][1])


@pytest.mark.parametrize("task", sorted(PAGES))
def test_every_input_screen_full_page_and_htmx_block(client, task):
    url = PAGES[task].url
    full = client.get(url)
    assert full.status_code == 200 and full.text.startswith("<!doctype html>")
    assert f'data-task="{task}"' in full.text and 'id="task-form"' in full.text
    assert "data-ncstart" in full.text and "/static/measure.css" in full.text
    block = client.get(url, headers=HTMX)
    assert block.status_code == 200 and "<html" not in block.text
    assert re.sub(r"^<title>[^<]*</title>", "", block.text).lstrip().startswith('<div id="screen"')   # title: issue 29
    assert 'id="vsoftkeys" class="vsoftkeys" hx-swap-oob="true"' in block.text


def test_multi_point_screen_has_p_keys_but_no_calculate_until_all_stored(client):
    text = client.get("/measure/workpiece/corner/any", headers=HTMX).text
    for n in (1, 2, 3, 4):
        assert f"P{n} stored" in text
    assert "Calculate" not in text
    single = client.get("/measure/workpiece/edge/set", headers=HTMX).text
    assert "P1 stored" not in single


def test_target_is_preset_to_the_active_wo(client):
    client.post("/api/machine/activate", json={"offset": "G55"})
    text = client.get("/measure/workpiece/edge/set").text
    assert '<option value="G55" selected>' in text
    client.post("/api/machine/activate", json={"offset": "G500"})
    # under G500 nothing could be corrected: G54 is proposed, "Measure only" one choice away
    assert '<option value="G54" selected>' in client.get("/measure/workpiece/edge/set").text


def test_field_check_shows_the_error_next_to_the_field(client):
    answer = client.post("/measure/task/hole.1/check/diameter", data={"diameter": "-3"}, headers=HTMX)
    assert answer.status_code == 200
    assert answer.text.startswith('<span id="err-diameter" class="field-error"')
    assert "Approx. diameter: enter a value greater than 0" in answer.text      # the operator's words (issue 17)
    ok = client.post("/measure/task/hole.1/check/diameter", data={"diameter": "20"}, headers=HTMX)
    assert '<span id="err-diameter" class="field-error" role="alert"></span>' in ok.text


def test_nc_start_with_bad_input_keeps_the_text_and_changes_nothing(client):
    before = client.get("/api/offsets/G54").json()
    position = client.get("/api/machine").json()["mcs"]
    answer = client.post("/measure/task/spigot.1/start", data={"target": "G54", "diameter": "abc", "infeed": "5"},
                         headers=HTMX)
    assert answer.status_code == 200
    assert 'value="abc"' in answer.text and "Approx. diameter: enter a number" in answer.text   # operator's words
    assert client.get("/api/offsets/G54").json() == before
    assert client.get("/api/machine").json()["mcs"] == position
    assert client.get("/api/log").json() == []


def _ball_to(client, x, y, z):
    for target in ({"Z": 0.0}, {"X": x, "Y": y}, {"Z": z + PROBE_LENGTH}):
        assert client.post("/api/machine/goto", json={**target, "coords": "MCS"}).status_code == 200


def test_one_hole_through_the_screen_writes_g54_and_the_log(client):
    client.post("/api/machine/tool", json={"tool": 9})
    client.post("/api/machine/activate", json={"offset": "G54"})
    _ball_to(client, HOLE_MCS[0] + 1.0, HOLE_MCS[1] - 2.0, BLOCK_TOP_Z - 10.0)
    answer = client.post("/measure/task/hole.1/start", headers=HTMX, data={
        "target": "G54", "diameter": "20", "probe_angle": "0", "setpoint.X": "0", "setpoint.Y": "0"})
    assert 'id="task-result"' in answer.text
    assert f'data-result="Diameter">{HOLE["diameter"]:.3f}<' in answer.text
    g54 = client.get("/api/offsets/G54").json()["trans"]
    assert g54["X"] == pytest.approx(HOLE_MCS[0], abs=1e-6) and g54["Y"] == pytest.approx(HOLE_MCS[1], abs=1e-6)
    log_page = client.get("/log").text
    assert "hole.1" in log_page and f"trans.X 0.000→{HOLE_MCS[0]:.3f}" in log_page
    rows = list(csv.reader(io.StringIO(client.get("/log/export.csv").text)))
    assert rows[0][:4] == ["id", "time", "task", "target"] and rows[1][2:4] == ["hole.1", "G54"]
    exported = client.get("/log/export.json")
    assert exported.headers["content-type"].startswith("application/json")
    assert exported.json()[0]["result"]["diameter"] == pytest.approx(HOLE["diameter"], abs=1e-9)
    detail = client.get(f"/log/{exported.json()[0]['id']}", headers=HTMX)
    assert detail.status_code == 200 and 'class="log-detail"' in detail.text


def test_a_measurement_ending_while_its_screen_is_drawn_shows_progress_or_outcome(client):
    """NC Start's thread sets the outcome, then ends ``running``; the screen is drawn meanwhile in
    another thread. Whatever moment the thread ends at, the screen shows the progress (which asks
    again at the next session event) or the outcome: drawn with neither, nothing asks again."""
    client.post("/api/machine/tool", json={"tool": 9})
    _ball_to(client, HOLE_MCS[0] + 1.0, HOLE_MCS[1] - 2.0, BLOCK_TOP_Z - 10.0)
    form = {"target": "measure_only", "diameter": "20", "probe_angle": "0", "setpoint.X": "0", "setpoint.Y": "0"}
    assert 'id="task-result"' in client.post("/measure/task/hole.1/start", headers=HTMX, data=form).text
    session = client.app.state.services.workflow.session
    outcome = session.last

    class EndsWhenTheOutcomeIsRead(type(session)):
        """The thread ends right after the screen has read the outcome (still the old one)."""
        @property
        def last(self):
            shown = self.__dict__["last"]
            if self.__dict__.pop("ends_now", False):
                self.__dict__["last"], self.running = outcome, False
            return shown

        @last.setter
        def last(self, value):
            self.__dict__["last"] = value

    session.__class__ = EndsWhenTheOutcomeIsRead
    session.__dict__.update(last=None, ends_now=True)
    session.running = True
    screen = client.get("/measure/task/hole.1/progress?n=1", headers=HTMX).text
    assert not session.running and session.__dict__["last"] is outcome        # it did end meanwhile
    assert 'id="task-progress"' in screen or 'id="task-result"' in screen


def test_alarm_shows_on_the_screen_and_nothing_is_stored(client):
    client.post("/api/machine/tool", json={"tool": 9})
    _ball_to(client, 100.0, 100.0, BLOCK_TOP_Z - 10.0)     # in front of the block: -Y probes into nothing
    answer = client.post("/measure/task/edge.align/start", headers=HTMX,
                         data={"axis": "Y", "direction": "-", "reference_axis": "X"})
    assert 'class="task-alarm"' in answer.text and "61301" in answer.text
    assert all(not p["stored"] for p in client.get("/api/measure/current").json()["points"])


def test_back_deletes_the_session_and_shows_the_parent_menu(client):
    client.post("/api/measure", json={"task": "corner.right", "params": {}})
    answer = client.post("/measure/task/corner.right/leave", headers=HTMX)
    assert answer.headers["HX-Push-Url"] == "/measure/workpiece/corner"
    assert "Right-angled corner" in answer.text and "Any corner" in answer.text
    assert client.get("/api/measure/current").json() is None


def test_log_screen_empty_and_unknown_entry(client):
    assert "No measurements yet." in client.get("/log").text
    assert client.get("/log/999").status_code == 404


def test_horizontal_softkey_log(client):
    assert 'href="/log"' in client.get("/jog").text


def test_log_detail_of_an_impossible_id_is_not_found(client):
    assert client.get("/log/99999999999999999999999").status_code == 404


def test_the_csv_export_has_every_log_field_a_bom_and_the_local_time(client):
    """issue [operator-ux] item 11: every log field, the byte-order mark for spreadsheets, local
    time with its offset (the stored time is UTC)."""
    from db.repository import LOG_FIELDS

    with client.app.state.services.db.unit() as unit:
        unit.add_log({"task": "edge.set", "target": "G54", "status": "ok", "measuring_wo": "G54",
                      "params": {"axis": "X"}, "result": {"position": 1.5}, "warnings": ["Feed override 80 %"],
                      "probe": {"number": 1}, "program": "MDA", "block": "N10 CYCLE978"})
    text = client.get("/log/export.csv", params={"bom": "true", "delimiter": ";", "tz": "Asia/Shanghai"}).text
    assert text.startswith("\ufeff")
    rows = list(csv.reader(io.StringIO(text[1:]), delimiter=";"))
    header, row = rows[0], dict(zip(rows[0], rows[1], strict=True))
    for field in LOG_FIELDS:                        # every stored field has a column
        assert field in header or f"{field}_json" in header, field
    assert row["measuring_wo"] == "G54" and row["warnings"] == "Feed override 80 %"
    assert row["program"] == "MDA" and row["block"] == "N10 CYCLE978" and row["probe"] == "probe 1"
    utc = datetime.fromisoformat(row["time"]).replace(tzinfo=UTC)
    local = datetime.fromisoformat(row["local_time"])
    assert local.utcoffset() == timedelta(hours=8) and abs((local - utc).total_seconds()) < 1
    refused = client.get("/log/export.csv", params={"tz": "Mars/Olympus"})
    assert refused.status_code == 422 and refused.json()["error"]["field"] == "tz"
    plain = client.get("/log/export.csv").text
    assert not plain.startswith("\ufeff") and plain.startswith("id,time,task,target")


def test_a_bug_while_drawing_the_preview_is_logged_and_shown_not_an_empty_picture(client, monkeypatch, caplog):
    def broken(*_args, **_kwargs):
        raise TypeError("a bug in the planning")

    monkeypatch.setattr("app.web.task_screens.StepExecutor", broken)
    with caplog.at_level("ERROR", logger="app.web"):
        text = client.get("/measure/workpiece/edge/set", headers=HTMX).text
    assert "The picture could not be drawn: internal error (see the HMI log)." in text
    assert "No preview (no probe position)." not in text
    logged = [r for r in caplog.records if r.name == "app.web" and r.exc_info]
    assert logged and "a bug in the planning" in str(logged[0].exc_info[1])

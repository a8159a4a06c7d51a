"""The measuring defaults of the settings (issue [operator-ux] item 9, spec §4.1/§4.4): the WO
active while measuring (_JM_I[4]) is activated when a measurement opens, the screen proposes G54
under G500, and the standard compensation choice (_JM_I[5] = 0) refuses basic frames in the API
as on the screen."""

from __future__ import annotations

from truthkit import Operator, scenario

HTMX = {"HX-Request": "true"}


def test_the_measuring_wo_setting_is_activated_when_a_measurement_opens(client):
    op = Operator(client, scenario())
    op.load()
    op.activate("G500")
    op.ok(op.c.put("/api/settings", json={"measuring_wo": "G55"}))
    session = op.create("edge.set", {"axis": "X", "direction": "+", "setpoint": 0.0})
    assert op.ok(op.c.get("/api/machine"))["active_offset"] == "G55"
    assert session["target"] == "G55"                    # the default target: the active WO
    op.ok(op.c.put("/api/settings", json={"measuring_wo": "active"}))
    op.activate("G54")
    op.create("edge.set", {"axis": "X", "direction": "+", "setpoint": 0.0})
    assert op.ok(op.c.get("/api/machine"))["active_offset"] == "G54"   # "active": kept


def test_under_g500_the_screen_proposes_g54(client):
    op = Operator(client, scenario())
    op.load()
    op.activate("G500")
    page = op.c.get("/measure/workpiece/edge/set").text
    select = page[page.index('name="target"'):]
    select = select[:select.index("</select>")]
    assert '<option value="G54" selected' in select, select[:400]
    assert 'value="measure_only"' in select                           # still one choice away


def test_standard_compensation_refuses_a_basic_frame_in_the_api(client):
    op = Operator(client, scenario())
    op.load()
    op.activate("G54")
    before = op.ok(op.c.get("/api/offsets"))
    body = op.ok(op.c.post("/api/measure", json={"task": "edge.set", "target": "BASIC_0",
                                                 "params": {"axis": "X", "direction": "+", "setpoint": 0.0}}), 400)
    assert body["error"]["field"] == "target" and "extended" in body["error"]["message"]
    assert op.ok(op.c.get("/api/offsets")) == before
    op.ok(op.c.put("/api/settings", json={"compensation_choice": "extended"}))
    op.ok(op.c.post("/api/measure", json={"task": "edge.set", "target": "BASIC_0",
                                          "params": {"axis": "X", "direction": "+", "setpoint": 0.0}}))
    op.ok(op.c.post("/api/measure", json={"task": "edge.set", "target": "BASIC_REF",
                                          "params": {"axis": "X", "direction": "+", "setpoint": 0.0}}))

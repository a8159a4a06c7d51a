"""HTML screens: full page on a normal GET, the screen blocks on an htmx request; in-place edits."""

from __future__ import annotations

import re

import pytest

HTMX = {"HX-Request": "true"}
SCREENS = ["/jog", "/offsets", "/offsets/audit", "/tools", "/machine-view", "/settings",
           "/measure/workpiece", "/measure/workpiece/edge", "/measure/workpiece/corner",
           "/measure/workpiece/pocket", "/measure/workpiece/spigot", "/measure/workpiece/calibrate",
           "/measure/workpiece/edge/set", "/measure/workpiece/plane", "/measure/tool", "/measure/tool/length",
           "/measure/tool/calibrate"]


@pytest.mark.parametrize("path", SCREENS)
def test_screen_full_page_and_htmx_block(client, path):
    full = client.get(path)
    assert full.status_code == 200
    assert full.text.startswith("<!doctype html>")
    for part in ('id="header-status"', 'id="position-values"', 'id="screen"', 'id="vsoftkeys"',
                 'id="hsoftkeys"', 'id="mcp"', "htmx-2.0.11.min.js"):
        assert part in full.text
    block = client.get(path, headers=HTMX)
    assert block.status_code == 200
    assert "<html" not in block.text and 'id="mcp"' not in block.text
    assert re.sub(r"^<title>[^<]*</title>", "", block.text).lstrip().startswith('<div id="screen"')   # title: issue 29
    assert 'id="vsoftkeys" class="vsoftkeys" hx-swap-oob="true"' in block.text
    assert 'id="hsoftkeys" class="hsoftkeys" hx-swap-oob="true"' in block.text


def test_root_redirects_to_jog(client):
    response = client.get("/", follow_redirects=False)
    assert response.status_code == 303 and response.headers["location"] == "/jog"


def test_measure_workpiece_menu_has_the_manual_softkeys(client):
    text = client.get("/measure/workpiece").text
    for label in ("Measure edge &gt;", "Measure corner &gt;", "Measure pocket/hole &gt;", "Measure spigot &gt;",
                  "Orient plane", "Calibrate probe &gt;", "Back"):
        assert label in text
    pocket = client.get("/measure/workpiece/pocket", headers=HTMX).text
    for label in ("Rectangular pocket", "1 hole", "2 holes", "3 holes", "4 holes"):
        assert label in pocket
    tool = client.get("/measure/tool", headers=HTMX).text
    for label in ("Length &gt;", "Diameter &gt;", "Calibrate probe &gt;", "&lt;&lt; Back"):
        assert label in tool


def test_unknown_menu_entry_is_404(client):
    assert client.get("/measure/workpiece/nothing").status_code == 404
    assert client.get("/measure/workpiece/edge/nothing").status_code == 404
    assert client.get("/measure/tool/nothing").status_code == 404


def test_partials(client):
    assert client.get("/ui/position", headers=HTMX).text.lstrip().startswith('<div id="position-values"')
    assert client.get("/ui/header", headers=HTMX).text.lstrip().startswith('<div id="header-status"')


def tab(axis: str = "X", increment: str = "1000") -> dict:
    """The headers a browser tab sends with its own panel selection (static/hmi.js)."""
    return {**HTMX, "X-Panel-Axis": axis, "X-Panel-Increment": increment}


def test_panel_jog_with_inc_1000_moves_one_millimetre(client):
    mcp = client.post("/ui/panel/axis", data={"axis": "Y"}, headers=tab()).text
    assert 'data-axis="Y"' in mcp
    client.post("/ui/jog", data={"direction": "+"}, headers=tab("Y", "1000"))
    assert client.get("/api/machine").json()["mcs"]["Y"] == pytest.approx(101.0)
    client.post("/ui/jog", data={"direction": "-"}, headers=tab("Y", "10"))
    assert client.get("/api/machine").json()["mcs"]["Y"] == pytest.approx(100.99)


def test_a_jog_moves_the_axis_its_tab_names_not_another_tabs(client):
    client.post("/ui/panel/axis", data={"axis": "Z"}, headers=tab("Z"))          # tab B picks Z
    client.post("/ui/jog", data={"direction": "+", "axis": "X"}, headers=tab("X"))  # tab A: X +
    mcs = client.get("/api/machine").json()["mcs"]
    assert mcs["X"] == pytest.approx(101.0) and mcs["Z"] == pytest.approx(0.0, abs=1e-9)


def test_panel_jog_error_goes_to_the_message_line(client):
    text = client.post("/ui/jog", data={"direction": "+"}, headers=tab("X", "cont")).text
    assert 'id="message"' in text and "increment" in text


def test_offset_cell_edit_stores_and_audits_with_source_screen(client):
    cell = client.post("/offsets/G54/trans.X", data={"value": "12,5"}, headers=HTMX).text
    assert 'value="12.500"' in cell and "field-error" not in cell
    assert client.get("/api/offsets/G54").json()["trans"]["X"] == 12.5
    assert client.get("/api/audit").json()[0]["source"] == "screen"


@pytest.mark.parametrize("text", ["abc", "", "1e999", "400"])
def test_offset_cell_error_keeps_the_text_and_the_stored_value(client, text):
    client.put("/api/offsets/G54", json={"rot": {"Z": 5}})
    cell = client.post("/offsets/G54/rot.Z", data={"value": text}, headers=HTMX).text
    assert "field-error" in cell and f'value="{text}"' in cell
    assert client.get("/api/offsets/G54").json()["rot"]["Z"] == 5


def test_activate_from_the_offsets_screen(client):
    text = client.post("/offsets/G55/activate", headers=HTMX).text
    assert client.get("/api/machine").json()["active_offset"] == "G55"
    assert "active: G55" in text


def test_tool_cell_edit_and_load(client):
    assert 'value="86.000"' in client.post("/tools/1/length", data={"value": "86"}, headers=HTMX).text
    bad = client.post("/tools/1/radius", data={"value": "-2"}, headers=HTMX).text
    assert "field-error" in bad and 'value="-2"' in bad
    assert client.get("/api/tools/1").json()["radius"] == 5.0
    client.post("/tools/1/load", headers=HTMX)
    assert client.get("/api/machine").json()["tool"] == 1
    assert "in spindle" in client.get("/tools").text


def test_settings_form_marks_bad_fields_and_saves_good_ones(client):
    form = {"plane": "G18", "measuring_feed": "abc", "fast_feed": "-5", "measuring_wo": "G54"}
    text = client.post("/settings", data=form, headers=HTMX).text
    assert text.count("field-error") == 2 and 'value="abc"' in text and "Not saved" in text
    assert client.get("/api/settings").json()["plane"] == "G17"
    text = client.post("/settings", data={"plane": "G18", "measuring_feed": "250", "rapid_return": "on"},
                       headers=HTMX).text
    assert "Settings saved" in text
    saved = client.get("/api/settings").json()
    assert (saved["plane"], saved["measuring_feed"], saved["rapid_return"]) == ("G18", 250, True)


def test_machine_view_draws_the_scene_and_the_probe(client):
    text = client.get("/machine-view/views", headers=HTMX).text
    assert 'id="view-top"' in text and 'id="view-front"' in text
    assert 'class="block"' in text and 'id="probe-top"' in text and 'class="ring_outer"' in text


@pytest.mark.parametrize("screen, api", [("/probes", "/api/probes"), ("/tool-probes", "/api/tool-probes")])
def test_probe_record_saved_untouched_keeps_every_stored_digit(client, screen, api):
    """The screens show 4 decimals; saving the form as shown must not round the stored record."""
    trigger = {"X-": 1.98765432, "X+": -2.01234567, "Y-": 2.0, "Y+": -2.0}
    client.put(f"{api}/2", json={"trigger": trigger})
    record = client.get(f"{api}/2").json()
    form = {f"trigger.{k}": f"{v:.4f}" for k, v in record["trigger"].items()}
    if screen == "/probes":
        form.update({"ball_diameter": f"{record['ball_diameter']:.4f}", "tool": ""})
    else:
        form.update({"disc_diameter": f"{record['disc_diameter']:.4f}", "dz": f"{record['dz']:.4f}",
                     "type": str(record["type"]), "axes": str(record["axes"])})
    page = client.post(f"{screen}/2", data=form, headers=HTMX)
    assert "2 saved" in page.text, page.text
    assert client.get(f"{api}/2").json()["trigger"] == trigger

"""The MDA / AUTO screen and the program manager as HTML (htmx partials), through TestClient."""

from __future__ import annotations

import re

HX = {"HX-Request": "true"}
BORE = "N10 G500 G17 G90 G0 Z-100\nN20 X291 Y179.5\nN30 Z-128\nN40 _MVAR=1 _SETVAL=20 _KNUM=0\nN50 CYCLE977\nN60 M30"


def wait_channel(client, state):
    services = client.app.state.services
    services.nc.wait(10)
    html = client.get("/mda/channel", headers=HX).text
    assert f'data-state="{state}"' in html, html[:400]
    return html


def test_mda_screen_has_the_editor_keys_and_the_softkeys(client):
    html = client.get("/mda").text
    for part in ('id="mda-form"', "data-ncstart", 'id="mda-text"', 'id="mda-gutter"', 'id="single-block"',
                 'id="mda-stop"', 'id="mda-reset"', 'id="nc-channel"', "MDA / AUTO", "Programs", "nc.js"):
        assert part in html, part
    assert re.search(r'id="hdr-mode"[^>]*>MDA<', html)       # the mode the screen selects (issue 29)
    assert re.search(r'id="hdr-mode"[^>]*>JOG<', client.get("/jog").text)


def test_nc_start_single_block_highlights_the_block_and_shows_results(client):
    html = client.post("/mda/start", data={"text": BORE, "single_block": "on"}, headers=HX).text
    assert 'id="nc-channel"' in html
    html = wait_channel(client, "stopped")
    assert re.search(r'<tr class="current" data-line="2">', html)          # N20 runs next
    assert "single block" in html
    assert re.search(r'id="hdr-mode"[^>]*>MDA<', client.get("/jog").text)      # the program's mode
    for _ in range(5):                  # N20 .. N60 M30
        client.post("/mda/start", data={"text": BORE, "single_block": "on"}, headers=HX)
        client.app.state.services.nc.wait(10)
    html = wait_channel(client, "done")
    assert 'data-name="_OVR[4]">20.0000<' in html and 'data-name="_OVI[2]">977<' in html


def test_results_are_named_with_their_meaning(client):
    """Issue 29 item 6: next to each index what it means, from the manual's CYCLE977 result table
    (bore: _OVR[1]/[2] setpoint centre, [4] actual diameter, [5]/[6] actual centre abscissa /
    ordinate; _OVI[2] the cycle number, [3] the variant, [5] the probe number)."""
    client.post("/mda/start", data={"text": BORE}, headers=HX)
    html = wait_channel(client, "done")
    assert 'id="nc-results-cycle">CYCLE977<' in html
    for name, meaning in (("_OVR[1]", "setpoint centre abscissa"), ("_OVR[2]", "setpoint centre ordinate"),
                          ("_OVR[4]", "actual diameter / width"), ("_OVR[5]", "actual centre abscissa"),
                          ("_OVR[6]", "actual centre ordinate"), ("_OVI[2]", "measuring cycle"),
                          ("_OVI[3]", "measuring variant"), ("_OVI[5]", "probe number")):
        assert f'data-meaning="{name}">{meaning}<' in html, name
    assert 'data-name="_OVR[4]">20.0000<' in html
    html = client.get("/mda/channel?lang=de", headers=HX).text
    assert 'data-meaning="_OVR[5]">Istwert Mittelpunkt Abszisse<' in html
    html = client.get("/mda/channel?lang=zh", headers=HX).text
    assert 'data-meaning="_OVR[4]">直径 / 宽度实际值<' in html


def test_an_empty_program_says_so_and_changes_nothing(client):
    before = client.app.state.services.nc.status()
    for text in ("", "   \n\n", "; only a comment\n  ; another\n"):
        html = client.post("/mda/start", data={"text": text}, headers=HX).text
        assert "The program is empty: nothing to run." in html, repr(text)
        assert client.app.state.services.nc.status()["state"] == before["state"]
    html = client.post("/mda/start?lang=de", data={"text": ""}, headers=HX).text
    assert "Das Programm ist leer" in html


def test_a_new_run_starts_without_the_previous_programs_results(client):
    client.post("/mda/start", data={"text": BORE}, headers=HX)
    assert 'id="nc-results"' in wait_channel(client, "done")
    client.post("/mda/start", data={"text": "N10 G500 G90 G0 Z-100\nN20 M30"}, headers=HX)
    html = wait_channel(client, "done")
    assert 'id="nc-results"' not in html and 'id="nc-results-cycle"' not in html
    values = client.get("/api/nc/variables", params={"names": "_OVR,_OVI"}).json()
    assert not any(values["_OVR"]) and not any(values["_OVI"])
    # the same program again from its start (NC Start after the end): its own results once more
    client.post("/mda/start", data={"text": BORE}, headers=HX)
    wait_channel(client, "done")
    client.post("/mda/start", data={"text": BORE}, headers=HX)
    assert 'data-name="_OVR[4]">20.0000<' in wait_channel(client, "done")


def test_a_syntax_error_is_shown_at_its_line_and_column(client):
    html = client.post("/mda/start", data={"text": "N10 G0 X10\nN20 G1 X"}, headers=HX).text
    assert 'data-alarm-line="2"' in html and "line 2, column 8" in html
    assert '<code class="caret">       ^</code>' in html
    assert client.app.state.services.nc.status()["state"] == "idle"


def test_an_alarm_is_shown_at_its_block(client):
    client.post("/mda/start", data={"text": "N10 G500 G0 Z-100\nN20 X291 Y180\nN30 G1 F500 Z-150"}, headers=HX)
    html = wait_channel(client, "alarm")
    assert re.search(r'<tr class="current alarm" data-line="3">', html) and "61302" in html
    html = client.post("/mda/reset", headers=HX).text
    assert 'data-state="idle"' in html


def test_program_manager_new_edit_select_delete(client):
    html = client.get("/programs").text
    assert 'id="programs-table"' in html and "No programs yet" in html
    html = client.post("/programs/new", data={"name": "BORE1"}, headers=HX).text
    assert 'id="program-editor"' in html and 'data-program="BORE1"' in html
    assert "letters, digits" in client.post("/programs/new", data={"name": "1X"}, headers=HX).text
    html = client.post("/programs/BORE1/save", data={"text": BORE}, headers=HX).text
    assert "saved" in html
    html = client.post("/programs/BORE1/save", data={"text": "G0 X"}, headers=HX).text
    assert "nc-syntax" in html and "line 1, column 4" in html
    client.post("/programs/BORE1/save", data={"text": BORE}, headers=HX)
    response = client.post("/programs/BORE1/select", headers=HX)
    assert response.headers["HX-Push-Url"] == "/mda" and "AUTOMATIC" in response.text
    assert client.get("/api/machine").json()["mode"] == "AUTO"
    client.post("/mda/start", data={"text": ""}, headers=HX)
    wait_channel(client, "done")
    assert client.get("/api/log").json()[0]["program"] == "BORE1"
    html = client.post("/programs/BORE1/delete", headers=HX).text
    assert "deleted" in html and 'data-program="BORE1"' not in html

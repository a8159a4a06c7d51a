"""The audit trail in the operator's terms (issue 29 item 6): names, units, localised numbers and
times, the source; no raw values ("calibrated_length: False → True", ['G17'], 17-digit floats)."""

from __future__ import annotations

import re

RAW = [re.compile(p) for p in (r"\bTrue\b", r"\bFalse\b", r"\[\s*'", r"\d\.\d{7,}", r"\b[a-z]+_[a-z_]+\b:",
                               r"\bNone\b")]


def _changes(client) -> None:
    client.put("/api/offsets/G54", json={"trans": {"X": 12.123456789012345}, "rot": {"Z": 0.5}})
    client.put("/api/tools/1", json={"length": 85.123})
    client.put("/api/settings", json={"measuring_feed": 250.0, "plane": "G18"})
    client.put("/api/probes/1", json={"ball_diameter": 4.01, "calibrated_length": True,
                                      "calibrated_planes": ["G17"]})


def _rows(html: str) -> str:
    return html.split("<tbody>")[1].split("</tbody>")[0]


def test_the_audit_trail_shows_no_raw_values(client):
    _changes(client)
    rows = _rows(client.get("/offsets/audit").text)
    shown = re.sub(r"<[^>]+>", " ", rows)
    for raw in RAW:
        assert not raw.search(shown), (raw.pattern, raw.search(shown).group(0))
    assert "<b>translation X</b>: 0.000 mm → 12.123 mm" in rows          # the screen's 3 decimals
    assert "<b>rotation Z</b>: 0.0000° → 0.5000°" in rows
    assert "<b>length</b>: 85.000 mm → 85.123 mm" in rows
    assert "<b>calibrated (length)</b>: – → yes" in rows
    assert "<b>calibrated in planes</b>: – → G17" in rows
    assert "Workpiece probe 1" in rows and "Settings" in rows
    sources = re.findall(r'<td class="source">([^<]*)</td>', rows)
    assert sources and all(s.strip() for s in sources), sources       # every row names its source


def test_the_audit_trail_in_german_and_in_inch(client):
    _changes(client)
    client.put("/api/settings", json={"units": "inch"})
    rows = _rows(client.get("/offsets/audit?lang=de").text)
    # 12.123456789 mm = 0.4773 inch (4 decimals in inch), German decimal comma
    assert "0,0000 inch → 0,4773 inch" in rows
    assert re.search(r"\d{2}\.\d{2}\.\d{4}", rows) or re.search(r"\d{1,2}\.\d{1,2}\.\d{2,4}", rows)   # a German date
    assert "Werkstückmesstaster 1" in rows or "Messtaster 1" in rows


def test_restore_screen_in_chinese_asks_first(client):
    client.put("/api/offsets/G55", json={"trans": {"X": 10.0}})
    client.put("/api/offsets/G55", json={"trans": {"X": 20.0}})
    newest = client.get("/api/audit", params={"name": "G55"}).json()[0]["id"]
    token = client.cookies.get("csrftoken") or ""
    client.get("/offsets/G55/history?lang=zh")
    asked = client.post(f"/offsets/audit/{newest}/restore?lang=zh",
                        headers={"HX-Request": "true", "Origin": "http://testserver",
                                 "X-CSRFToken": client.cookies.get("csrftoken") or token})
    assert 'id="restore-question"' in asked.text
    assert client.get("/api/offsets/G55").json()["trans"]["X"] == 20.0

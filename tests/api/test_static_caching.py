"""Static files are named by their content (app/web/static_files.py): a page's links carry the
file's version, the browser may keep such a file, and any other request for it is revalidated."""

from __future__ import annotations

import hashlib
import re
from pathlib import Path

STATIC = Path(__file__).resolve().parents[2] / "static"


def _links(html: str) -> list[str]:
    return re.findall(r'(?:src|href)="(/static/[^"]+)"', html)


def test_a_page_names_each_static_file_by_its_content(client):
    links = _links(client.get("/jog").text)
    assert len(links) >= 8, links
    for link in links:
        path, _, query = link.partition("?")
        content = (STATIC / path.removeprefix("/static/")).read_bytes()
        assert query == f"v={hashlib.sha256(content).hexdigest()[:12]}", link


def test_a_versioned_file_is_kept_and_others_are_asked_again(client):
    link = next(link for link in _links(client.get("/offsets").text) if "hmi.js" in link)
    kept = client.get(link)
    assert kept.status_code == 200 and "immutable" in kept.headers["cache-control"]
    assert "max-age=31536000" in kept.headers["cache-control"]
    plain = client.get(link.partition("?")[0])
    assert plain.status_code == 200 and plain.headers["cache-control"] == "no-cache"
    stale = client.get(link.partition("?")[0] + "?v=000000000000")
    assert stale.status_code == 200 and stale.headers["cache-control"] == "no-cache"
    assert plain.content == kept.content


def test_a_missing_static_file_is_still_404(client):
    assert client.get("/static/nothing-here.js?v=1").status_code == 404

"""Every milling measuring screen has its help picture; the redraw route follows the typed fields
and refuses an unknown function."""

from __future__ import annotations

import pytest

from app.web.task_screens import PAGES

HTMX = {"HX-Request": "true"}
POINTS = {"edge.set": 1, "edge.align": 2, "edge.distance": 2, "corner.right": 3, "corner.any": 4,
          "hole.1": 4, "spigot.1": 4, "pocket.rect": 4, "spigot.rect": 4, "plane.align": 3, "probe.radius": 4}


@pytest.mark.parametrize("task", sorted(t for t in PAGES if not t.startswith("lathe.")))
def test_every_milling_screen_has_a_help_picture(client, task):
    text = client.get(PAGES[task].url).text
    assert 'id="task-help"' in text and f'<figure class="help-picture" data-task="{task}"' in text
    if task in POINTS:                                   # touches drawn (spec §2.5-§2.9, §5.3)
        assert f'data-touches="{POINTS[task]}"' in text


def test_the_redraw_follows_the_fields_and_refuses_an_unknown_function(client):
    answer = client.post("/measure/task/edge.align/help", data={"axis": "X", "direction": "-"}, headers=HTMX)
    assert answer.status_code == 200 and answer.text.lstrip().startswith('<section id="task-help"')
    assert answer.text.count('data-dir="-X"') == 2
    assert client.post("/measure/task/nothing/help", data={}, headers=HTMX).status_code == 404

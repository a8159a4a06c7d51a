"""The machine view's data (/machine-view/scene for the 3D panel, the 2D scale bars) against the
test scenario's geometry (tests/hmi_testdata.py: block corner 1 at MCS (250, 150, −120), 200 × 120 × 60,
a Ø20 hole at (40, 30), ring gauge at (600, 100, −160), ball Ø4)."""

from __future__ import annotations

import re

import numpy as np
import pytest
from hmi_testdata import BLOCK_TOP_Z, PROBE_LENGTH, TEST_SCENARIO

from app.web.machine_view import nice_length

CORNER = np.array(TEST_SCENARIO["workpiece"]["pose"]["trans"])
SIZE = np.array(TEST_SCENARIO["workpiece"]["features"][0]["size"])
BALL_R = TEST_SCENARIO["probe"]["ball_diameter"] / 2
FACE_X = CORNER[0]                     # the block's −X face (MCS)


def ball_to(client, x, y, z):
    for target in ({"Z": 0.0}, {"X": x, "Y": y}, {"Z": z + PROBE_LENGTH}):
        assert client.post("/api/machine/goto", json={**target, "coords": "MCS"}).status_code == 200


def scene(client) -> dict:
    answer = client.get("/machine-view/scene")
    assert answer.status_code == 200 and answer.headers["cache-control"] == "no-store"
    return answer.json()


@pytest.fixture
def probing(client):
    assert client.post("/api/machine/tool", json={"tool": 9}).status_code == 200
    assert client.post("/api/machine/activate", json={"offset": "G54"}).status_code == 200
    return client


def test_the_solids_are_the_clamped_part_and_the_fixtures(client):
    data = scene(client)
    corners = np.array(data["solids"]["block"]["corners"])
    low, high = CORNER - [0, 0, SIZE[2]], CORNER + [SIZE[0], SIZE[1], 0]
    assert corners.min(axis=0) == pytest.approx(low) and corners.max(axis=0) == pytest.approx(high)
    kinds = {c["kind"]: c for c in data["solids"]["circles"]}
    assert kinds["hole"]["center"] == pytest.approx([CORNER[0] + 40, CORNER[1] + 30, BLOCK_TOP_Z])
    assert kinds["hole"]["diameter"] == 20.0
    assert kinds["ring_bore"]["diameter"] == TEST_SCENARIO["ring_gauge"]["diameter"]
    assert kinds["tool_probe"]["center"] == pytest.approx(TEST_SCENARIO["tool_probe"]["center"])
    assert data["hidden"] is False


def test_the_planned_path_before_nc_start_and_the_touch_after(probing):
    ball_to(probing, FACE_X - 20.0, 200.0, BLOCK_TOP_Z - 10.0)
    session = probing.post("/api/measure", json={"task": "edge.set", "target": "G54",
                                                 "params": {"axis": "X", "direction": "+"}}).json()
    before = scene(probing)
    assert before["touches"] == [] and before["measured"] == []
    probe_moves = [s for s in before["plan"]["segments"] if s["kind"] == "probe"]
    assert probe_moves, before["plan"]
    start, end = np.array(probe_moves[0]["from"]), np.array(probe_moves[0]["to"])
    assert start == pytest.approx([FACE_X - 20.0, 200.0, BLOCK_TOP_Z - 10.0])
    direction = (end - start) / np.linalg.norm(end - start)
    assert direction == pytest.approx([1.0, 0.0, 0.0])              # X+, at the probe's height
    # the start guard's model ends the stroke where the ball first touches the face, a contact
    assert end[0] == pytest.approx(FACE_X - BALL_R, abs=1e-6) and probe_moves[0]["verdict"] == "contact"

    assert probing.post(f"/api/measure/{session['id']}/start").status_code == 200
    after = scene(probing)
    touches = [t["at"] for t in after["touches"]]
    assert touches == [pytest.approx([FACE_X - BALL_R, 200.0, BLOCK_TOP_Z - 10.0], abs=1e-3)]
    faces = [m for m in after["measured"] if m["kind"] == "face"]
    assert len(faces) == 1 and faces[0]["normal"] == pytest.approx([1.0, 0.0, 0.0])
    assert faces[0]["at"][0] == pytest.approx(FACE_X, abs=1e-3)
    assert after["wcs"]["name"] == "G54" and after["wcs"]["origin"][0] == pytest.approx(FACE_X, abs=1e-3)


def test_a_hole_measured_is_a_circle_where_the_hole_is(probing):
    hole = (CORNER[0] + 40, CORNER[1] + 30)
    ball_to(probing, hole[0] + 1.0, hole[1] - 2.0, BLOCK_TOP_Z - 10.0)
    session = probing.post("/api/measure", json={"task": "hole.1", "target": "G54",
                                                 "params": {"diameter": 20.0}}).json()
    assert probing.post(f"/api/measure/{session['id']}/start").status_code == 200
    circles = [m for m in scene(probing)["measured"] if m["kind"] == "circle"]
    assert len(circles) == 1
    assert circles[0]["diameter"] == pytest.approx(20.0, abs=1e-3)
    assert circles[0]["at"] == pytest.approx([*hole, BLOCK_TOP_Z - 10.0], abs=1e-3)    # at the probing height
    touches = [np.array(t["at"]) for t in scene(probing)["touches"]]
    assert len(touches) >= 4                                         # one touch per probing direction
    for at in touches:                                               # ball centres one radius inside the wall
        assert np.linalg.norm(at[:2] - hole) == pytest.approx(10.0 - BALL_R, abs=1e-3)


def test_trainer_mode_leaves_the_part_out_and_keeps_the_fixtures(client):
    assert client.put("/api/settings", json={"trainer_hide_part": True}).status_code == 200
    data = scene(client)
    assert data["hidden"] is True and data["solids"]["block"] is None
    assert {c["kind"] for c in data["solids"]["circles"]} == {"ring_bore", "ring_outer", "tool_probe"}
    assert data["probe"]["offset"] == [0.0, 0.0, 0.0]                # drawn where the NC puts it
    page = client.get("/machine-view").text
    assert 'class="block"' not in page and 'class="hole"' not in page
    assert 'id="trainer-panel"' in page


@pytest.mark.parametrize("span, length", [(1000.0, 200.0), (260.0, 50.0), (99.0, 10.0), (12.0, 2.0), (0.9, 0.1)])
def test_the_scale_bar_is_a_1_2_5_length_of_at_most_a_fifth_of_the_view(span, length):
    assert nice_length(span) == pytest.approx(length)


def test_each_2d_view_has_a_scale_bar_in_millimetres(client):
    page = client.get("/machine-view").text
    bars = re.findall(r'<g class="scale-bar" data-length="([\d.]+) mm"[^>]*>\s*<line x1="([-\d.]+)" y1="[-\d.]+" '
                      r'x2="([-\d.]+)"', page)
    assert len(bars) == 2
    for label, x1, x2 in bars:                                       # SVG user units are mm
        assert float(x2) - float(x1) == pytest.approx(float(label), abs=0.01)

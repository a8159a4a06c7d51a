"""The lathe's 3D view data (/machine-view/scene, app/web/scene3d.py build_lathe) against the
scenario's truth (lathe_kit.LATHE_SCENARIO, turning.md §10.2): the turned part as bodies of
revolution about the spindle axis, eccentric by e_X at the spindle's angle; the chuck; the
grooves and the tool probe; the probe's NC tip, its true offset and F; the touches, the measured
diameter and the planned path."""

from __future__ import annotations

import pytest
from lathe_kit import LATHE_SCENARIO, Lathe, make_client

WP = LATHE_SCENARIO["workpiece"]
PROBE = LATHE_SCENARIO["probe"]


@pytest.fixture
def lathe(tmp_path):
    with make_client(tmp_path) as client:
        yield Lathe(client)


def scene(lathe) -> dict:
    answer = lathe.c.get("/machine-view/scene")
    assert answer.status_code == 200 and answer.headers["cache-control"] == "no-store"
    return answer.json()


def test_the_turned_part_the_chuck_the_grooves_and_the_tool_probe(lathe):
    data = scene(lathe)
    assert data["kind"] == "lathe" and data["hidden"] is False
    assert set(data["limits"]) == {"X", "Z"}
    part = data["solids"]["part"]
    assert [p["type"] for p in part] == [p["type"] for p in WP["profile"]]
    for drawn, truth in zip(part, WP["profile"], strict=True):
        assert drawn["z"] == pytest.approx([WP["chuck_face_z"] + truth["z"][0], WP["chuck_face_z"] + truth["z"][1]])
        assert drawn["diameter"] == pytest.approx(truth["diameter"])
        assert drawn["axis_x"] == pytest.approx(WP["eccentricity"][0])          # spindle at 0°
    chuck = data["solids"]["chuck"]
    assert chuck["face_z"] == WP["chuck_face_z"]
    assert chuck["diameter"] > WP["profile"][0]["diameter"]                      # the part sits inside the jaws
    assert len(data["solids"]["grooves"]) == len(LATHE_SCENARIO["grooves"])
    assert data["solids"]["tool_probe"] == pytest.approx(LATHE_SCENARIO["tool_probe"]["faces"])
    lathe.spos(180.0)                                 # the eccentric axis turns with the spindle
    assert scene(lathe)["solids"]["part"][0]["axis_x"] == pytest.approx(-WP["eccentricity"][0])


def test_the_probe_where_the_nc_puts_it_with_its_true_offset_and_f(lathe):
    lathe.tool(PROBE["t"])
    lathe.ball_to(30.0, 30.0)
    probe = scene(lathe)["probe"]
    nominal = PROBE["nominal"]
    assert probe["tip"] == pytest.approx([30.0, 0.0, 30.0], abs=1e-9)
    assert probe["lengths"] == pytest.approx([nominal["l1"], nominal["l2"]])
    assert probe["f"] == pytest.approx([30.0 + nominal["l1"], 0.0, 30.0 + nominal["l2"]], abs=1e-9)
    # the true ball centre: F − the true L1/L2 (the simulator's, not the tool data's)
    assert probe["offset"] == pytest.approx([nominal["l1"] - PROBE["l1"], 0.0, nominal["l2"] - PROBE["l2"]], abs=1e-9)
    assert probe["is_probe"] is True and probe["diameter"] == pytest.approx(PROBE["ball_diameter"])


def test_touches_the_measured_diameter_and_the_next_path(lathe):
    lathe.calibrate_probe_in_groove()
    lathe.ball_to(60.0, 30.0, coords="WCS")
    lathe.task("lathe.point", {"axis": "X", "setpoint": 45, "measuring_path": 2})
    data = scene(lathe)
    assert len(data["touches"]) == 4                  # groove X both ways, groove −Z, the diameter
    circles = [s for s in data["measured"] if s["kind"] == "circle"]
    assert len(circles) == 1
    # one touch at spindle angle 0 on the cylinder whose axis is 0.030 off in +X
    assert circles[0]["diameter"] == pytest.approx(WP["profile"][0]["diameter"] + 2 * WP["eccentricity"][0], abs=2e-3)
    assert circles[0]["at"] == pytest.approx([0.0, 0.0, 30.0], abs=1e-6)
    assert circles[0]["normal"] == pytest.approx([0.0, 0.0, 1.0])
    session = lathe.c.post("/api/measure", json={"task": "lathe.point",
                                                 "params": {"axis": "X", "setpoint": 45, "measuring_path": 2}})
    assert session.status_code in (200, 201), session.text
    plan = scene(lathe)["plan"]
    probing = [s for s in plan["segments"] if s["kind"] == "probe"]
    assert plan["task"] == "lathe.point" and probing
    start, end = probing[0]["from"], probing[0]["to"]
    assert start[2] == pytest.approx(30.0) and end[2] == pytest.approx(30.0)     # along X at the Z it stands
    assert end[0] < start[0]                                                    # towards the axis (X−)


def test_trainer_mode_leaves_the_turned_part_out(lathe):
    assert lathe.c.put("/api/settings", json={"trainer_hide_part": True}).status_code == 200
    data = scene(lathe)
    assert data["hidden"] is True and data["solids"]["part"] == []
    assert data["solids"]["grooves"] and data["solids"]["tool_probe"]           # the fixtures stay

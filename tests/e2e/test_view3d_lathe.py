"""End to end in Chromium on the simulated lathe: the machine view's 3D panel (static/view3d_lathe.js),
opened from a lathe task's screen as the operator does. Truth: the lathe scenario (tests/lathe/lathe_kit.py:
the turned part Ø45.006 × 60 with a bore Ø35.004 × 40 on the chuck face at Z 0, eccentric by 0.030 in X
at spindle angle 0; one groove set; the tool probe; the probe T8 with its NC lengths L1 40.123, L2 100.456
and a true ball centre 0.004 above the NC's in X). Positions are what the test commanded, never the HMI's
answers."""

from __future__ import annotations

import re

import pytest
from lathe_kit import LATHE_SCENARIO
from live import browser_tab, watch_offline
from playwright.sync_api import expect

pytestmark = pytest.mark.e2e

PROFILE = LATHE_SCENARIO["workpiece"]["profile"]
GROOVES = LATHE_SCENARIO["grooves"]


@pytest.fixture
def tab(browser, lathe_server):
    """A page with every request outside the HMI blocked and recorded, and the console's errors."""
    with browser_tab(browser, lathe_server, timeout_ms=15000) as page:
        watch_offline(page, lathe_server)
        yield page


def open_3d_from_the_task(tab, label: str, slug: str):
    tab.goto("/measure/lathe")
    tab.locator("#vsoftkeys").get_by_text(re.compile(f"^{re.escape(label)}")).click()
    expect(tab).to_have_url(f"/measure/lathe/{slug}")
    tab.locator("#hsoftkeys").get_by_text("Machine view").click()
    expect(tab).to_have_url(re.compile("/machine-view$"))
    view = tab.locator("#view3d")
    expect(view).to_have_attribute("data-state", "ready", timeout=15000)      # the first load of three.js
    return view


def test_a_lathe_task_opens_the_3d_view_of_the_turned_part_and_the_probe(tab, lathe):
    lathe.tool(8)
    lathe.ball_to(30.0, 30.0)                      # the NC's ball centre at MCS X 30 (radius), Z 30
    view = open_3d_from_the_task(tab, "1-point measurement", "point")
    expect(view).to_have_attribute("data-kind", "lathe")
    expect(view).to_have_attribute("data-scene-kind", "lathe")
    expect(view).to_have_attribute("data-part", str(len(PROFILE)))           # the cylinder and the bore
    expect(view).to_have_attribute("data-chuck", "1")
    expect(view).to_have_attribute("data-grooves", str(len(GROOVES)))
    expect(view).to_have_attribute("data-tool-probe", "1")
    expect(view).to_have_attribute("data-probe", "30.000 0.000 30.000")
    assert int(view.get_attribute("data-draw-calls")) > len(PROFILE) + 3    # WebGL really drew
    box = tab.locator("#view3d-canvas").bounding_box()
    assert box["width"] > 300 and box["height"] > 200
    # the text summary: the part as the scenario clamps it, the lathe's axes, the probe live
    part = view.locator('[data-out="part"]')
    for item in PROFILE:
        name = "bore" if item["type"] == "bore" else "cylinder"
        expect(part.locator(f'[data-part="{item["type"]}"]')).to_have_text(
            f"{name} Ø {item['diameter']:.3f} × {item['z'][1] - item['z'][0]:.3f}")
    expect(view.locator('[data-out="axes"]')).to_have_text("Z along the spindle · X up (radius)")
    expect(view.locator('[data-out="probe"]')).to_have_text("X 30.000 (Ø 60.000) · Z 30.000")
    # the turret moves along Z: the probe follows
    lathe.goto(Z=40.0 + lathe.lengths(8)[1])       # F = the ball centre + L2 (as ball_to positions)
    expect(view).to_have_attribute("data-probe", "30.000 0.000 40.000")
    expect(view.locator('[data-out="probe"]')).to_have_text("X 30.000 (Ø 60.000) · Z 40.000")
    assert tab.seen["outside"] == [] and tab.seen["errors"] == []


def test_touches_the_measured_diameter_and_the_planned_path_in_3d(tab, lathe):
    lathe.calibrate_probe_in_groove()              # X both ways (2 touches), then −Z (1 touch)
    lathe.ball_to(60.0, 30.0, coords="WCS")
    lathe.task("lathe.point", {"axis": "X", "setpoint": 45, "measuring_path": 2})    # 1 touch, a diameter
    view = open_3d_from_the_task(tab, "1-point measurement", "point")
    expect(view).to_have_attribute("data-touches", "4")
    expect(view.locator('[data-out="touches"]')).to_have_text("4")
    expect(view.locator('[data-out="measured"]')).to_have_text("1")        # the diameter's circle
    circle = [s for s in lathe.ok(lathe.c.get("/machine-view/scene"))["measured"] if s["kind"] == "circle"]
    # the truth: the cylinder's Ø45.006 touched once at spindle angle 0, its axis 0.030 off in X
    eccentric = LATHE_SCENARIO["workpiece"]["eccentricity"][0]
    assert circle[0]["diameter"] == pytest.approx(PROFILE[0]["diameter"] + 2 * eccentric, abs=2e-3)
    assert circle[0]["at"] == pytest.approx([0.0, 0.0, 30.0], abs=1e-6)        # about the spindle axis
    # a new measurement typed, NC Start not yet pressed: its path from where the probe stands
    session = lathe.c.post("/api/measure", json={"task": "lathe.point",
                                                  "params": {"axis": "X", "setpoint": 45, "measuring_path": 2}})
    assert session.status_code in (200, 201), session.text
    expect(view.locator('[data-out="plan"]')).to_have_text("P1")
    assert int(view.get_attribute("data-plan")) >= 2                 # the probing travel and the return
    assert tab.seen["outside"] == [] and tab.seen["errors"] == []


@pytest.mark.parametrize(("lang", "axes", "probe"), [("de", "Z längs der Spindel", "Messtaster (MKS, X als Radius)"),
                                                     ("zh", "Z 沿主轴", "测量头（机床坐标系，X 为半径）")])
def test_the_3d_panel_speaks_the_operators_language(tab, lathe, lang, axes, probe):
    tab.goto(f"/jog?lang={lang}")
    tab.goto("/machine-view")
    view = tab.locator("#view3d")
    expect(view).to_have_attribute("data-state", "ready", timeout=15000)
    expect(view.locator('[data-out="axes"]')).to_contain_text(axes)
    expect(view.locator(".view3d-legend")).to_contain_text(probe)

"""End to end in Chromium: the machine view's 3D panel (three.js from /static only), the 2D scale
bars and trainer mode, as the operator uses them. Truth: the test scenario (tests/hmi_testdata.py:
block corner 1 at MCS (250, 150, −120), 200 × 120 × 60, a Ø20 hole at part (40, 30), ball Ø4)."""

from __future__ import annotations

import re

import pytest
from hmi_testdata import BLOCK_TOP_Z, PROBE_LENGTH, TEST_SCENARIO
from live import watch_offline
from playwright.sync_api import expect

pytestmark = pytest.mark.e2e

CORNER = TEST_SCENARIO["workpiece"]["pose"]["trans"]
BLOCK_X = TEST_SCENARIO["workpiece"]["features"][0]["size"][0]
HOLE = (CORNER[0] + 40.0, CORNER[1] + 30.0)
PART_SOLIDS = len(TEST_SCENARIO["workpiece"]["features"])          # the block and its hole
START = TEST_SCENARIO["start"]


@pytest.fixture
def watched(page, live_server):
    """The page with every request outside the HMI blocked and recorded, and the console's errors."""
    watch_offline(page, live_server)
    return page


def ball_to(api, x, y, z):
    for target in ({"Z": 0.0}, {"X": x, "Y": y}, {"Z": z + PROBE_LENGTH}):
        assert api.post("/api/machine/goto", json={**target, "coords": "MCS"}).status_code == 200


def view3d(page):
    return page.locator("#view3d")


def test_the_3d_view_draws_the_part_and_follows_the_probe(watched, api):
    page = watched
    page.goto("/jog")
    page.locator("#hsoftkeys").get_by_text("Machine view").click()
    expect(page).to_have_url(re.compile("/machine-view$"))
    view = view3d(page)
    expect(view).to_have_attribute("data-state", "ready", timeout=15000)   # the first load of three.js
    expect(view).to_have_attribute("data-part", str(PART_SOLIDS))
    expect(view).to_have_attribute("data-hidden", "false")
    nc_tip = f"{START['X']:.3f} {START['Y']:.3f} {START['Z'] - PROBE_LENGTH:.3f}"
    expect(view).to_have_attribute("data-probe", nc_tip)
    assert int(view.get_attribute("data-draw-calls")) > PART_SOLIDS        # WebGL really drew
    assert int(view.get_attribute("data-objects")) > PART_SOLIDS
    api.post("/api/machine/jog", json={"axis": "X", "distance": 25})
    expect(view).to_have_attribute("data-probe", re.compile(rf"^{START['X'] + 25:.3f} "))
    expect(page.locator('[data-out="probe"]')).to_contain_text(f"X {START['X'] + 25:.3f}")
    box = page.locator("#view3d-canvas").bounding_box()
    assert box["width"] > 300 and box["height"] > 200
    assert page.seen["outside"] == [] and page.seen["errors"] == []


def test_the_planned_path_before_nc_start_and_the_touches_after(watched, api):
    page = watched
    api.post("/api/machine/tool", json={"tool": 9})
    api.post("/api/machine/activate", json={"offset": "G54"})
    ball_to(api, HOLE[0] + 1.0, HOLE[1] - 2.0, BLOCK_TOP_Z - 10.0)
    page.goto("/measure/workpiece/pocket/hole1")
    page.locator('#task-form [name="diameter"]').fill("20")
    page.locator('#task-form [name="diameter"]').press("Tab")
    page.locator("#nc-start").click()
    expect(page.locator("#task-result")).to_be_visible()
    page.locator("#hsoftkeys").get_by_text("Machine view").click()
    view = view3d(page)
    expect(view).to_have_attribute("data-state", "ready", timeout=15000)   # the first load of three.js
    expect(view).to_have_attribute("data-touches", re.compile(r"^([4-9]|\d\d+)$"))   # 4 directions at least
    expect(page.locator('[data-out="measured"]')).to_have_text("1")                 # the hole's circle

    # a new measurement opened (what the operator types on its screen), NC Start not yet pressed
    session = api.post("/api/measure", json={"task": "edge.set", "target": "G54",
                                             "params": {"axis": "X", "direction": "+"}})
    assert session.status_code in (200, 201), session.text
    expect(page.locator('[data-out="plan"]')).to_have_text("P1")
    assert int(view.get_attribute("data-plan")) >= 1
    assert page.seen["outside"] == [] and page.seen["errors"] == []


def test_each_2d_view_has_a_true_scale_bar(page, api):
    page.goto("/machine-view")
    expect(page.locator("#view-top .scale-bar")).to_have_count(1)
    # one read of the live-swapped SVG: the bar and the block as drawn on the screen
    drawn = page.evaluate("""() => {
        const svg = document.querySelector('#view-top');
        const bar = svg.querySelector('.scale-bar line').getBoundingClientRect();
        const block = svg.querySelector('polygon.block').getBoundingClientRect();
        return {bar: bar.width, block: block.width,
                label: svg.querySelector('.scale-bar').dataset.length};
    }""")
    label_mm = float(drawn["label"].split()[0])
    assert drawn["bar"] / label_mm == pytest.approx(drawn["block"] / BLOCK_X, rel=0.03)
    expect(page.locator("#view-front .scale-bar text")).to_have_text(re.compile(r"^\d+ mm$"))


def test_trainer_mode_hides_the_part_and_shows_the_set_up_error(watched, api):
    page = watched
    page.goto("/settings")
    page.locator("#gud-trainer_hide_part").check()
    page.locator('#vsoftkeys [data-key="S-F1"]').click()                 # Save
    expect(page.locator("#gud-trainer_hide_part")).to_be_checked()
    delta = {"X": 0.013, "Y": -0.021, "Z": 0.004}                      # the trainee's set-up, off by delta
    frame = {"trans": {"X": CORNER[0] + delta["X"], "Y": CORNER[1] + delta["Y"], "Z": CORNER[2] + delta["Z"]},
             "rot": {"X": 0.0, "Y": 0.0, "Z": 0.0}}
    assert api.put("/api/offsets/G54", json=frame).status_code == 200
    assert api.post("/api/machine/activate", json={"offset": "G54"}).status_code == 200

    page.locator("#hsoftkeys").get_by_text("Machine view").click()
    view = view3d(page)
    expect(view).to_have_attribute("data-state", "ready", timeout=15000)   # the first load of three.js
    expect(view).to_have_attribute("data-part", "0")
    expect(view).to_have_attribute("data-hidden", "true")
    for name in ("top", "front"):
        expect(page.locator(f"#view-{name} polygon.block")).to_have_count(0)
        expect(page.locator(f"#view-{name} .hole")).to_have_count(0)
        expect(page.locator(f"#view-{name} .ring_outer")).to_have_count(1)      # the fixtures stay
    expect(page.locator("#screen h1")).to_contain_text("trainer mode")

    panel = page.locator("#trainer-panel")
    page.locator("#trainer-offset").select_option("G54")
    page.locator("#trainer-check").click()
    expect(panel.locator("table.trainer-error")).to_have_attribute("data-offset", "G54")
    for axis, value in delta.items():
        expect(panel.locator(f'[data-error="trans.{axis}"]')).to_have_text(f"{value:.3f}")
    expect(panel.locator('[data-error="rot.Z"]')).to_have_text("0.0000")
    expect(panel).to_contain_text("corner 1")
    assert page.seen["outside"] == [] and page.seen["errors"] == []
    api.put("/api/settings", json={"trainer_hide_part": False})

"""The live feed in Chromium (design.md §9.9): positions follow the machine from server-sent events
with no polling, the header and the JOG alarm pane show the same alarm with the manual's remedy,
a long measurement shows its point and step while it runs, and a failed attempt is in the log.
"""

from __future__ import annotations

import threading
import time
from contextlib import contextmanager

import pytest
from hmi_testdata import PROBE_LENGTH, TEST_SCENARIO, test_scenario
from live import browser_tab
from playwright.sync_api import Error as PlaywrightError
from playwright.sync_api import expect

pytestmark = pytest.mark.e2e


def real_time(api, **machine) -> None:
    scenario = test_scenario()
    scenario["machine"].update({"time_scale": 1.0, **machine})      # the operator sees motion
    assert api.post("/api/sim/scenario", json={**scenario, "reset_data": True}).status_code == 200


@contextmanager
def stopped_afterwards(api):
    """Reset at the end, so that a measurement still running (a slow machine) stops before the next test."""
    try:
        yield
    finally:
        api.post("/api/machine/reset")
        deadline = time.monotonic() + 5
        while api.get("/api/machine").json()["busy"] and time.monotonic() < deadline:
            time.sleep(0.05)


def probe_in_the_ring(api) -> None:
    """At a fifth of real time (a ring calibration then takes ~40 s), the probe in the ring gauge."""
    real_time(api, time_scale=0.2)
    cx, cy, top = TEST_SCENARIO["ring_gauge"]["center"]
    for body in ({"Z": -100.0}, {"X": cx + 0.2, "Y": cy - 0.1}, {"Z": top - 8.0}):     # G500: WCS = tip
        assert api.post("/api/machine/goto", json={**body, "coords": "WCS"}).status_code == 200


def open_ring_calibration(page) -> None:
    page.goto("/measure/workpiece/calibrate/radius")
    field = page.locator('input[name="diameter"]')
    field.fill(str(TEST_SCENARIO["ring_gauge"]["diameter"]))
    field.dispatch_event("change")


def test_positions_follow_a_move_without_polling(browser, live_server, api):
    real_time(api)
    with browser_tab(browser, live_server) as page:
        requests: list[str] = []
        page.on("request", lambda r: requests.append(r.url))
        # every time the live feed asks the screen again (static/live.js: "hmi-state" on the body)
        page.add_init_script("window.stateAsks = 0;"
                             "document.addEventListener('hmi-state', () => window.stateAsks++, true);")
        page.goto("/jog")
        cell = page.locator('#position-values td.value[data-axis="X"]')
        wcs_x = TEST_SCENARIO["start"]["X"]                   # G500: the WCS X is the axis
        expect(cell).to_have_text(f"{wcs_x:.3f}")
        # every text the X cell shows, recorded in the page (the test's own calls may be slow on a busy machine)
        page.evaluate("""() => { window.shownX = [];
            new MutationObserver(() => { const c = document.querySelector('#position-values td.value[data-axis="X"]');
                if (c) window.shownX.push(c.textContent); })
              .observe(document.body, {subtree: true, childList: true, characterData: true}); }""")
        # a 20 mm move at 1000 mm/min takes 1.2 s; the screen shows the axis on its way
        move = threading.Thread(target=api.post, args=("/api/machine/goto",),      # it answers at the end
                                kwargs={"json": {"X": wcs_x + 20.0, "coords": "MCS", "feed": 1000.0}})
        move.start()
        move.join(timeout=5)
        expect(cell).to_have_text(f"{wcs_x + 20.0:.3f}")
        shown = page.evaluate("window.shownX")
        between = {v for v in shown if wcs_x < float(v) < wcs_x + 20.0}
        # >= 10 updates a second while moving: at least 12 positions on the way in 1.2 s
        assert len(between) >= 12, f"the position was shown at only {sorted(between)} on its way"
        polls = [u for u in requests if u.endswith("/ui/position") or u.endswith("/ui/header")]
        asks = page.evaluate("window.stateAsks")              # read after: each poll's ask is counted
        # the header and the position block are fetched once per ask, when the state changes (the
        # first event, the move's start and end, once more for an answer a newer state overtook),
        # never on a timer (a 1.2 s move polled at 5 Hz would be some 12 more)
        assert len(polls) <= 2 * asks, f"{len(polls)} position/header requests for {asks} asks: still polling"
        assert asks <= 6, f"the screen was asked again {asks} times for one move"
        z = page.locator('#position-values td.value[data-axis="Z"]')
        expect(z).to_have_text(f"{TEST_SCENARIO['start']['Z'] - PROBE_LENGTH:.3f}")


def test_header_and_alarm_pane_agree_and_show_the_remedy(browser, live_server, api):
    with browser_tab(browser, live_server) as page:
        page.goto("/jog")
        expect(page.locator("#alarm-pane")).to_contain_text("No alarms.")
        # 60 mm in front of the block in air: an edge probed from there touches nothing (61301)
        api.post("/api/machine/goto", json={"X": 150.0, "Y": 50.0, "Z": -30.0, "coords": "MCS"})
        session = api.post("/api/measure", json={"task": "edge.set", "params": {"axis": "X", "direction": "+"},
                                                 "target": "measure_only"}).json()
        assert api.post(f"/api/measure/{session['id']}/start").status_code == 409
        expect(page.locator("#alarm-line")).to_contain_text("61301")                 # default 5 s: a loaded CI computer
        pane = page.locator('#alarm-pane li[data-alarm="61301"]')
        expect(pane).to_contain_text("Probe not switched")
        # the manual (seed 001 §11): check the measuring input, the measuring path, the probe
        expect(pane.locator(".remedy")).to_contain_text("measuring input")
        expect(page.locator("#alarm-line .remedy")).to_contain_text("measuring input")
        page.keyboard.press("Escape")                         # Reset clears it on both
        expect(page.locator("#alarm-line")).not_to_contain_text("61301")
        expect(page.locator("#alarm-pane")).to_contain_text("No alarms.")
        page.goto("/log")                                      # the failed attempt is logged
        expect(page.locator("table.log-table")).to_contain_text("alarm 61301")


def test_a_running_measurement_shows_point_and_step(browser, live_server, api):
    """A ring-gauge radius calibration at a fifth of real time (real: ~40 s): the screen counts its
    steps while it runs."""
    probe_in_the_ring(api)
    with browser_tab(browser, live_server, timeout_ms=8000) as page, stopped_afterwards(api):
        open_ring_calibration(page)
        page.locator("#nc-start").click()
        progress = page.locator("#task-progress")
        expect(progress).to_contain_text("Measuring P1")
        seen = set()
        deadline = time.monotonic() + 30
        read = "() => { const p = document.querySelector('#task-progress'); if (!p) return null;" \
               " const s = p.querySelector('[data-step]'); return s ? s.textContent : ''; }"
        while time.monotonic() < deadline:
            step = page.evaluate(read)                  # read in one go: the element is swapped meanwhile
            if step is None:
                break
            seen.add(step)
            time.sleep(0.1)
        seen.discard("")
        assert len(seen) >= 3, f"the steps shown while measuring: {sorted(seen)}"
        expect(page.locator("#task-result")).to_be_visible(timeout=30000)


def test_the_outcome_shows_although_a_progress_answer_came_too_late(browser, live_server, api):
    """The screen asks for its progress on each session event. When the answer that holds the
    outcome is so late that the browser gives up on it (a busy computer), the outcome must still
    show: after the measurement no session event follows that would ask again."""
    probe_in_the_ring(api)
    with browser_tab(browser, live_server, timeout_ms=8000) as page, stopped_afterwards(api):
        open_ring_calibration(page)
        page.evaluate("() => { window.givenUp = 0; document.addEventListener('htmx:timeout', () => window.givenUp++); }")
        held = []
        gave_up = threading.Event()

        def hold_the_outcome(route) -> None:      # answers with the outcome never arrive, until one was given up
            try:
                answer = route.fetch()
                if 'id="task-result"' in answer.text() and not gave_up.is_set():
                    held.append(route)
                else:
                    route.fulfill(response=answer)
            except PlaywrightError:     # the browser gave up on it meanwhile, or the tab closed (CI)
                pass

        page.route("**/progress*", hold_the_outcome)
        try:
            page.locator("#nc-start").click()
            expect(page.locator("#task-progress")).to_contain_text("Measuring P1")
            page.wait_for_function("() => window.givenUp > 0", timeout=60000)
            gave_up.set()
            assert held, "no answer with the outcome was held back: the test proved nothing"
            expect(page.locator("#task-result")).to_be_visible(timeout=10000)
        finally:
            page.unroute_all(behavior="ignoreErrors")     # a handler still fetching must not fail the next test


def test_the_outcome_shows_although_the_nc_start_answer_came_too_late(page, api):
    """NC Start's own answer so late that the browser gives up on it (htmx's timeout): the
    measurement runs on in the HMI, so the screen asks for its progress and shows the outcome
    (a fresh-clone run at load 8 waited 30 s in vain for the result of a ring calibration)."""
    cx, cy, top = TEST_SCENARIO["ring_gauge"]["center"]
    for body in ({"Z": -100.0}, {"X": cx + 0.2, "Y": cy - 0.1}, {"Z": top - 8.0}):     # G500: WCS = tip
        assert api.post("/api/machine/goto", json={**body, "coords": "WCS"}).status_code == 200
    open_ring_calibration(page)
    page.evaluate("() => { window.givenUp = 0; document.addEventListener('htmx:timeout', () => window.givenUp++); }")
    held = []

    def never_answered(route) -> None:          # the HMI takes NC Start; its answer never reaches the page
        try:
            route.fetch()
        except PlaywrightError:                  # the tab closed while it was fetched
            return
        held.append(route)

    page.route("**/measure/task/*/start", never_answered)
    try:
        page.locator("#nc-start").click()
        page.wait_for_function("() => window.givenUp > 0")
        assert held, "NC Start never reached the HMI: the test proved nothing"
        expect(page.locator("#task-result")).to_be_visible()
    finally:
        page.unroute_all(behavior="ignoreErrors")
    assert api.get("/api/probes/1").json()["calibrated_at"] is not None      # the calibration was stored

"""Access in real Chromium (design.md §9.2): a page of another origin posting forms (urlencoded and
text/plain), a no-cors fetch and a framed HMI at the operator's browser changes nothing; the HMI's
own pages still write (their CSRF token); sign-in, the operator panel's disabled softkeys;
/docs offline with "Try it out"."""

from __future__ import annotations

import http.server
import re
import threading
from contextlib import contextmanager

import httpx
import pytest
from hmi_testdata import TEST_SCENARIO
from live import browser_tab, free_port, serve
from playwright.sync_api import expect

pytestmark = pytest.mark.e2e

ATTACK = """<!doctype html><html><body>
<iframe name="f1"></iframe><iframe name="f2"></iframe><iframe name="f3"></iframe><iframe name="f4"></iframe>
<iframe id="framed" src="{hmi}/offsets"></iframe>
<form id="a1" method="post" action="{hmi}/offsets/G54/trans.X" target="f1">
  <input name="value" value="777.7"><input name="csrftoken" value="guessed"></form>
<form id="a2" method="post" action="{hmi}/api/offsets/G54" enctype="text/plain" target="f2">
  <input name='{{"trans": {{"X": 777.7}}, "pad": "' value='"}}'></form>
<form id="a3" method="post" action="{hmi}/ui/jog" target="f3"><input name="direction" value="+"></form>
<form id="a4" method="post" action="{hmi}/api/sim/scenario" enctype="text/plain" target="f4">
  <input name='{{"reset_data": true, "pad": "' value='"}}'></form>
<script>
  for (const id of ["a1", "a2", "a3", "a4"]) document.getElementById(id).submit();
  fetch("{hmi}/api/machine/jog", {{method: "POST", mode: "no-cors", headers: {{"Content-Type": "text/plain"}},
        body: JSON.stringify({{axis: "X", distance: 50}})}}).catch(() => null);
  document.title = "sent";
</script></body></html>"""


@contextmanager
def attacker_site(hmi: str):
    """A page on another port of this computer (same site as the HMI: the browser even sends its
    SameSite=Strict cookies), served by the standard library."""
    page = ATTACK.format(hmi=hmi).encode()

    class Handler(http.server.BaseHTTPRequestHandler):
        def do_GET(self):  # noqa: N802
            self.send_response(200)
            self.send_header("content-type", "text/html")
            self.end_headers()
            self.wfile.write(page)

        def log_message(self, *args):
            pass

    port = free_port()
    server = http.server.ThreadingHTTPServer(("127.0.0.1", port), Handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{port}/"
    finally:
        server.shutdown()


def test_a_foreign_origin_page_changes_nothing(browser, live_server, api):
    g54 = api.get("/api/offsets/G54").json()
    mcs = api.get("/api/machine").json()["mcs"]
    log_before = len(api.get("/api/audit", params={"limit": 1000}).json())
    statuses: dict[str, int] = {}
    with browser_tab(browser, live_server) as page, attacker_site(live_server) as evil:
        page.goto("/offsets")                                   # the operator has the HMI open: cookies exist
        assert any(c["name"] == "csrftoken" for c in page.context.cookies())
        page.context.on("response", lambda r: statuses.__setitem__(r.url.split(live_server)[-1], r.status)
                        if r.url.startswith(live_server) and r.request.method == "POST" else None)
        page.goto(evil)
        page.wait_for_function("document.title === 'sent'")
        page.wait_for_timeout(1500)
    assert statuses.get("/offsets/G54/trans.X") == 403, statuses
    assert statuses.get("/api/offsets/G54") in (403, 405), statuses     # PUT-only route: a POST cannot write either
    assert statuses.get("/ui/jog") == 403 and statuses.get("/api/sim/scenario") == 403, statuses
    assert api.get("/api/offsets/G54").json() == g54
    assert api.get("/api/machine").json()["mcs"] == mcs
    assert len(api.get("/api/audit", params={"limit": 1000}).json()) == log_before


def test_the_hmis_own_pages_still_write(page, api):
    page.goto("/offsets")
    cell = page.locator('td[data-offset="G56"][data-field="trans.Y"] input')
    with page.expect_response(lambda r: "/offsets/G56/trans.Y" in r.url) as answer:
        cell.fill("12.5")
        cell.press("Tab")
    assert answer.value.status == 200
    assert api.get("/api/offsets/G56").json()["trans"]["Y"] == 12.5
    # hmi.js requests (htmx.ajax) carry the token too: NC Start outside a measuring screen
    page.goto("/jog")
    with page.expect_response(lambda r: r.request.method == "POST" and "/ui/ncstart" in r.url) as answer:
        page.locator("#nc-start").click()
    assert answer.value.status == 200
    assert page.locator("#trainer-banner").is_visible()


@pytest.fixture(scope="module")
def signin_server(tmp_path_factory):
    """A live HMI with sign-in on: user anna (level 3)."""
    from app.access.service import AccessService
    from db import Database

    root = tmp_path_factory.mktemp("signin")
    with Database(root / "hmi.db") as db:
        AccessService(db).add_user("anna", 3, "anna-pw-3")
    with serve(root, TEST_SCENARIO) as url:
        yield url


def test_sign_in_sign_out_and_the_panels_disabled_softkeys(browser, signin_server):
    with browser_tab(browser, signin_server) as page:
        page.goto("/offsets")
        page.wait_for_url("**/signin?next=/offsets")
        page.fill("#signin-user", "anna")
        page.fill("#signin-password", "wrong")
        page.click("#signin-submit")
        assert "wrong user name or password" in page.locator("#signin-error").inner_text()
        page.fill("#signin-password", "anna-pw-3")
        page.click("#signin-submit")
        page.wait_for_url("**/offsets")
        assert "anna" in page.locator("#who").inner_text() and "level 3" in page.locator("#who").inner_text()
        cell = page.locator('td[data-offset="G57"][data-field="trans.X"] input')
        assert cell.is_enabled()
        with page.expect_response(lambda r: "/offsets/G57/trans.X" in r.url) as answer:
            cell.fill("3.25")
            cell.press("Tab")
        assert answer.value.status == 200
        audit = page.request.get(f"{signin_server}/api/audit?name=G57").json()
        assert audit[0]["who"] == "user:anna"
        page.locator("#who .signout").click()
        # the sign-out's redirect and a poll's (now unauthenticated) redirect may race: both go to
        # the sign-in page, the first navigation is aborted; only where the tab ends matters
        expect(page).to_have_url(re.compile(r"/signin"))
        assert page.request.get(f"{signin_server}/api/machine").status == 401

        page.goto("/signin")
        page.click("#panel-submit")                                  # the operator at the machine, key at 0
        page.wait_for_url("**/jog")
        assert "Operator panel" in page.locator("#who").inner_text()
        page.goto("/offsets")
        cell = page.locator('td[data-offset="G57"][data-field="trans.X"] input')
        assert cell.is_disabled() and "needs level 5" in cell.get_attribute("title")
        page.goto("/settings")
        save = page.locator('#vsoftkeys [data-key="S-F1"]')
        assert save.is_disabled() and "needs level 3" in save.inner_text()
        page.goto("/measure/workpiece/calibrate")
        assert page.locator('#vsoftkeys [data-key="S-F1"]').is_disabled()


def test_a_refused_write_says_why_on_the_message_line(browser, signin_server):
    """The level can drop while a screen is open (signed out in another tab, key switch): a write
    from a key still enabled is refused (403) and the message line says which level it needs."""
    with browser_tab(browser, signin_server) as page:
        page.goto("/signin")
        page.click("#panel-submit")                                  # the operator panel, key at 0
        page.wait_for_url("**/jog")
        page.goto("/offsets")
        cell = page.locator('td[data-offset="G57"][data-field="trans.Y"] input')
        assert cell.is_disabled()
        # the request a screen rendered before the level dropped sends
        with page.expect_response(lambda r: "/offsets/G57/trans.Y" in r.url) as answer:
            page.evaluate("""() => htmx.ajax("POST", "/offsets/G57/trans.Y",
                {target: 'td[data-offset="G57"][data-field="trans.Y"]', swap: "outerHTML", values: {value: "7.5"}})""")
        assert answer.value.status == 403
        expect(page.locator("#message")).to_contain_text("level 5")
        expect(page.locator("#message")).to_have_class(re.compile(r"\berror\b"))
        assert page.locator("#screen").count() == 1                  # the screen itself stays
        page.reload()
        expect(page.locator('td[data-offset="G57"][data-field="trans.Y"] input')).not_to_have_value("7.5")


def test_docs_work_offline_and_try_it_out_respects_the_levels(browser, live_server):
    with browser_tab(browser, live_server, timeout_ms=15000) as page:
        outside: list[str] = []

        def only_local(route):
            if route.request.url.startswith(live_server):
                return route.continue_()
            outside.append(route.request.url)
            return route.abort()

        page.route("**/*", only_local)
        errors: list[str] = []
        page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
        page.goto("/docs")
        page.wait_for_selector(".opblock", timeout=15000)
        assert page.locator(".opblock").count() > 40
        block = page.locator("#operations-machine-reset_api_machine_reset_post")
        block.locator(".opblock-summary").click()
        block.locator(".try-out__btn").click()
        with page.expect_response(lambda r: r.url.endswith("/api/machine/reset")) as answer:
            block.locator(".execute").click()
        assert answer.value.status == 200                           # the CSRF token went with it
        assert answer.value.request.headers.get("x-csrftoken")
        page.goto("/redoc")
        page.wait_for_selector("h1", timeout=15000)
        assert "Measure-in-JOG HMI" in page.locator("h1").first.inner_text()
        # nothing left this computer; the CSP blocked no script (ReDoc's footer logo on its CDN is
        # blocked by img-src, as it should be offline)
        assert outside == [], outside
        assert not [e for e in errors if "Content Security Policy" in e and "script-src" in e], errors


def test_the_hmi_cannot_be_framed(browser, live_server):
    with browser_tab(browser, live_server) as page:
        headers = httpx.get(f"{live_server}/jog").headers
        assert headers["x-frame-options"] == "DENY" and "frame-ancestors 'none'" in headers["content-security-policy"]
        page.set_content(f'<iframe id="f" src="{live_server}/jog"></iframe>')
        page.wait_for_timeout(800)
        frame = page.frame_locator("#f")
        assert frame.locator("#screen").count() == 0

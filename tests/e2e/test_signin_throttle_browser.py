"""The sign-in screen when a computer keeps typing wrong passwords (issue 25 item 2): it says, in
the operator's language, that this computer must wait."""

from __future__ import annotations

import httpx
import pytest
from hmi_testdata import TEST_SCENARIO
from live import browser_tab, serve

pytestmark = pytest.mark.e2e


@pytest.fixture(scope="module")
def guarded_server(tmp_path_factory):
    def prepare(app):
        app.state.access.add_user("anna", 3, "anna-pw-33")

    with serve(tmp_path_factory.mktemp("throttle"), TEST_SCENARIO, prepare=prepare) as url:
        yield url


def test_wrong_passwords_make_this_computer_wait_and_the_screen_says_so_in_german(browser, guarded_server):
    with browser_tab(browser, guarded_server) as page:
        page.goto("/signin?lang=de")
        for _ in range(5):
            page.fill("#signin-user", "anna")
            page.fill("#signin-password", "falsch")
            page.click("#signin-submit")
            assert page.locator("#signin-error").inner_text() == "Benutzername oder Passwort falsch"
        page.fill("#signin-user", "anna")
        page.fill("#signin-password", "anna-pw-33")          # right, but this computer must wait
        page.click("#signin-submit")
        assert page.locator("#signin-error").inner_text().startswith(
            "Zu viele fehlgeschlagene Anmeldungen von diesem Rechner: in ")
        assert "/signin" in page.url
    # the JSON API of the same computer gets the same answer, with the time to wait; another
    # computer is not held (other addresses: tests/hardening/test_signin_bounds.py)
    with httpx.Client(base_url=guarded_server) as api:
        answer = api.post("/api/session", json={"user": "anna", "password": "anna-pw-33"})
        assert answer.status_code == 429 and answer.json()["error"]["code"] == "too_many_attempts"
        assert int(answer.headers["Retry-After"]) >= 1

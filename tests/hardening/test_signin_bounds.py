"""Sign-in that an attacker can neither starve the server with nor turn into a lock-out (issue 25
items 1 and 2, design.md §10.8): bounded password work, per-source throttling, per-channel counts,
the password policy. The timing figures of a flood are bench/bench_signin_flood.py's."""

from __future__ import annotations

import re
import threading
from concurrent.futures import ThreadPoolExecutor

import pytest
from fastapi.testclient import TestClient
from waiting import wait_until

from app.access.service import AccessError, AccessService, SignInRefused
from app.access.throttle import HTTP, OPCUA, SignInGate, Throttled

PASSWORD = "anna-right-pw"
LOCAL = "http://127.0.0.1:8000"       # a Host the HMI serves (the clients below come from elsewhere)


class Clock:
    def __init__(self):
        self.now = 1000.0

    def __call__(self) -> float:
        return self.now


# --- per source --------------------------------------------------------------------------------

def test_a_source_waits_after_its_free_failures_and_a_refused_try_does_not_extend_the_wait():
    clock = Clock()
    gate = SignInGate(free_failures=5, base_delay_s=1.0, max_delay_s=60.0, clock=clock)
    attacker = (HTTP, "192.0.2.7")
    for _ in range(5):
        gate.check_source(attacker)
        gate.failed(attacker)
    with pytest.raises(Throttled) as refused:
        gate.check_source(attacker)
    assert refused.value.code == "too_many_attempts" and refused.value.retry_after_s == 1
    clock.now += 0.5
    with pytest.raises(Throttled):                # refused at once, the wait stays 1 s from the failure
        gate.check_source(attacker)
    clock.now += 0.5
    gate.check_source(attacker)                   # the wait is over: one more try
    gate.failed(attacker)                         # the 6th failure: 2 s now
    clock.now += 1.5
    with pytest.raises(Throttled) as refused:
        gate.check_source(attacker)
    assert refused.value.retry_after_s == 1       # 0.5 s left, rounded up
    for _ in range(20):                           # the wait doubles up to its ceiling
        clock.now += 100
        gate.failed(attacker)
    assert gate.wait_left(attacker) == 60.0


def test_other_sources_and_the_other_channel_are_not_held_and_a_success_clears_the_source():
    clock = Clock()
    gate = SignInGate(clock=clock)
    for _ in range(10):
        gate.failed((OPCUA, "192.0.2.7"))
    assert gate.wait_left((OPCUA, "192.0.2.7")) > 0
    assert gate.wait_left((HTTP, "192.0.2.7")) == 0          # OPC UA failures do not lock HTTP
    assert gate.wait_left((OPCUA, "198.51.100.1")) == 0
    gate.succeeded((OPCUA, "192.0.2.7"))
    assert gate.wait_left((OPCUA, "192.0.2.7")) == 0


def test_the_table_of_sources_is_bounded():
    gate = SignInGate(max_sources=100)
    for n in range(1000):
        gate.failed((HTTP, f"10.0.{n // 256}.{n % 256}"))
    assert gate.sources == 100
    assert gate.wait_left((HTTP, "10.0.3.231")) == 0 and gate.sources == 100    # read only


def test_old_failures_are_forgotten():
    clock = Clock()
    gate = SignInGate(free_failures=2, forget_s=900.0, clock=clock)
    for _ in range(2):
        gate.failed((HTTP, "a"))
    clock.now += 901
    gate.failed((HTTP, "a"))                     # counts as the first again
    assert gate.wait_left((HTTP, "a")) == 0


# --- the bounded pool ---------------------------------------------------------------------------

def test_beyond_the_workers_and_the_queue_a_check_is_refused_at_once():
    gate = SignInGate(workers=2, queue=1)
    release = threading.Event()
    running = []

    def check():
        running.append(threading.current_thread().name)
        release.wait(30)
        return "checked"

    with ThreadPoolExecutor(3) as callers:
        held = [callers.submit(gate.run, check) for _ in range(3)]
        wait_until(lambda: len(running) == 2 and gate.admitted == 3, "two checks run, one waits")
        with pytest.raises(Throttled) as refused:
            gate.run(check)
        assert refused.value.code == "sign_in_busy"
        release.set()
        assert [future.result(timeout=30) for future in held] == ["checked"] * 3
    assert gate.admitted == 0 and gate.run(lambda: 7) == 7          # free again
    # always the gate's own threads (their malloc arenas are all that argon2's memory can stay in)
    assert len(set(running)) <= 2 and all(name.startswith("password-check") for name in running)


# --- the HTTP sign-in as a client sees it ---------------------------------------------------------

@pytest.fixture
def anna(app):
    access: AccessService = app.state.access
    access.add_user("anna", 3, PASSWORD)
    return access


def _sign_in(client, password: str):
    return client.post("/api/session", json={"user": "anna", "password": password})


def test_a_flood_of_wrong_sign_ins_is_bounded_and_reset_and_jog_still_answer(app, anna, monkeypatch):
    """200 parallel wrong sign-ins while the password checks are held: no more than the pool's
    workers run argon2, the rest beyond the queue are refused at once, and the machine calls answer
    while the checks are still held (before: every request thread sat in argon2)."""
    release = threading.Event()
    lock = threading.Lock()
    now = {"running": 0, "most": 0, "runs": 0}
    verify = anna._hasher.verify_and_update

    def held_verify(password, hashed):
        with lock:
            now["running"] += 1
            now["most"] = max(now["most"], now["running"])
            now["runs"] += 1
        release.wait(60)
        with lock:
            now["running"] -= 1
        return verify(password, hashed)

    monkeypatch.setattr(anna._hasher, "verify_and_update", held_verify)
    gate = anna.gate
    token, _record = anna.add_token("mes", 1)
    machine = {"Authorization": f"Bearer {token}"}
    with TestClient(app) as client, ThreadPoolExecutor(64) as pool:
        flood = [pool.submit(_sign_in, client, f"wrong-{n}") for n in range(200)]
        wait_until(lambda: sum(f.done() for f in flood) == 200 - gate.workers - gate.queue,
                   "all but the admitted sign-ins answered")
        assert now["running"] == gate.workers
        assert client.get("/api/health").json() == {"status": "ok"}
        z = client.get("/api/machine", headers=machine).json()["mcs"]["Z"]
        assert client.post("/api/machine/jog", json={"axis": "Z", "distance": -1.0}, headers=machine).status_code == 200
        assert client.get("/api/machine", headers=machine).json()["mcs"]["Z"] == pytest.approx(z - 1.0)
        assert client.post("/api/machine/reset", headers=machine).status_code == 200
        busy = [f.result() for f in flood if f.done()]
        assert {r.status_code for r in busy} == {429}
        assert {r.json()["error"]["code"] for r in busy} == {"sign_in_busy"}
        assert all(r.headers["Retry-After"] == "1" for r in busy)
        release.set()
        answers = [f.result(timeout=60) for f in flood]
    codes = [r.status_code for r in answers]
    assert set(codes) == {401, 429}
    # the admitted ones ran one at a time; once this computer had failed 5 times, a queued try was
    # refused when its turn came, before argon2 (the 6th may have started before the 5th was counted)
    assert gate.free_failures <= codes.count(401) <= gate.free_failures + gate.workers
    assert now["most"] == gate.workers and now["runs"] == codes.count(401)


def _form_token(client) -> str:
    """The CSRF field of the sign-in form (its cookie is now set on the client)."""
    return re.search(r'name="csrftoken" value="([^"]+)"', client.get("/signin").text).group(1)


def test_a_flood_of_the_sign_in_form_is_refused_early_as_the_json_sign_in(app, anna, monkeypatch):
    """The HTML form (POST /signin) shares the bounded pool of POST /api/session: beyond the
    workers and the queue a try is answered 429 at once, before any password work and without a
    worker thread (the refusal runs on the event loop), and the machine calls still answer."""
    import app.web.signin as signin_screen

    release = threading.Event()
    verify = anna._hasher.verify_and_update
    monkeypatch.setattr(anna._hasher, "verify_and_update",
                        lambda password, hashed: (release.wait(60), verify(password, hashed))[1])
    threaded = []
    to_thread = signin_screen.run_in_threadpool

    async def counted(function, *args):
        threaded.append(args[2])                          # the user name of a check that got a thread
        return await to_thread(function, *args)

    monkeypatch.setattr(signin_screen, "run_in_threadpool", counted)
    gate = anna.gate
    token, _record = anna.add_token("mes", 1)
    machine = {"Authorization": f"Bearer {token}"}
    with TestClient(app) as client, ThreadPoolExecutor(64) as pool:
        csrf = _form_token(client)

        def submit(n):
            return client.post("/signin", data={"user": "anna", "password": f"wrong-{n}", "csrftoken": csrf},
                               follow_redirects=False)

        flood = [pool.submit(submit, n) for n in range(200)]
        wait_until(lambda: sum(f.done() for f in flood) == 200 - gate.workers - gate.queue,
                   "all but the admitted form sign-ins answered")
        assert client.get("/api/machine", headers=machine).status_code == 200
        assert client.post("/api/machine/reset", headers=machine).status_code == 200
        busy = [f.result() for f in flood if f.done()]
        assert {r.status_code for r in busy} == {429}
        assert all(r.headers["Retry-After"] == "1" for r in busy)
        assert all('id="signin-error"' in r.text and "too many sign-ins at once" in r.text for r in busy)
        # most were refused without a thread: the look-ahead on the event loop lets through only
        # the first of the burst, before the first checks were admitted (those are refused by the
        # pool itself, again before any password work)
        assert len(threaded) < 50
        release.set()
        answers = [f.result(timeout=60) for f in flood]
    codes = [r.status_code for r in answers]
    assert set(codes) == {401, 429}
    # argon2 ran for the admitted ones only, one at a time (as for the JSON sign-in above)
    assert gate.free_failures <= codes.count(401) <= gate.free_failures + gate.workers


def test_an_attackers_failures_do_not_lock_the_user_out_from_another_computer(app, anna):
    with TestClient(app, client=("192.0.2.66", 40000), base_url=LOCAL) as attacker, \
            TestClient(app, client=("198.51.100.20", 40001), base_url=LOCAL) as setter:
        codes = [_sign_in(attacker, "guess").status_code for _ in range(8)]
        assert codes == [401] * 5 + [429] * 3
        refused = _sign_in(attacker, PASSWORD)       # the attacker's computer waits, right or wrong
        assert refused.status_code == 429 and refused.json()["error"]["code"] == "too_many_attempts"
        assert int(refused.headers["Retry-After"]) >= 1
        signed = _sign_in(setter, PASSWORD)
        assert signed.status_code == 200 and signed.json()["name"] == "anna"


def test_opc_ua_failures_do_not_lock_http_of_the_same_computer(app, anna):
    for _ in range(8):
        with pytest.raises(SignInRefused):
            anna.verify_password("anna", "guess", (OPCUA, "192.0.2.66"))
    with pytest.raises(SignInRefused) as held:
        anna.verify_password("anna", PASSWORD, (OPCUA, "192.0.2.66"))
    assert held.value.status == 429
    with TestClient(app, client=("192.0.2.66", 40000), base_url=LOCAL) as same_computer:
        assert _sign_in(same_computer, PASSWORD).status_code == 200


def test_a_failed_sign_in_costs_no_more_memory_than_a_right_one(anna):
    """Unknown users are checked against a hash of the same parameters as real ones, and the pool
    bounds what checks can hold at once (argon2's m is its memory in KiB)."""
    anna.verify_password("anna", PASSWORD)
    with pytest.raises(SignInRefused):
        anna.verify_password("nobody", PASSWORD)
    with anna._db.unit(readonly=True) as unit:
        stored = unit.get_user("anna", with_hash=True)["password_hash"]
    memory = {int(re.search(r"\$m=(\d+),", h).group(1)) for h in (stored, anna._dummy())}
    assert len(memory) == 1
    assert anna.gate.workers * memory.pop() * 1024 <= 50e6


def test_an_old_hash_is_renewed_at_the_next_right_sign_in(anna, app):
    from pwdlib import PasswordHash

    old = PasswordHash.recommended().hash(PASSWORD)          # argon2's default: 64 MiB
    with anna._db.unit() as unit:
        unit.set_password_hash("anna", old)
    anna.verify_password("anna", PASSWORD)
    with anna._db.unit(readonly=True) as unit:
        renewed = unit.get_user("anna", with_hash=True)["password_hash"]
    assert renewed != old and "$m=19456,t=2,p=1$" in renewed
    anna.verify_password("anna", PASSWORD)                   # the renewed hash signs in


# --- password policy ---------------------------------------------------------------------------

@pytest.mark.parametrize("level", [1, 2, 3])
def test_passwords_of_every_password_level_have_at_least_8_characters(anna, level):
    with pytest.raises(AccessError, match="password: at least 8 characters"):
        anna.add_user(f"short{level}", level, "1234567")
    assert anna.add_user(f"long{level}", level, "12345678")["level"] == level


def test_a_short_password_is_refused_by_the_api_naming_the_field(app, anna):
    token, _ = anna.add_token("admin", 1)
    with TestClient(app) as client:
        answer = client.post("/api/users", json={"name": "bert", "password": "abcd", "level": 3},
                             headers={"Authorization": f"Bearer {token}"})
        assert answer.status_code == 422 and answer.json()["error"]["field"] == "password"
        assert [u["name"] for u in client.get("/api/users", headers={"Authorization": f"Bearer {token}"}).json()] \
            == ["anna"]

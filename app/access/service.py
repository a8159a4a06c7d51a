"""Users, API tokens, sign-in sessions and the simulated keyswitch (design.md §9.2).

- Passwords are hashed with argon2id by pwdlib (a maintained library made for it); the hash is
  all the database holds.
- API tokens and session cookies are 256-bit random secrets; the database holds their SHA-256 (a
  random secret of that size needs no slow hash), so a stolen database signs nobody in.
- Sign-in is on as soon as one user exists (the check is cached for a second, so a user added by
  ``python -m app user add`` in another process takes effect at once, near enough).
- The keyswitch is machine state (``machine_state`` "keyswitch", position 0..3, default 0); the
  operator panel's session has the keyswitch's level, read on every request.
"""

from __future__ import annotations

import hashlib
import logging
import re
import secrets
import time
from datetime import UTC, datetime, timedelta
from http.cookies import CookieError, SimpleCookie

from pwdlib import PasswordHash
from pwdlib.hashers.argon2 import Argon2Hasher

from db import Database, StorageUnavailable

from .identity import ANONYMOUS, INVALID, NOBODY, PANEL, TOKEN, TRAINER, USER, Identity
from .levels import KEYSWITCH_POSITIONS, PASSWORD_LEVELS, TOKEN_LEVELS, TRAINER_LEVEL, keyswitch_level
from .throttle import HTTP, SignInGate, Throttled

log = logging.getLogger(__name__)
SESSION_COOKIE = "hmi_session"
CSRF_COOKIE = "csrftoken"
NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.@-]{0,63}$")
MIN_PASSWORD = 8            # every password level (1-3): docs/access.md
TOKEN_PREFIX = "hmi_"
STATE_KEYSWITCH = "keyswitch"
STATE_CSRF_SECRET = "access.csrf_secret"
USERS_CACHE_S = 1.0
# argon2id as OWASP's Password Storage Cheat Sheet recommends (m = 19 MiB, t = 2, p = 1): the
# memory a check costs is what bounds the sign-in pool's memory (2 checks: < 40 MiB). A hash made
# with other parameters (argon2's default 64 MiB) is re-made at the next successful sign-in.
ARGON2_MEMORY_KIB, ARGON2_TIME, ARGON2_PARALLELISM = 19456, 2, 1


class AccessError(ValueError):
    """Bad input to an administration call (name, level, password)."""


class SignInRefused(Exception):
    def __init__(self, message: str, status: int = 401, code: str = "sign_in_failed",
                 retry_after_s: int | None = None):
        super().__init__(message)
        self.message, self.status, self.code = message, status, code
        self.retry_after_s = retry_after_s


def digest(secret: str) -> str:
    return hashlib.sha256(secret.encode()).hexdigest()


def _now() -> datetime:
    return datetime.now(UTC)


def check_name(name: str, what: str = "name") -> str:
    if not isinstance(name, str) or not NAME.match(name):
        raise AccessError(f"{what}: 1-64 letters, digits or _.@- (starting with a letter or digit)")
    return name


def check_level(level, allowed: tuple[int, ...], what: str) -> int:
    if isinstance(level, bool) or not isinstance(level, int) or level not in allowed:
        raise AccessError(f"level: a {what} has level {allowed[0]}..{allowed[-1]}, got {level!r}")
    return level


def check_password(password) -> str:
    if not isinstance(password, str) or len(password) < MIN_PASSWORD:
        raise AccessError(f"password: at least {MIN_PASSWORD} characters")
    return password


class AccessService:
    def __init__(self, db: Database, session_hours: float = 8.0):
        self._db = db
        self._session_hours = session_hours
        self._hasher = PasswordHash((Argon2Hasher(time_cost=ARGON2_TIME, memory_cost=ARGON2_MEMORY_KIB,
                                                   parallelism=ARGON2_PARALLELISM),))
        self._dummy_hash: str | None = None
        self._users_cache: tuple[float, bool] | None = None
        self.gate = SignInGate()

    # --- mode -------------------------------------------------------------------------------
    def signin_on(self) -> bool:
        """At least one user exists (else: the stand-alone trainer)."""
        cached = self._users_cache
        now = time.monotonic()
        if cached is not None and now - cached[0] < USERS_CACHE_S:
            return cached[1]
        with self._db.unit(readonly=True) as unit:
            exists = unit.users_exist()
        self._users_cache = (now, exists)
        return exists

    def _forget_users(self) -> None:
        self._users_cache = None

    # --- users ------------------------------------------------------------------------------
    def add_user(self, name: str, level: int, password: str) -> dict:
        check_name(name, "user")
        check_level(level, PASSWORD_LEVELS, "user (password)")
        password_hash = self._hasher.hash(check_password(password))
        with self._db.unit() as unit:
            try:
                user = unit.add_user(name, level, password_hash)
            except ValueError as exc:
                raise AccessError(str(exc)) from None
            unit.add_audit("user", name, None, user, "users")
        self._forget_users()
        return user

    def set_password(self, name: str, password: str) -> None:
        password_hash = self._hasher.hash(check_password(password))
        with self._db.unit() as unit:
            try:
                unit.set_password_hash(name, password_hash)
            except KeyError:
                raise AccessError(f"no user {name!r}") from None
            unit.add_audit("user", name, None, {"name": name, "password": "changed"}, "users")

    def delete_user(self, name: str) -> dict:
        with self._db.unit() as unit:
            try:
                user = unit.delete_user(name)
            except KeyError:
                raise AccessError(f"no user {name!r}") from None
            unit.add_audit("user", name, user, None, "users")
        self._forget_users()
        return user

    def list_users(self) -> list[dict]:
        with self._db.unit(readonly=True) as unit:
            return unit.list_users()

    # --- tokens -----------------------------------------------------------------------------
    def add_token(self, name: str, level: int) -> tuple[str, dict]:
        """(the secret, shown once; the stored record without it)."""
        check_name(name, "token")
        check_level(level, TOKEN_LEVELS, "token")
        secret = TOKEN_PREFIX + secrets.token_urlsafe(32)
        with self._db.unit() as unit:
            try:
                record = unit.add_token(name, level, digest(secret))
            except ValueError as exc:
                raise AccessError(str(exc)) from None
            unit.add_audit("token", name, None, record, "users")
        return secret, record

    def delete_token(self, name: str) -> dict:
        with self._db.unit() as unit:
            try:
                record = unit.delete_token(name)
            except KeyError:
                raise AccessError(f"no token {name!r}") from None
            unit.add_audit("token", name, record, None, "users")
        return record

    def list_tokens(self) -> list[dict]:
        with self._db.unit(readonly=True) as unit:
            return unit.list_tokens()

    # --- keyswitch --------------------------------------------------------------------------
    def keyswitch(self) -> int:
        with self._db.unit(readonly=True) as unit:
            position = unit.get_state(STATE_KEYSWITCH, 0)
        return position if position in KEYSWITCH_POSITIONS else 0

    def set_keyswitch(self, position: int, source: str = "api") -> dict:
        if isinstance(position, bool) or position not in KEYSWITCH_POSITIONS:
            raise AccessError("position: the keyswitch has positions 0..3")
        with self._db.unit() as unit:
            before = unit.get_state(STATE_KEYSWITCH, 0)
            unit.set_state(STATE_KEYSWITCH, position)
            unit.add_audit("keyswitch", "keyswitch", {"position": before}, {"position": position}, source)
        return {"position": position, "level": keyswitch_level(position)}

    # --- sessions ---------------------------------------------------------------------------
    def sign_in(self, name: str, password: str, source: tuple[str, str] = (HTTP, "")) -> tuple[str, Identity]:
        """(cookie secret, identity); SignInRefused for a wrong name or password (one message
        for both), and 429 at once while ``source`` (channel, address) must wait or the password
        checks are all busy (app/access/throttle.py)."""
        identity = self.verify_password(name, password, source)
        return self._open_session(name, identity)

    def verify_password(self, name: str, password: str, source: tuple[str, str] = (HTTP, "")) -> Identity:
        """The user's identity when the password is right (no session: the OPC UA endpoint signs
        in per connection); SignInRefused as ``sign_in``, with the same bounds."""
        if not isinstance(name, str) or not isinstance(password, str):
            raise SignInRefused("user and password are required", 422, "validation")
        try:
            self.gate.check_source(source)
            user, right = self.gate.run(lambda: self._check(name, password, source))
        except Throttled as exc:
            raise SignInRefused(exc.message, 429, exc.code, exc.retry_after_s) from None
        if not right:
            self.gate.failed(source)
            raise SignInRefused("wrong user name or password")
        self.gate.succeeded(source)
        return Identity(USER, name, user["level"])

    def _check(self, name: str, password: str, source: tuple[str, str]) -> tuple[dict, bool]:
        """(the user, whether the password is right); an unknown user costs the same work. The
        source is looked at again when the check's turn comes: the failures of the tries queued
        before it may have made it wait meanwhile."""
        self.gate.check_source(source)
        with self._db.unit(readonly=True) as unit:
            user = unit.get_user(name, with_hash=True)
        if user is None:
            self._hasher.verify(password, self._dummy())
            return {}, False
        right, new_hash = self._hasher.verify_and_update(password, user["password_hash"])
        if right and new_hash is not None:
            self._rehash(name, new_hash)
        return user, right

    def _rehash(self, name: str, new_hash: str) -> None:
        """The same password under today's parameters; a database that cannot be written keeps
        the old hash (the sign-in itself goes on)."""
        try:
            with self._db.unit() as unit:
                unit.set_password_hash(name, new_hash)
        except StorageUnavailable as exc:       # a read-only database: the sign-in goes on
            log.warning("password hash of %r not renewed: %s", name, exc)

    def user_identity(self, name: str) -> Identity | None:
        """The user's identity with the level stored now; None when the user is gone."""
        with self._db.unit(readonly=True) as unit:
            user = unit.get_user(name)
        return None if user is None else Identity(USER, name, user["level"])

    def sign_in_panel(self) -> tuple[str, Identity]:
        """The operator panel (the browser on the machine's own computer): no password, the
        keyswitch's level. The caller checks that the request comes from this computer."""
        return self._open_session(None, Identity(PANEL, "panel", keyswitch_level(self.keyswitch())))

    def _open_session(self, user: str | None, identity: Identity) -> tuple[str, Identity]:
        secret = secrets.token_urlsafe(32)
        expires = (_now() + timedelta(hours=self._session_hours)).isoformat(timespec="microseconds")
        with self._db.unit() as unit:
            unit.add_session(digest(secret), user, expires)
        return secret, Identity(identity.kind, identity.name, identity.level, expires)

    def sign_out(self, secret: str | None) -> None:
        if secret:
            with self._db.unit() as unit:
                unit.delete_session(digest(secret))

    @property
    def session_seconds(self) -> int:
        return int(self._session_hours * 3600)

    def _dummy(self) -> str:
        if self._dummy_hash is None:
            self._dummy_hash = self._hasher.hash(secrets.token_urlsafe(16))
        return self._dummy_hash

    # --- who is this request ----------------------------------------------------------------
    def resolve(self, authorization: str | None, cookie_header: str | None) -> Identity:
        """Bearer token first, then the session cookie; without either: the trainer when no user
        exists, else nobody. Wrong credentials are INVALID (401), never the trainer."""
        scheme, _, bearer = (authorization or "").partition(" ")
        if scheme.lower() == "bearer" and not bearer.strip() and not self.signin_on():
            authorization = None            # an empty "Bearer " of a trainer-mode client: no credentials
        if authorization:
            scheme, _, bearer = authorization.partition(" ")
            if scheme.lower() != "bearer" or not bearer.strip():
                return Identity(INVALID, reason="Authorization must be 'Bearer <token>'")
            with self._db.unit(readonly=True) as unit:
                token = unit.token_by_hash(digest(bearer.strip()))
            if token is None:
                return Identity(INVALID, reason="unknown or revoked API token")
            return Identity(TOKEN, token["name"], token["level"])
        secret = session_secret(cookie_header)
        if secret:
            with self._db.unit(readonly=True) as unit:
                session = unit.get_session(digest(secret))
                position = unit.get_state(STATE_KEYSWITCH, 0) if session and session["user"] is None else 0
            if session is not None:
                user = session["user"]
                if user is None:
                    level = keyswitch_level(position if position in KEYSWITCH_POSITIONS else 0)
                    return Identity(PANEL, "panel", level, session["expires"])
                return Identity(USER, user["name"], user["level"], session["expires"])
        if not self.signin_on():
            return Identity(TRAINER, None, TRAINER_LEVEL)
        return NOBODY

    def csrf_secret(self) -> str:
        """The CSRF tokens' signing secret, kept in the database so tokens outlive a restart."""
        with self._db.unit(readonly=True) as unit:
            secret = unit.get_state(STATE_CSRF_SECRET)
        if isinstance(secret, str) and len(secret) >= 32:
            return secret
        if self._db.read_only:          # kept for this run only: tokens end with it
            return secrets.token_urlsafe(48)
        with self._db.unit() as unit:
            secret = unit.get_state(STATE_CSRF_SECRET)
            if not (isinstance(secret, str) and len(secret) >= 32):
                secret = secrets.token_urlsafe(48)
                unit.set_state(STATE_CSRF_SECRET, secret)
        return secret


def session_secret(cookie_header: str | None) -> str | None:
    if not cookie_header:
        return None
    cookies = SimpleCookie()
    try:
        cookies.load(cookie_header)
    except CookieError:      # a malformed Cookie header is no session
        return None
    morsel = cookies.get(SESSION_COOKIE)
    return morsel.value if morsel is not None and morsel.value else None


__all__ = ["ANONYMOUS", "CSRF_COOKIE", "SESSION_COOKIE", "AccessError", "AccessService", "SignInRefused"]

"""Fixtures of the access tests: an app with sign-in on (one user per password level) and tokens at
every level 1..7."""

from __future__ import annotations

import pytest
from access_helpers import PASSWORDS
from fastapi.testclient import TestClient


@pytest.fixture
def access(app):
    return app.state.access


@pytest.fixture
def signin_client(app, access):
    """Sign-in on: user anna (level 3) exists; the client itself sends no credentials."""
    password, level = PASSWORDS["anna"]
    access.add_user("anna", level, password)
    with TestClient(app) as client:
        yield client


@pytest.fixture
def tokens(access, signin_client) -> dict[int, dict]:
    """{level: Authorization header} for a token at each level 1..7."""
    out = {}
    for level in range(1, 8):
        secret, _record = access.add_token(f"mes{level}", level)
        out[level] = {"Authorization": f"Bearer {secret}"}
    return out

"""Waiting on state instead of sleeping a guessed time: a test goes on as soon as the state it
needs is there, and fails with a message (not a hang) when it never comes."""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import TypeVar

T = TypeVar("T")
POLL_S = 0.01          # between looks; the limit is only a guard against a hang, never a bar


def wait_until(check: Callable[[], T], what: str, limit_s: float = 30.0) -> T:
    """``check()`` once it is truthy (its value), else AssertionError naming ``what``."""
    pause = threading.Event()
    waited = 0.0
    while True:
        value = check()
        if value:
            return value
        if waited >= limit_s:
            raise AssertionError(f"waited {limit_s:g} s in vain: {what}")
        pause.wait(POLL_S)
        waited += POLL_S

"""The level check for writes outside a route (the measuring commit), from the acting identity of
the context (``db.current_actor()``)."""

from __future__ import annotations

from db import current_actor

from .errors import AccessDenied
from .levels import required_level


def check_actor(settings, functions: list[str]) -> None:
    """For writes outside a route (the measuring commit): the acting identity of the context may do
    each of ``functions``; no identity in context (internal calls, tests of a service) passes."""
    actor = current_actor()
    if actor is None or actor.level is None:
        return
    gud = settings.get()
    for function in functions:
        needed = required_level(gud, function)
        if actor.level > needed:
            raise AccessDenied(function, needed, actor.level, actor.who)

"""Who is acting in a request: a signed-in user, the operator panel, an API token, the trainer, or
nobody (sign-in is on and no credentials came)."""

from __future__ import annotations

from dataclasses import dataclass

from db import Actor

from .levels import LOWEST, describe_level

TRAINER, USER, PANEL, TOKEN, ANONYMOUS, INVALID = "trainer", "user", "panel", "token", "anonymous", "invalid"


@dataclass(frozen=True)
class Identity:
    kind: str                      # one of the names above
    name: str | None = None        # user or token name; "panel"; None
    level: int | None = None       # the protection level it acts with; None: nobody (or invalid)
    expires: str | None = None     # a session's end (UTC ISO)
    reason: str = ""               # INVALID: why the credentials were refused

    @property
    def authenticated(self) -> bool:
        return self.level is not None

    @property
    def who(self) -> str:
        """As the audit rows name it: "user:anna", "token:mes", "panel", "trainer"."""
        if self.kind in (USER, TOKEN):
            return f"{self.kind}:{self.name}"
        return self.kind

    @property
    def actor(self) -> Actor | None:
        return Actor(self.who, self.level) if self.authenticated else None

    @property
    def label(self) -> str:
        """For the header: "anna · level 2", "Operator panel · level 7", "Trainer"."""
        if self.kind == TRAINER:
            return "Trainer (no sign-in)"
        if self.kind == PANEL:
            return f"Operator panel · {describe_level(self.level if self.level is not None else LOWEST)}"
        if self.level is not None:                      # authenticated
            return f"{self.name} · {describe_level(self.level)}"
        return "not signed in"

    def may(self, required: int) -> bool:
        return self.level is not None and self.level <= required


NOBODY = Identity(ANONYMOUS)

"""The refusals of the access checks: 401 (who are you?) and 403 ``access_level`` (naming the level
needed). ``AccessDenied`` is a ``WorkflowError`` so that the measuring screens show it in place."""

from __future__ import annotations

from app.errors import HmiError, WorkflowError

from .levels import FUNCTIONS, describe_level, how_to_reach


class Unauthenticated(HmiError):
    status = 401
    code = "unauthenticated"


class AccessDenied(WorkflowError):
    def __init__(self, function: str, required: int, level: int | None, who: str = ""):
        label = FUNCTIONS[function].label if function in FUNCTIONS else function
        have = describe_level(level) if level is not None else "no level"
        message = (f"{label} needs access level {required} ({how_to_reach(required)}); "
                   f"{who + ' has' if who else 'you have'} {have}")
        super().__init__(403, "access_level", message)
        self.function, self.required, self.level = function, required, level

    def short(self) -> str:
        """For a disabled softkey: "level 5 needed (keyswitch 2)"."""
        return f"needs level {self.required}: {how_to_reach(self.required)}"

"""CYCLE198 / CYCLE199 (manual §3.2): user programs the control runs before and after every
measuring cycle when a program of that name is stored (design.md §10.2).

The hook runs as its own program on the same machine: the active zero offset, the tool and the
axes as the cycle finds or leaves them; its variables are its own (R parameters and DEF of the
hook do not touch the calling program's) and it calls no measuring cycle. An alarm of the hook
stops the calling program at the cycle's block, naming the hook and its line.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

from app.nc.errors import NcSyntaxError
from app.nc.interpreter import CycleContext, Interpreter
from app.nc.variables import Variables
from engine import alarms

BEFORE, AFTER = "CYCLE198", "CYCLE199"


class HookSource(Protocol):
    def user_hook(self, name: str) -> str | None:
        """The stored program text of ``name`` (CYCLE198 / CYCLE199), None when there is none."""


def run_hook(source: HookSource, ctx: CycleContext, name: str) -> None:
    text = source.user_hook(name)
    if text is None:
        return
    hook = Interpreter(ctx.runtime, Variables(axes=tuple(ctx.runtime.axes)), {})
    try:
        hook.load(text, name)
    except NcSyntaxError as exc:
        raise ctx.alarm(exc.alarm or alarms.NC_SYNTAX, f"{name} line {exc.line}: {exc.message}") from None
    result = hook.run()
    if result.state == "alarm" and result.alarm is not None:
        alarm = result.alarm
        raise ctx.alarm(alarm.alarm or alarms.NC_INTERNAL, f"{name} line {alarm.line}: {alarm.message}")
    if result.state != "done":
        raise ctx.alarm(alarms.NC_INTERNAL, f"{name} stopped ({result.reason}): a hook runs to its end (M17/M2)")


def hooked(source: HookSource, handler: Callable[[CycleContext], None]) -> Callable[[CycleContext], None]:
    """``handler`` with CYCLE198 before and CYCLE199 after it."""
    def run(ctx: CycleContext) -> None:
        run_hook(source, ctx, BEFORE)
        handler(ctx)
        run_hook(source, ctx, AFTER)
    return run

"""A bug inside a cycle is no silent failure (issue 27 item 6): the channel alarms with the NC's
internal-error alarm and the HMI log keeps the traceback."""

from __future__ import annotations

import logging

from nc_runtimes import FakeRuntime

from app.nc.interpreter import Interpreter
from app.nc.variables import Variables
from engine import alarms


def _broken_cycle(ctx) -> None:
    return {}["no such key"]          # a KeyError: a bug, not an NC alarm


def test_an_internal_error_in_a_cycle_alarms_and_is_logged_with_its_traceback(caplog):
    interp = Interpreter(FakeRuntime(), Variables(), cycles={"CYCLE977": _broken_cycle})
    interp.load("N10 CYCLE977\nN20 M30")
    with caplog.at_level(logging.ERROR, logger="app.nc.interpreter"):
        result = interp.run()
    assert result.state == "alarm"
    assert result.alarm is not None and result.alarm.alarm is alarms.NC_INTERNAL
    assert "internal error" in str(result.alarm) and "no such key" in str(result.alarm)
    logged = [r for r in caplog.records if r.name == "app.nc.interpreter" and r.exc_info]
    assert logged and logged[0].exc_info[0] is KeyError
    assert "_broken_cycle" in caplog.text            # the traceback names where it broke

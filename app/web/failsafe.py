"""A picture that cannot be drawn (issue 27 item 6): the screens' previews, 3D scene and help
tables catch the domain errors by type (bad or missing input, no record, a machine alarm or a
busy machine, no storage) and draw nothing for them, because the screen already says why. Anything
else is a bug: it is logged with its traceback and the screen shows an error in the picture's
place instead of an empty picture."""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import TypeVar

from markupsafe import Markup, escape

from app.errors import HmiError
from app.i18n import _
from app.machine.protocol import MachineAlarm, MachineBusy
from db.database import StorageUnavailable
from engine.types import MeasuringError

log = logging.getLogger("app.web")

# what a picture may meet in normal use; ValueError is the engine's refusal of a shape or a value
EXPECTED = (HmiError, MachineAlarm, MachineBusy, StorageUnavailable, MeasuringError, ValueError)


def picture_failed(what: str) -> Markup:
    """Log the exception being handled (a bug) and give the error line the screen shows instead."""
    log.exception("drawing %s failed", what)
    return Markup('<p class="alarm picture-error">{}</p>').format(
        escape(_("The picture could not be drawn: internal error (see the HMI log).")))


T = TypeVar("T")
F = TypeVar("F")


class PictureFailed(Exception):
    """A part of a picture met a bug, logged with its traceback: ``line`` is the error line the
    screen shows in the picture's place."""

    def __init__(self, line: Markup):
        super().__init__(str(line))
        self.line = line


def drawn(what: str, compute: Callable[[], T], fallback: F) -> T | F:
    """``compute()``, or ``fallback`` on a domain error (the screen already says why). Anything
    else is a bug: logged with its traceback, then raised as PictureFailed."""
    try:
        return compute()
    except EXPECTED:
        return fallback
    except Exception as exc:        # a bug: logged, and shown in the picture's place
        raise PictureFailed(picture_failed(what)) from exc

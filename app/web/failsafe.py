"""A picture that cannot be drawn (issue 27 item 6): the screens' previews, 3D scene and help
tables catch the domain errors by type (bad or missing input, no record, a machine alarm or a
busy machine, no storage) and draw nothing for them, because the screen already says why. Anything
else is a bug: it is logged with its traceback and the screen shows an error in the picture's
place instead of an empty picture."""

from __future__ import annotations

import logging

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

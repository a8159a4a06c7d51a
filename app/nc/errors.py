"""Errors of the NC language, in operator words, with the line and column of the block.

- ``NcSyntaxError``: found when a program is loaded (grammar, unknown names, words that may not
  stand in one block): nothing has moved.
- ``NcAlarm``: raised while a block executes (a measuring move that did not switch, G101
  without a measured value, a collision reported by the runtime, ...).
- ``NcRuntimeError``: what an ``NcRuntime`` raises when the machine refuses or aborts a command;
  the interpreter turns it into an ``NcAlarm`` at the block that gave the command.

Every error carries an ``engine.alarms`` catalogue entry where one fits (``alarm``), never a
literal number.
"""

from __future__ import annotations

from engine import alarms
from engine.alarms import AlarmDef


class NcError(Exception):
    """An error located in a program: ``line`` and ``column`` are 1-based."""

    def __init__(self, message: str, line: int | None = None, column: int | None = None, *,
                 alarm: AlarmDef | None = None, block_text: str | None = None):
        self.message = message
        self.line = line
        self.column = column
        self.alarm = alarm
        self.block_text = block_text
        super().__init__(self.__str__())

    @property
    def where(self) -> str:
        if self.line is None:
            return ""
        if self.column is None:
            return f"line {self.line}"
        return f"line {self.line}, column {self.column}"

    def __str__(self) -> str:
        where = self.where
        return f"{self.message} in {where}" if where else self.message

    def to_dict(self) -> dict:
        """JSON-ready: ``{"code", "name", "text", "message", "line", "column", "block"}``."""
        return {
            "code": self.alarm.number if self.alarm else None,
            "name": self.alarm.name if self.alarm else None,
            "text": self.alarm.text if self.alarm else None,
            "message": str(self),
            "line": self.line,
            "column": self.column,
            "block": self.block_text,
        }


class NcSyntaxError(NcError):
    """The program cannot run as written (raised by ``parse_program`` / ``Interpreter.load``)."""

    def __init__(self, message: str, line: int | None = None, column: int | None = None, *,
                 alarm: AlarmDef | None = None, block_text: str | None = None):
        super().__init__(message, line, column, alarm=alarm or alarms.NC_SYNTAX, block_text=block_text)


class NcAlarm(NcError):
    """A block could not be executed; the program stops at that block."""


class NcRuntimeError(Exception):
    """Raised by an ``NcRuntime`` when the machine refuses or aborts a command.

    ``alarm`` is the catalogue entry of what happened (collision, limit switch, Reset, unknown
    tool...), ``message`` says it in operator words.
    """

    def __init__(self, message: str, alarm: AlarmDef | None = None):
        super().__init__(message)
        self.message = message
        self.alarm = alarm

"""The NC language core (design.md §9.4): grammar, parser, variables, expressions and an
interpreter with modal state that runs part programs block by block on an ``NcRuntime``.

    from app.nc import Interpreter, Variables

    interp = Interpreter(runtime, Variables(backings={"_EV": ev_store, "_MV": mv_store}),
                         cycles={"CYCLE977": cycle977})
    interp.load(text)            # NcSyntaxError(line, column) before anything moves
    result = interp.run()        # or step(); request_stop() from another thread
    result.state                 # "done" | "stopped" | "alarm"; result.alarm is an NcAlarm

``runtime`` implements ``app.nc.runtime.NcRuntime`` (the machine), a cycle handler is
``handler(ctx: CycleContext) -> None``.
"""

from .errors import NcAlarm, NcError, NcRuntimeError, NcSyntaxError
from .interpreter import BlockRef, CycleContext, CycleHandler, Interpreter, NcStateError, RunResult
from .modal import ModalState
from .offsets import MeasuringOffsets
from .parser import parse_program, parse_reference
from .runtime import MeasureResult, NcRuntime
from .variables import Backing, CallbackBacking, VarDef, VariableError, Variables

__all__ = [
    "Backing", "BlockRef", "CallbackBacking", "CycleContext", "CycleHandler", "Interpreter", "MeasureResult",
    "MeasuringOffsets", "ModalState", "NcAlarm", "NcError", "NcRuntime", "NcRuntimeError", "NcStateError",
    "NcSyntaxError", "RunResult", "VarDef", "VariableError", "Variables", "parse_program", "parse_reference",
]

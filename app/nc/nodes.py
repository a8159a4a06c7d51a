"""The parsed program: immutable nodes with their source position (1-based line and column).

Names are upper case (the language is case-insensitive); numbers are Python ints or floats.
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class Pos:
    line: int
    column: int


# --- expressions ---------------------------------------------------------------------------------

@dataclass(frozen=True)
class Num:
    value: int | float
    pos: Pos


@dataclass(frozen=True)
class Str:
    value: str
    pos: Pos


@dataclass(frozen=True)
class Var:
    """A variable reference: ``R1`` is ``Var("R", (Num(1),))``, ``_EV[9]``, ``$AA_MM[X]``."""

    name: str
    indices: tuple[Expr, ...]
    pos: Pos

    @property
    def text(self) -> str:
        return self.name if not self.indices else f"{self.name}[...]"


@dataclass(frozen=True)
class Unary:
    op: str                 # "-", "+", "NOT"
    operand: Expr
    pos: Pos


@dataclass(frozen=True)
class Binary:
    op: str                 # + - * / DIV MOD == <> < > <= >= AND OR XOR
    left: Expr
    right: Expr
    pos: Pos


@dataclass(frozen=True)
class Func:
    name: str
    args: tuple[Expr, ...]
    pos: Pos


Expr = Num | Str | Var | Unary | Binary | Func


# --- words (the parts of a block) ----------------------------------------------------------------

@dataclass(frozen=True)
class GCode:
    number: int
    pos: Pos

    @property
    def name(self) -> str:
        return f"G{self.number}"


@dataclass(frozen=True)
class MCode:
    number: int
    pos: Pos


@dataclass(frozen=True)
class Address:
    """F, S, T, D with a constant (``F150``) or an expression (``F=R1*2``)."""

    letter: str
    value: Expr
    pos: Pos


@dataclass(frozen=True)
class AxisWord:
    """``X10`` or ``X=R1+2``: a position, an increment, a G100 target, a G101 factor."""

    axis: str
    value: Expr
    pos: Pos


@dataclass(frozen=True)
class Assign:
    """``R1=5``, ``_EV[9]=0.004``, ``_SETV[0]=SET(1,2,3)`` (``values`` has one item unless SET)."""

    target: Var
    values: tuple[Expr, ...]
    pos: Pos
    is_set: bool = False


@dataclass(frozen=True)
class Meas:
    """``MEAS=1`` (delete the distance to go on the trigger) or ``MEAW=1`` (go on to the end)."""

    kind: str               # "MEAS" or "MEAW"
    value: Expr
    pos: Pos


@dataclass(frozen=True)
class Spos:
    value: Expr
    pos: Pos


@dataclass(frozen=True)
class CycleCall:
    """``CYCLE977``, ``CYCLE977(...)`` or ``L977``: a name looked up in the cycle registry."""

    name: str
    args: tuple[Expr, ...]
    pos: Pos


@dataclass(frozen=True)
class Goto:
    direction: str          # "GOTOF", "GOTOB", "GOTO"
    target: str             # label name or "N<number>"
    pos: Pos


@dataclass(frozen=True)
class Msg:
    value: Expr | None
    pos: Pos


@dataclass(frozen=True)
class Stopre:
    pos: Pos


@dataclass(frozen=True)
class Diameter:
    """DIAMON (``on``) / DIAMOF: X values as diameters or radii (840D G group 29; a lathe only)."""

    on: bool
    pos: Pos

    @property
    def name(self) -> str:
        return "DIAMON" if self.on else "DIAMOF"


@dataclass(frozen=True)
class IfGoto:
    condition: Expr
    goto: Goto
    pos: Pos


@dataclass(frozen=True)
class DefItem:
    name: str
    dims: tuple[int, ...]
    init: Expr | None
    pos: Pos


@dataclass(frozen=True)
class Define:
    """``DEF REAL A, B[10]=2``: local user data (LUD) of the program."""

    type: str               # REAL, INT, BOOL, STRING
    length: int | None      # STRING[32]
    items: tuple[DefItem, ...]
    pos: Pos


Word = (GCode | MCode | Address | AxisWord | Assign | Meas | Spos | CycleCall | Goto | Msg
        | Stopre | IfGoto | Define)


@dataclass(frozen=True)
class Block:
    """One line of the program that holds something to execute (or only N / a label)."""

    index: int              # position in Program.blocks
    line: int
    text: str               # the source line as written
    number: int | None      # N number
    label: str | None
    words: tuple[Word, ...]
    pos: Pos

    def gcodes(self) -> tuple[GCode, ...]:
        return tuple(w for w in self.words if isinstance(w, GCode))


@dataclass(frozen=True)
class Program:
    name: str
    text: str
    blocks: tuple[Block, ...]
    header: str | None = None                       # "%_N_TEST_MPF" line
    labels: dict[str, int] = field(default_factory=dict)   # label -> block index
    #: jump target ("LABEL", "N10") -> block indices, ascending (parser.jump_targets); None: not indexed
    targets: dict[str, tuple[int, ...]] | None = field(default=None, compare=False)

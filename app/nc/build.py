"""The words and expressions of a block as nodes: what the grammar's rules build, shared by
both readers of a program (``parser``: lark's LALR parser, which also words every syntax error;
``fastparse``: the hand-written reader of correct programs). Raises ``NcSyntaxError`` for
invalid words, whichever reader found them.
"""

from __future__ import annotations

from lark import Token, Transformer

from . import nodes as n
from .errors import NcSyntaxError
from .modal import AXIS_LETTERS

_UNSUPPORTED_ADDRESS = {
    "I": "circle and helix parameters (I, J, K) are not part of this control's language",
    "J": "circle and helix parameters (I, J, K) are not part of this control's language",
    "K": "circle and helix parameters (I, J, K) are not part of this control's language",
    "H": "auxiliary functions H are not part of this control's language",
    "E": "exponent notation and E words are not part of this control's language",
}
_STRUCTURED = {"ELSE", "ENDIF", "WHILE", "ENDWHILE", "FOR", "ENDFOR", "LOOP", "ENDLOOP", "REPEAT",
               "UNTIL", "CASE", "RET", "PROC"}
TYPES = {"REAL", "INT", "BOOL", "STRING"}


def pos_of(item) -> n.Pos:
    if isinstance(item, Token):
        assert item.line is not None and item.column is not None    # the lexer's tokens carry them
        return n.Pos(item.line, item.column)
    return n.Pos(item.meta.line, item.meta.column)


def lc(pos: n.Pos) -> tuple[int, int]:
    return pos.line, pos.column


def number_value(text: str) -> int | float:
    text = text.strip()
    if "." in text:
        return float(text)
    return int(text)


# --- expressions ------------------------------------------------------------------------------

def rparam(text: str, line: int, column: int) -> n.Var:
    """``R5`` written at ``line``, ``column``: the variable R with the index 5."""
    return n.Var("R", (n.Num(int(text[1:]), n.Pos(line, column + 1)),), n.Pos(line, column))


def unary(op: str, operand: n.Expr, pos: n.Pos) -> n.Unary:
    return n.Unary(op.upper(), operand, pos)


#: how strongly an operator binds (840D: comparisons weakest, then << (text concatenation), OR,
#: XOR, AND, + -, * / DIV MOD), by the operator's terminal
PRIORITY = {"CMP_OP": 1, "CONCAT": 1.5, "OR": 2, "XOR": 3, "AND": 4, "ADD_OP": 5, "MUL_OP": 6, "DIV": 6,
            "MOD": 6}


def climb(items: list) -> n.Expr:
    """``operand (operator operand)*`` -> the tree of binary operations: left-associative, by
    ``PRIORITY``; one comparison per chain (``a < b < c`` means nothing on the 840D). An
    operator is ``(terminal, text, pos)``."""
    if len(items) == 3:                         # one operator: nothing to weigh
        _kind, text, pos = items[1]
        return n.Binary(text.upper(), items[0], items[2], pos)
    operands: list[n.Expr] = [items[0]]
    operators: list[tuple[str, str, n.Pos]] = []
    comparison: tuple[str, str, n.Pos] | None = None

    def reduce() -> None:
        _kind, text, pos = operators.pop()
        right = operands.pop()
        operands.append(n.Binary(text.upper(), operands.pop(), right, pos))

    for k in range(1, len(items), 2):
        op = items[k]
        if op[0] == "CMP_OP":
            if comparison is not None:
                raise NcSyntaxError(f"a second comparison {op[1]} after {comparison[1]}: compare two values "
                                    "once and combine conditions with AND / OR", *lc(op[2]))
            comparison = op
        while operators and PRIORITY[operators[-1][0]] >= PRIORITY[op[0]]:
            reduce()
        operators.append(op)
        operands.append(items[k + 1])
    while operators:
        reduce()
    return operands[0]


# --- words --------------------------------------------------------------------------------------

def check_user_name(name: str, pos: n.Pos) -> None:
    if name in AXIS_LETTERS or name in ("F", "S", "T", "D", "G", "M", "N", "L", "R", "SPOS", "MEAS",
                                        "MEAW") or name in TYPES:
        raise NcSyntaxError(f"{name} is a word of the language and cannot be used as a name", *lc(pos))


def address_word(written: str, pos: n.Pos):
    """An address letter with its constant as written (``G1``, ``X-.5``, ``L977``) at ``pos``."""
    text = written.upper()
    letter, raw = text[0], text[1:]
    value = number_value(raw)
    if letter in ("G", "M", "L", "N"):
        if not isinstance(value, int) or raw.startswith(("+", "-")):
            raise NcSyntaxError(f"{written}: {letter} takes a whole number", *lc(pos))
        if letter == "G":
            return n.GCode(value, pos)
        if letter == "M":
            return n.MCode(value, pos)
        if letter == "L":
            return n.CycleCall(f"L{value}", (), pos)
        raise NcSyntaxError(f"block number {written} must stand at the start of the block", *lc(pos))
    num = n.Num(value, n.Pos(pos.line, pos.column + 1))
    if letter in AXIS_LETTERS:
        return n.AxisWord(letter, num, pos)
    if letter in ("F", "S", "T", "D"):
        return n.Address(letter, num, pos)
    if letter == "R":
        raise NcSyntaxError(f"{written}: an R parameter has a number (R1) and is assigned with '='", *lc(pos))
    reason = _UNSUPPORTED_ADDRESS.get(letter, f"the address {letter} is not part of this control's language")
    raise NcSyntaxError(f"{written}: {reason}", *lc(pos))


_EXAMPLES = {"G": "G1", "M": "M30", "N": "N10", "L": "L977"}
_ASSIGN_WORDS = {
    **{a: (lambda name, value, pos: n.AxisWord(name, value, pos)) for a in AXIS_LETTERS},
    **{a: (lambda name, value, pos: n.Address(name, value, pos)) for a in ("F", "S", "T", "D")},
    "SPOS": lambda name, value, pos: n.Spos(value, pos),
    "MEAS": lambda name, value, pos: n.Meas(name, value, pos),
    "MEAW": lambda name, value, pos: n.Meas(name, value, pos),
}


def assignment(target: n.Var, value):
    """``target=value``; ``value`` is an expression or ``("SET", exprs, pos)``."""
    pos = target.pos
    values, is_set = ((value[1], True) if isinstance(value, tuple) else ((value,), False))
    name = target.name
    if not target.indices and name in _ASSIGN_WORDS:
        if is_set:
            raise NcSyntaxError(f"{name}=SET(...) is not allowed; SET fills arrays", *lc(pos))
        return _ASSIGN_WORDS[name](name, values[0], pos)
    if not target.indices and name in _EXAMPLES:
        raise NcSyntaxError(f"{name}= is not allowed: write {name} with its number, e.g. {_EXAMPLES[name]}",
                            *lc(pos))
    return n.Assign(target, values, pos, is_set)


def bare_name(written: str, pos: n.Pos):
    """A name standing alone as a word: a cycle call, SUPA, or a word that needs a value."""
    name = written.upper()
    if name in AXIS_LETTERS or name in ("F", "S", "T", "D", "SPOS", "MEAS", "MEAW"):
        raise NcSyntaxError(f"{name} needs a value (e.g. {name}10 or {name}=R1)"
                            if len(name) == 1 else f"{name} needs a value: {name}=...", *lc(pos))
    if name == "SUPA":
        # SUPA suppresses the frames like G53 and also handwheel offsets, external zero offsets
        # and PRESET (840D Fundamentals, "Frame suppression"): this control has none of those,
        # so SUPA is G53 here (manual listings §6: N30 SUPA G0 Z100)
        return n.GCode(53, pos)
    if name in ("DIAMON", "DIAMOF"):        # diameter programming (lathe; refused by name on a mill)
        return n.Diameter(name == "DIAMON", pos)
    if name in _STRUCTURED:
        raise NcSyntaxError(f"{name}: structured control statements are not part of this control's "
                            f"language (use IF ... GOTOF/GOTOB with labels)", *lc(pos))
    return n.CycleCall(name, (), pos)


def goto(direction: str, target: str, is_blockno: bool, pos: n.Pos) -> n.Goto:
    value = target.upper()
    if is_blockno:
        value = f"N{int(value[1:])}"
    return n.Goto(direction.upper(), value, pos)


def def_item(name_written: str, dims, init, pos: n.Pos) -> n.DefItem:
    name = name_written.upper()
    check_user_name(name, pos)
    if dims is not None and any(d < 1 for d in dims):
        raise NcSyntaxError(f"DEF {name}: an array needs at least 1 element", *lc(pos))
    return n.DefItem(name, dims or (), init, pos)


def definition(type_written: str, type_pos: n.Pos, length: int | None, defs, pos: n.Pos) -> list:
    type_name = type_written.upper()
    if type_name not in TYPES:
        raise NcSyntaxError(f"DEF {type_written}: the type must be REAL, INT, BOOL or STRING[n]", *lc(type_pos))
    if length is not None and type_name != "STRING":
        raise NcSyntaxError(f"DEF {type_name}[{length}]: only STRING takes a length", *lc(type_pos))
    return [n.Define(type_name, length, tuple(defs), pos)]


class ToNodes(Transformer):
    """The rules' callbacks -> nodes, called by the parser as it reduces. Raises NcSyntaxError
    for invalid words. No state: the parser and this instance are shared between threads."""

    # --- program and blocks -------------------------------------------------------------------
    def start(self, items):
        return list(items)

    def header_block(self, items):
        return ("HEADER", items[0])

    def block(self, items):
        return ("BLOCK", items)

    # --- expressions ------------------------------------------------------------------------
    def number(self, items):
        (tok,) = items
        return n.Num(number_value(tok.value), pos_of(tok))

    def string(self, items):
        (tok,) = items
        return n.Str(tok.value[1:-1], pos_of(tok))

    def true(self, items):
        return n.Num(1, pos_of(items[0]))

    def false(self, items):
        return n.Num(0, pos_of(items[0]))

    def rparam(self, items):
        (tok,) = items
        return rparam(tok.value, tok.line, tok.column)

    def name(self, items):
        (tok,) = items
        return n.Var(tok.value.upper(), (), pos_of(tok))

    def indexed(self, items):
        tok, exprs = items
        return n.Var(tok.value.upper(), tuple(exprs), pos_of(tok))

    def function(self, items):
        tok, exprs = items
        return n.Func(tok.value.upper(), tuple(exprs or ()), pos_of(tok))

    def exprs(self, items):
        return list(items)

    def chain(self, items):
        return climb([item if k % 2 == 0 else (item.type, item.value, pos_of(item)) for k, item in enumerate(items)])

    def unop(self, items):
        op, operand = items
        return unary(op.value, operand, pos_of(op))

    def set_list(self, items):
        _set, exprs = items
        return ("SET", tuple(exprs), pos_of(_set))

    # --- words --------------------------------------------------------------------------------
    def address(self, items):
        (tok,) = items
        return address_word(tok.value, pos_of(tok))

    def assignment(self, items):
        target, value = items
        return assignment(target, value)

    def bare_name(self, items):
        (tok,) = items
        return bare_name(tok.value, pos_of(tok))

    def call(self, items):
        tok, exprs = items
        return n.CycleCall(tok.value.upper(), tuple(exprs or ()), pos_of(tok))

    def goto(self, items):
        kw, target = items
        return goto(kw.value, target.value, target.type == "BLOCKNO", pos_of(kw))

    def msg(self, items):
        kw, expr = items
        return n.Msg(expr, pos_of(kw))

    def stopre(self, items):
        return n.Stopre(pos_of(items[0]))

    def words(self, items):
        return list(items)

    def if_goto(self, items):
        kw, cond, jump = items
        return [n.IfGoto(cond, jump, pos_of(kw))]

    def type_length(self, items):
        return int(items[0].value)

    def dims(self, items):
        return tuple(int(t.value) for t in items)

    def def_item(self, items):
        tok, dims, init = items
        return def_item(tok.value, dims, init, pos_of(tok))

    def definition(self, items):
        kw, type_tok, length, *defs = items
        return definition(type_tok.value, pos_of(type_tok), length, defs, pos_of(kw))

    def label(self, items):
        tok = items[0]
        check_user_name(tok.value.upper(), pos_of(tok))
        return ("LABEL", tok)

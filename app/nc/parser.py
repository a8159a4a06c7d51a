"""Parser: program text -> ``nodes.Program`` (lark LALR on ``grammar.lark``).

``parse_program`` raises ``NcSyntaxError(line, column, message)`` in operator words for anything
wrong with the text itself: the grammar, words that do not exist, words that may not stand
together in one block (two G functions of one group, G100 with two axes, MEAS without a motion,
...), DEF after the first instruction, jump targets that do not exist. Names of variables and
cycles are checked later against the variable store and the cycle registry
(``Interpreter.load``), because they depend on the control's configuration.
"""

from __future__ import annotations

import re
from bisect import bisect_left, bisect_right
from collections.abc import Callable
from functools import lru_cache
from importlib import resources
from typing import Any

from lark import Lark, Token, Transformer, Tree
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, UnexpectedToken

from engine import alarms

from . import nodes as n
from .errors import NcSyntaxError
from .modal import (
    AXIS_LETTERS,
    FRAME_SUPPRESS,
    KNOWN_M,
    MEASURING,
    MOTION,
    g_group,
)
from .scope import OUT_OF_SCOPE, refusal

#: how a terminal is named in an error message
_TERMINAL_WORDS = {
    "_NL": "the end of the block", "EQUAL": "'='", "LSQB": "'['", "RSQB": "']'", "LPAR": "'('",
    "RPAR": "')'", "COMMA": "','", "COLON": "':'", "NUMBER": "a number", "INT_NUMBER": "a number",
    "NAME": "a name", "RPARAM": "an R parameter", "STRING": "a text in quotes", "ADDRESS": "a word",
    "BLOCKNO": "a block number", "CMP_OP": "a comparison", "ADD_OP": "'+' or '-'",
    "MUL_OP": "'*' or '/'",
}
_EXPRESSION_START = {"NUMBER", "INT_NUMBER", "NAME", "RPARAM", "STRING", "LPAR", "ADD_OP", "NOT", "CONCAT",
                     "TRUE", "FALSE"}
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


def _grammar() -> str:
    return resources.files(__package__).joinpath("grammar.lark").read_text(encoding="utf-8")


@lru_cache(maxsize=1)
def _lark() -> Lark:
    """The parser that builds the nodes while it parses (no parse tree: ~3x faster on long
    programs, bench/bench_nc_parse.py); ``_ToNodes`` keeps no state, so one instance serves
    every thread."""
    return Lark(_grammar(), parser="lalr", lexer="contextual", transformer=_ToNodes(),
                maybe_placeholders=True, start="start")


@lru_cache(maxsize=1)
def _lark_tree() -> Lark:
    """The same grammar building a parse tree: only to word the message of a syntax error (the
    tokens before the error are on its stack)."""
    return Lark(_grammar(), parser="lalr", lexer="contextual", propagate_positions=True,
                maybe_placeholders=True, start="start")


def _pos(item) -> n.Pos:
    if isinstance(item, Token):
        assert item.line is not None and item.column is not None    # the lexer's tokens carry them
        return n.Pos(item.line, item.column)
    return n.Pos(item.meta.line, item.meta.column)


def _number(text: str) -> int | float:
    text = text.strip()
    if "." in text:
        return float(text)
    return int(text)


class _ToNodes(Transformer):
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
        return n.Num(_number(tok.value), _pos(tok))

    def string(self, items):
        (tok,) = items
        return n.Str(tok.value[1:-1], _pos(tok))

    def true(self, items):
        return n.Num(1, _pos(items[0]))

    def false(self, items):
        return n.Num(0, _pos(items[0]))

    def rparam(self, items):
        (tok,) = items
        return n.Var("R", (n.Num(int(tok.value[1:]), n.Pos(tok.line, tok.column + 1)),), _pos(tok))

    def name(self, items):
        (tok,) = items
        return n.Var(tok.value.upper(), (), _pos(tok))

    def indexed(self, items):
        tok, exprs = items
        return n.Var(tok.value.upper(), tuple(exprs), _pos(tok))

    def function(self, items):
        tok, exprs = items
        return n.Func(tok.value.upper(), tuple(exprs or ()), _pos(tok))

    def exprs(self, items):
        return list(items)

    def chain(self, items):
        return _climb(items)

    def unop(self, items):
        op, operand = items
        return n.Unary(op.value.upper(), operand, _pos(op))

    def set_list(self, items):
        _set, exprs = items
        return ("SET", tuple(exprs), _pos(_set))

    # --- words --------------------------------------------------------------------------------
    def address(self, items):
        (tok,) = items
        return _address_word(tok)

    def assignment(self, items):
        target, value = items
        pos = target.pos
        values, is_set = ((value[1], True) if isinstance(value, tuple) else ((value,), False))
        name = target.name
        if not target.indices and name in _ASSIGN_WORDS:
            if is_set:
                raise NcSyntaxError(f"{name}=SET(...) is not allowed; SET fills arrays", *_lc(pos))
            return _ASSIGN_WORDS[name](name, values[0], pos)
        if not target.indices and name in _EXAMPLES:
            raise NcSyntaxError(f"{name}= is not allowed: write {name} with its number, e.g. {_EXAMPLES[name]}",
                                *_lc(pos))
        return n.Assign(target, values, pos, is_set)

    def bare_name(self, items):
        (tok,) = items
        name = tok.value.upper()
        pos = _pos(tok)
        if name in AXIS_LETTERS or name in ("F", "S", "T", "D", "SPOS", "MEAS", "MEAW"):
            raise NcSyntaxError(f"{name} needs a value (e.g. {name}10 or {name}=R1)"
                                if len(name) == 1 else f"{name} needs a value: {name}=...", *_lc(pos))
        if name == "SUPA":
            # SUPA suppresses the frames like G53 and also handwheel offsets, external zero offsets
            # and PRESET (840D Fundamentals, "Frame suppression"): this control has none of those,
            # so SUPA is G53 here (manual listings §6: N30 SUPA G0 Z100)
            return n.GCode(53, pos)
        if name in _STRUCTURED:
            raise NcSyntaxError(f"{name}: structured control statements are not part of this control's "
                                f"language (use IF ... GOTOF/GOTOB with labels)", *_lc(pos))
        return n.CycleCall(name, (), pos)

    def call(self, items):
        tok, exprs = items
        return n.CycleCall(tok.value.upper(), tuple(exprs or ()), _pos(tok))

    def goto(self, items):
        kw, target = items
        value = target.value.upper()
        if target.type == "BLOCKNO":
            value = f"N{int(value[1:])}"
        return n.Goto(kw.value.upper(), value, _pos(kw))

    def msg(self, items):
        kw, expr = items
        return n.Msg(expr, _pos(kw))

    def stopre(self, items):
        return n.Stopre(_pos(items[0]))

    def words(self, items):
        return list(items)

    def if_goto(self, items):
        kw, cond, goto = items
        return [n.IfGoto(cond, goto, _pos(kw))]

    def type_length(self, items):
        return int(items[0].value)

    def dims(self, items):
        return tuple(int(t.value) for t in items)

    def def_item(self, items):
        tok, dims, init = items
        name = tok.value.upper()
        pos = _pos(tok)
        _check_user_name(name, pos)
        if dims is not None and any(d < 1 for d in dims):
            raise NcSyntaxError(f"DEF {name}: an array needs at least 1 element", *_lc(pos))
        return n.DefItem(name, dims or (), init, pos)

    def definition(self, items):
        kw, type_tok, length, *defs = items
        type_name = type_tok.value.upper()
        if type_name not in TYPES:
            raise NcSyntaxError(f"DEF {type_tok.value}: the type must be REAL, INT, BOOL or STRING[n]",
                                *_lc(_pos(type_tok)))
        if length is not None and type_name != "STRING":
            raise NcSyntaxError(f"DEF {type_name}[{length}]: only STRING takes a length", *_lc(_pos(type_tok)))
        return [n.Define(type_name, length, tuple(defs), _pos(kw))]

    def label(self, items):
        tok = items[0]
        _check_user_name(tok.value.upper(), _pos(tok))
        return ("LABEL", tok)


#: how strongly an operator binds (840D: comparisons weakest, then << (text concatenation), OR,
#: XOR, AND, + -, * / DIV MOD)
_PRIORITY = {"CMP_OP": 1, "CONCAT": 1.5, "OR": 2, "XOR": 3, "AND": 4, "ADD_OP": 5, "MUL_OP": 6, "DIV": 6,
             "MOD": 6}


def _climb(items: list) -> n.Expr:
    """``operand (operator operand)*`` -> the tree of binary operations: left-associative, by
    ``_PRIORITY``; one comparison per chain (``a < b < c`` means nothing on the 840D)."""
    operands: list[n.Expr] = [items[0]]
    operators: list[Token] = []
    comparison: Token | None = None

    def reduce() -> None:
        op = operators.pop()
        right = operands.pop()
        operands.append(n.Binary(op.value.upper(), operands.pop(), right, _pos(op)))

    for k in range(1, len(items), 2):
        op = items[k]
        if op.type == "CMP_OP":
            if comparison is not None:
                raise NcSyntaxError(f"a second comparison {op.value} after {comparison.value}: compare two values "
                                    "once and combine conditions with AND / OR", *_lc(_pos(op)))
            comparison = op
        while operators and _PRIORITY[operators[-1].type] >= _PRIORITY[op.type]:
            reduce()
        operators.append(op)
        operands.append(items[k + 1])
    while operators:
        reduce()
    return operands[0]


def _lc(pos: n.Pos) -> tuple[int, int]:
    return pos.line, pos.column


def _check_user_name(name: str, pos: n.Pos) -> None:
    if name in AXIS_LETTERS or name in ("F", "S", "T", "D", "G", "M", "N", "L", "R", "SPOS", "MEAS",
                                        "MEAW") or name in TYPES:
        raise NcSyntaxError(f"{name} is a word of the language and cannot be used as a name", *_lc(pos))


def _address_word(tok: Token):
    text = tok.value.upper()
    letter, raw = text[0], text[1:]
    pos = _pos(tok)
    value = _number(raw)
    if letter in ("G", "M", "L", "N"):
        if not isinstance(value, int) or raw.startswith(("+", "-")):
            raise NcSyntaxError(f"{tok.value}: {letter} takes a whole number", *_lc(pos))
        if letter == "G":
            return n.GCode(value, pos)
        if letter == "M":
            return n.MCode(value, pos)
        if letter == "L":
            return n.CycleCall(f"L{value}", (), pos)
        raise NcSyntaxError(f"block number {tok.value} must stand at the start of the block", *_lc(pos))
    num = n.Num(value, n.Pos(pos.line, pos.column + 1))
    if letter in AXIS_LETTERS:
        return n.AxisWord(letter, num, pos)
    if letter in ("F", "S", "T", "D"):
        return n.Address(letter, num, pos)
    if letter == "R":
        raise NcSyntaxError(f"{tok.value}: an R parameter has a number (R1) and is assigned with '='", *_lc(pos))
    reason = _UNSUPPORTED_ADDRESS.get(letter, f"the address {letter} is not part of this control's language")
    raise NcSyntaxError(f"{tok.value}: {reason}", *_lc(pos))


_EXAMPLES = {"G": "G1", "M": "M30", "N": "N10", "L": "L977"}
_ASSIGN_WORDS = {
    **{a: (lambda name, value, pos: n.AxisWord(name, value, pos)) for a in AXIS_LETTERS},
    **{a: (lambda name, value, pos: n.Address(name, value, pos)) for a in ("F", "S", "T", "D")},
    "SPOS": lambda name, value, pos: n.Spos(value, pos),
    "MEAS": lambda name, value, pos: n.Meas(name, value, pos),
    "MEAW": lambda name, value, pos: n.Meas(name, value, pos),
}


# --- errors in operator words -------------------------------------------------------------------

def _describe(tok: Token) -> str:
    if tok.type == "_NL" or tok.type == "$END":
        return "end of the block"
    return f"'{tok.value}'"


def _last_token(stack) -> Token | None:
    for item in reversed(list(stack or ())):
        if isinstance(item, Token):
            return item
        if isinstance(item, Tree):
            tokens = [t for t in item.scan_values(lambda v: isinstance(v, Token))]
            if tokens:
                return max(tokens, key=lambda t: (t.line, t.column))
        # transformed values are not expected (we transform after parsing)
    return None


def _show(value: str) -> str:
    """A word as written (G1, X10, R1); punctuation in quotes ('=', '(')."""
    return value if any(c.isalnum() for c in value) else f"'{value}'"


def _after(prev: Token | None, line: int) -> str:
    if prev is None or prev.type == "_NL" or prev.line != line:
        return " at the start of the block"
    return f" after {_show(prev.value)}"


def _hint(expected: set[str]) -> str:
    expected = {e for e in expected if not e.startswith("__")}
    if not expected or "_NL" in expected:
        return ""
    if len(expected & _EXPRESSION_START) >= 3:
        return ": a value or an expression is expected"
    words = sorted({_TERMINAL_WORDS.get(e, e) for e in expected})
    if len(words) > 4:
        return ""
    return ": expected " + (", ".join(words[:-1]) + " or " + words[-1] if len(words) > 1 else words[0])


_BLOCK_SKIP = ": block skip (/) is not part of this control's language"


def _token_message(e: UnexpectedToken, line: int) -> str:
    prev = _last_token(getattr(getattr(e, "state", None), "value_stack", None))
    if prev is None and e.token_history:
        prev = e.token_history[-1]
    tok = e.token
    after = _after(prev, line)
    message = f"the block ends too early{after}" if tok.type == "_NL" else f"unexpected {_describe(tok)}{after}"
    if tok.value == "/" and after == " at the start of the block":
        return message + _BLOCK_SKIP
    return message + _hint(set(e.expected or ()))


def _character_message(e: UnexpectedCharacters, line: int) -> str:
    prev = e.token_history[-1] if getattr(e, "token_history", None) else None
    message = f"unexpected character '{e.char}'{_after(prev, line)}"
    if e.char == "/" and (prev is None or prev.line != line):
        message += _BLOCK_SKIP
    return message


def _syntax_error(e: UnexpectedInput, lines: list[str]) -> NcSyntaxError:
    line = getattr(e, "line", None) or 1
    column = getattr(e, "column", None) or 1
    text = lines[line - 1] if 0 < line <= len(lines) else None
    if isinstance(e, UnexpectedToken):
        message = _token_message(e, line)
    elif isinstance(e, UnexpectedCharacters):
        message = _character_message(e, line)
    elif isinstance(e, UnexpectedEOF):
        message = "the program ends too early"
    else:  # pragma: no cover - lark has no other kinds
        message = str(e)
    return NcSyntaxError(message, line, column, alarm=alarms.NC_SYNTAX, block_text=text)


# --- program ------------------------------------------------------------------------------------

#: the longest block (840D: 512 characters per block incl. comment; Programming Manual
#: Fundamentals, "Block format"): it also bounds the terms of an expression
MAX_BLOCK_CHARS = 512
#: the deepest nesting of parentheses and brackets in one block (the HMI's own bound: deeper
#: nesting is no measuring program, and the evaluator recurses over it)
MAX_NESTING = 32
#: the largest program text in bytes (UTF-8); the API answers 413 above it
MAX_PROGRAM_BYTES = 1024 * 1024


#: ``;`` and the fullwidth ``；`` the Chinese manual prints in its listings (chapter 6)
COMMENT_STARTS = (";", "\uff1b")


def _scan_line(line: str, number: int) -> None:
    """What the grammar cannot bound: the block's length, its nesting, and ASCII outside the
    texts in quotes and the comment (a fullwidth digit is no digit of the NC: ``X１２``)."""
    if len(line) > MAX_BLOCK_CHARS:
        raise NcSyntaxError(f"the block has {len(line)} characters; a block holds at most {MAX_BLOCK_CHARS} "
                            "(split it into several blocks)", number, MAX_BLOCK_CHARS + 1,
                            block_text=line[:80])
    if line.isascii() and "(" not in line and "[" not in line:
        return
    if line.lstrip().startswith("%"):
        return              # the program name line (a file name, not a block: the manual prints %_N_斜面测量_MPF)
    depth = 0
    quoted = False
    for column, ch in enumerate(line, start=1):
        if ch == '"':
            quoted = not quoted
        elif quoted:
            continue
        elif ch in COMMENT_STARTS:
            return
        elif not ch.isascii():
            raise NcSyntaxError(f"unexpected character '{ch}' (U+{ord(ch):04X}): the NC reads ASCII letters, "
                                "digits and signs only (texts in quotes and comments may hold any)",
                                number, column, block_text=line.strip())
        elif ch in "([":
            depth += 1
            if depth > MAX_NESTING:
                raise NcSyntaxError(f"the expression nests more than {MAX_NESTING} parentheses or brackets deep: "
                                    "compute a part into an R parameter first", number, column,
                                    block_text=line.strip())
        elif ch in ")]":
            depth -= 1


_OUT_OF_SCOPE = re.compile(r"(?<![$\w])(" + "|".join(re.escape(w) for w in OUT_OF_SCOPE) + r")(?!\w)", re.IGNORECASE)


def refuse_out_of_scope(text: str) -> None:
    """A word of the manual this control does not run (app.nc.scope) names itself, wherever it
    stands in the program, before any other complaint (``CYCLE800(1,““,...)`` of manual §5.7.2):
    what ``Interpreter.load`` checks first; the grammar itself still reads such words."""
    upper = text.upper()
    if not any(word in upper for word in OUT_OF_SCOPE):        # the usual case: one pass per word, no regex
        return
    for number, line in enumerate(text.replace("\r\n", "\n").replace("\r", "\n").split("\n"), start=1):
        if line.lstrip().startswith("%"):
            continue
        code = line.split(";", 1)[0].split("\uff1b", 1)[0]
        match = _OUT_OF_SCOPE.search(code)
        if match is not None:
            raise NcSyntaxError(refusal(match.group(0)) or match.group(0), number, match.start() + 1,
                                alarm=alarms.NC_NAME_UNKNOWN, block_text=line.strip())


def parse_program(text: str, name: str = "MDA") -> n.Program:
    """Parse and check ``text``; raises ``NcSyntaxError`` with line and column."""
    if not isinstance(text, str):
        raise TypeError("program text must be a str")
    source = text.replace("\r\n", "\n").replace("\r", "\n")
    lines = source.split("\n")
    for number, line in enumerate(lines, start=1):
        _scan_line(line, number)
    try:
        raw_blocks = _lark().parse(source + "\n")
    except UnexpectedInput as e:
        raise _worded(e, lines) from None
    except NcSyntaxError as err:
        if err.line is not None and err.block_text is None and 0 < err.line <= len(lines):
            err.block_text = lines[err.line - 1].strip()
        raise
    return _assemble(raw_blocks, source, lines, name)


def _worded(e: UnexpectedInput, lines: list[str]) -> NcSyntaxError:
    """The error in operator words: the line is parsed again into a tree, whose stack holds the
    tokens before the error ("unexpected '=' after X10"); the grammar is one block per line."""
    line = getattr(e, "line", None) or 1
    if 0 < line <= len(lines):
        try:
            _lark_tree().parse("\n" * (line - 1) + lines[line - 1] + "\n")
        except UnexpectedInput as again:
            return _syntax_error(again, lines)
    return _syntax_error(e, lines)


def _block_start(items) -> tuple[int, int]:
    first = items[0]
    if isinstance(first, tuple):                # ("LABEL", token)
        first = first[1]
    if isinstance(first, Token):
        return _lc(_pos(first))
    return _lc(first[0].pos)                    # the words of the body


def _assemble(raw_blocks, source: str, lines: list[str], name: str) -> n.Program:
    blocks: list[n.Block] = []
    header = None
    labels: dict[str, int] = {}
    seen_instruction = False
    for kind, items in raw_blocks:
        if kind == "HEADER":
            if blocks or header is not None:
                raise NcSyntaxError("the program name line (%...) must be the first line", items.line, items.column,
                                    block_text=lines[items.line - 1].strip())
            header = items.value
            continue
        block = _block(items, len(blocks), lines, labels)
        is_def = any(isinstance(w, n.Define) for w in block.words)
        if is_def and seen_instruction:
            raise NcSyntaxError("DEF must come before the first instruction of the program", block.line,
                                block.words[0].pos.column, block_text=block.text)
        seen_instruction = seen_instruction or bool(block.words and not is_def)
        blocks.append(block)
    program = n.Program(name, source, tuple(blocks), header, labels, jump_targets(blocks))
    _check_jumps(program)
    return program


def _block(items, index: int, lines: list[str], labels: dict[str, int]) -> n.Block:
    """One block from the parser's items (N number, label, words), checked; its label recorded."""
    line, column = _block_start(items)
    text = lines[line - 1].strip()
    number = None
    label = None
    words: list = []
    for child in items:
        if isinstance(child, Token) and child.type == "BLOCKNO":
            number = int(child.value[1:])
        elif isinstance(child, tuple) and child[0] == "LABEL":
            tok = child[1]
            label = tok.value.upper()
            if label in labels:
                raise NcSyntaxError(f"label {label} is defined twice", tok.line, tok.column, block_text=text)
            labels[label] = index
        elif child is not None:
            words.extend(child)
    block = n.Block(index, line, text, number, label, tuple(words), n.Pos(line, column))
    try:
        _check_block(block)
    except NcSyntaxError as err:
        err.block_text = text
        raise
    return block


def _err(word, message: str, **kw) -> NcSyntaxError:
    return NcSyntaxError(message, word.pos.line, word.pos.column, **kw)


class _Words:
    """One block's words sorted for the checks: G functions by group, M functions, axes, MEAS."""

    def __init__(self, block: n.Block):
        self.block = block
        self.groups: dict[str, n.GCode] = {}
        self.ms = [w for w in block.words if isinstance(w, n.MCode)]
        self.axes = [w for w in block.words if isinstance(w, n.AxisWord)]
        self.meas = next((w for w in block.words if isinstance(w, n.Meas)), None)


def _check_g_groups(words: _Words) -> None:
    """Every G function exists, and one per group."""
    for g in words.block.gcodes():
        group = g_group(g.number)
        if group is None:
            hint = " (circles G2/G3 are not part of this control's language)" if g.number in (2, 3) else ""
            raise _err(g, f"G{g.number} is not a G function of this control{hint}",
                       alarm=alarms.NC_G_FUNCTION_UNKNOWN)
        if group in words.groups:
            raise _err(g, f"G{g.number} and G{words.groups[group].number} exclude each other in one block")
        words.groups[group] = g


def _check_m_functions(words: _Words) -> None:
    """Every M function exists; one of the spindle group (M3 M4 M5), one program end (M0 M2 M17 M30)."""
    for m in words.ms:
        if m.number not in KNOWN_M:
            raise _err(m, f"M{m.number} is not an M function of this control (M0 M2 M3 M4 M5 M6 M17 M30)")
    for group in ((3, 4, 5), (0, 2, 17, 30)):
        same = [m for m in words.ms if m.number in group]
        if len(same) > 1:
            raise _err(same[1], f"M{same[1].number} and M{same[0].number} exclude each other in one block")


#: the word a block may hold once, by its kind
_ONCE: tuple[tuple[type | tuple[type, ...], Callable[[Any], str | None]], ...] = (
    (n.AxisWord, lambda w: w.axis), (n.Address, lambda w: w.letter), (n.Spos, lambda w: "SPOS"),
    (n.Meas, lambda w: "MEAS/MEAW"), ((n.Goto, n.IfGoto), lambda w: "GOTO"), (n.Msg, lambda w: "MSG"),
    (n.MCode, lambda w: "M6" if w.number == 6 else None),
)


def _once_key(w) -> str | None:
    return next((key(w) for kind, key in _ONCE if isinstance(w, kind)), None)


def _check_once(words: _Words) -> None:
    """An axis, an address, SPOS, MEAS, a jump, MSG and M6 stand once in a block."""
    seen: set[str] = set()
    for w in words.block.words:
        key = _once_key(w)
        if key is None:
            continue
        if key in seen:
            raise _err(w, f"{key} is programmed twice in one block")
        seen.add(key)


def _check_calls(words: _Words) -> None:
    calls = [w for w in words.block.words if isinstance(w, n.CycleCall)]
    if len(calls) > 1:
        raise _err(calls[1], f"only one cycle call per block ({calls[0].name} is already called)")


def _check_spos(words: _Words) -> None:
    spos = next((w for w in words.block.words if isinstance(w, n.Spos)), None)
    rotate = next((m for m in words.ms if m.number in (3, 4)), None)
    if spos is not None and rotate is not None:
        raise _err(spos, f"SPOS positions the stopped spindle: it cannot stand with M{rotate.number} in one block")


def _check_g101_g102(words: _Words) -> None:
    """G101/G102 take axis factors only."""
    measuring = words.groups.get(MEASURING)
    if measuring is None or measuring.number not in (101, 102):
        return
    code = measuring.number
    for g in words.block.gcodes():
        if g is not measuring:
            raise _err(g, f"G{code} takes axis factors only: program G{g.number} in another block")
    others = [w for w in words.block.words if not isinstance(w, (n.AxisWord, n.GCode))]
    if others:
        raise _err(others[0], f"G{code} takes axis factors only: program this in another block")
    if code == 101 and not words.axes:
        raise _err(measuring, "G101 needs at least one axis with its factor, e.g. G101 X1")


def _check_g100(words: _Words) -> None:
    """G100 is itself the measuring move of one geometry axis (F and assignments may stand with it)."""
    measuring = words.groups.get(MEASURING)
    if measuring is None or measuring.number != 100:
        return
    groups, axes = words.groups, words.axes
    if MOTION in groups:
        raise _err(groups[MOTION], f"G100 is itself the measuring move: leave out G{groups[MOTION].number}")
    if FRAME_SUPPRESS in groups:
        raise _err(groups[FRAME_SUPPRESS], "G100 measures in the workpiece coordinates: leave out G53")
    if len(axes) == 1 and axes[0].axis not in ("X", "Y", "Z"):
        raise _err(axes[0], f"G100 measures a geometry axis (X, Y, Z), not {axes[0].axis}")
    if len(axes) != 1:
        raise _err(measuring if not axes else axes[1],
                   "G100 measures one axis: program G100 with exactly one axis and its target, "
                   "a separate G100 block for each axis")
    if words.meas is not None:
        raise _err(words.meas, "G100 is itself the measuring move: leave out MEAS/MEAW")


def _check_meas(words: _Words) -> None:
    meas = words.meas
    if meas is None:
        return
    if not words.axes:
        raise _err(meas, f"{meas.kind} needs an axis motion in the same block (e.g. {meas.kind}=1 G1 X100)")
    motion = words.groups.get(MOTION)
    if motion is not None and motion.number == 0:
        raise _err(motion, f"{meas.kind} is a measuring move at feed: program G1, not G0")


#: the block checks, group by group, in the order the operator is told about them
_BLOCK_CHECKS = (_check_g_groups, _check_m_functions, _check_once, _check_spos, _check_calls, _check_g101_g102,
                 _check_g100, _check_meas)


def _check_block(block: n.Block) -> None:
    """Words that may not stand together in one block (independent of the configuration)."""
    words = _Words(block)
    for check in _BLOCK_CHECKS:
        check(words)


def _g100_extra_ok(word) -> bool:
    """Words a G100 block may hold besides its axis: F (measuring feed) and assignments."""
    return isinstance(word, n.Assign) or (isinstance(word, n.Address) and word.letter == "F")


def _check_jumps(program: n.Program) -> None:
    for b in program.blocks:
        for w in b.words:
            goto = w.goto if isinstance(w, n.IfGoto) else w if isinstance(w, n.Goto) else None
            if goto is None:
                continue
            if find_jump(program, b.index, goto) is None:
                where = {"GOTOF": " after this block", "GOTOB": " before this block", "GOTO": ""}[goto.direction]
                raise NcSyntaxError(f"{goto.direction} {goto.target}: there is no label or block "
                                    f"{goto.target}{where}", goto.pos.line, goto.pos.column,
                                    alarm=alarms.NC_JUMP_TARGET, block_text=b.text)


def jump_targets(blocks) -> dict[str, tuple[int, ...]]:
    """Block indices by what a jump may name: the label, and "N<number>" (block numbers may
    repeat; the search direction picks one)."""
    targets: dict[str, list[int]] = {}
    for b in blocks:
        if b.label is not None:
            targets.setdefault(b.label, []).append(b.index)
        if b.number is not None:
            targets.setdefault(f"N{b.number}", []).append(b.index)
    return {k: tuple(v) for k, v in targets.items()}


def find_jump(program: n.Program, from_index: int, goto: n.Goto) -> int | None:
    """Index of the block ``goto`` jumps to from block ``from_index`` (840D search rules:
    GOTOF forward, GOTOB backward, GOTO forward first, then backward)."""
    targets = program.targets if program.targets is not None else jump_targets(program.blocks)
    found = targets.get(goto.target, ())
    at = bisect_right(found, from_index)
    forward = found[at] if at < len(found) else None
    before = bisect_left(found, from_index)
    backward = found[before - 1] if before > 0 else None
    if goto.direction == "GOTOF":
        return forward
    if goto.direction == "GOTOB":
        return backward
    return forward if forward is not None else backward


def parse_reference(text: str) -> n.Var:
    """A variable reference as the API names it: ``R1``, ``R[5]``, ``_EV[9]``, ``$AA_MM[X]``."""
    try:
        program = parse_program(f"__REF__={text}", name="REF")
    except NcSyntaxError as e:
        raise NcSyntaxError(f"{text!r} is not a variable reference", None, None) from e
    block = program.blocks[0] if len(program.blocks) == 1 else None
    words = block.words if block else ()
    if len(words) != 1 or not isinstance(words[0], n.Assign) or len(words[0].values) != 1 \
            or not isinstance(words[0].values[0], n.Var):
        raise NcSyntaxError(f"{text!r} is not a variable reference", None, None)
    return words[0].values[0]

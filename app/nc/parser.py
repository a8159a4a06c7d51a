"""Parser: program text -> ``nodes.Program`` (``fastparse`` for correct programs; lark LALR on
``grammar.lark`` for the rest, which words every syntax error).

``parse_program`` raises ``NcSyntaxError(line, column, message)`` in operator words for anything
wrong with the text itself: the grammar, words that do not exist, words that may not stand
together in one block (two G functions of one group, G100 with two axes, MEAS without a motion,
...), DEF after the first instruction, jump targets that do not exist. Names of variables and
cycles are checked later against the variable store and the cycle registry
(``Interpreter.load``), because they depend on the control's configuration.
"""

from __future__ import annotations

import gc
import re
import threading
from bisect import bisect_left, bisect_right
from collections import OrderedDict
from collections.abc import Callable
from contextlib import contextmanager
from functools import lru_cache
from importlib import resources
from typing import Any

from lark import Lark, Token, Tree
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, UnexpectedToken

from engine import alarms

from . import nodes as n
from .build import ToNodes, lc, pos_of
from .errors import NcSyntaxError
from .fastparse import read_blocks
from .modal import (
    FRAME_SUPPRESS,
    KNOWN_M,
    MEASURING,
    MOTION,
    g_group,
)
from .scope import LATHE_WORDS, OUT_OF_SCOPE, refusal

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


def _grammar() -> str:
    return resources.files(__package__).joinpath("grammar.lark").read_text(encoding="utf-8")


@lru_cache(maxsize=1)
def _lark() -> Lark:
    """The parser that builds the nodes while it parses (no parse tree: ~3x faster on long
    programs, bench/bench_nc_parse.py); ``build.ToNodes`` keeps no state, so one instance serves
    every thread."""
    return Lark(_grammar(), parser="lalr", lexer="contextual", transformer=ToNodes(),
                maybe_placeholders=True, start="start")


@lru_cache(maxsize=1)
def _lark_tree() -> Lark:
    """The same grammar building a parse tree: only to word the message of a syntax error (the
    tokens before the error are on its stack)."""
    return Lark(_grammar(), parser="lalr", lexer="contextual", propagate_positions=True,
                maybe_placeholders=True, start="start")


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
    if line.isascii() and line.count("(") + line.count("[") <= MAX_NESTING:
        return              # no other characters, and not so many parentheses that they could nest too deep
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


def refuse_out_of_scope(text: str, lathe: bool = False) -> None:
    """A word of the manual this control does not run (app.nc.scope) names itself, wherever it
    stands in the program, before any other complaint (``CYCLE800(1,““,...)`` of manual §5.7.2):
    what ``Interpreter.load`` checks first; the grammar itself still reads such words. ``lathe``:
    the machine is a lathe, which runs the words of ``scope.LATHE_WORDS``."""
    upper = text.upper()
    words = [w for w in OUT_OF_SCOPE if not (lathe and w in LATHE_WORDS)]
    if not any(word in upper for word in words):        # the usual case: one pass per word, no regex
        return
    for number, line in enumerate(text.replace("\r\n", "\n").replace("\r", "\n").split("\n"), start=1):
        if line.lstrip().startswith("%"):
            continue
        code = line.split(";", 1)[0].split("\uff1b", 1)[0]
        match = next((m for m in _OUT_OF_SCOPE.finditer(code) if refusal(m.group(0), lathe)), None)
        if match is not None:
            raise NcSyntaxError(refusal(match.group(0), lathe) or match.group(0), number, match.start() + 1,
                                alarm=alarms.NC_NAME_UNKNOWN, block_text=line.strip())


#: the last programs read, by (text, name): the channel reads one text several times (the check
#: when it is stored, the load when it is selected, again at NC Start after its end); the nodes
#: are immutable, so the readers share them. Two: a long program is tens of MB of nodes.
_read: OrderedDict[tuple[str, str], n.Program] = OrderedDict()
_read_lock = threading.Lock()
_READ_KEPT = 2


def parse_program(text: str, name: str = "MDA") -> n.Program:
    """Parse and check ``text``; raises ``NcSyntaxError`` with line and column."""
    if not isinstance(text, str):
        raise TypeError("program text must be a str")
    key = (text, name)
    with _read_lock:
        program = _read.get(key)
        if program is not None:
            _read.move_to_end(key)
    if program is None:
        program = _parse(text, name)
        with _read_lock:
            _read[key] = program
            while len(_read) > _READ_KEPT:
                _read.popitem(last=False)
    return program


def forget_programs() -> None:
    """Read every program again (bench/bench_nc_parse.py times the reading itself)."""
    with _read_lock:
        _read.clear()


def _parse(text: str, name: str) -> n.Program:
    source = text.replace("\r\n", "\n").replace("\r", "\n")
    lines = source.split("\n")
    for number, line in enumerate(lines, start=1):
        _scan_line(line, number)
    with _collector_paused():
        raw_blocks, read = read_blocks(lines)       # the fast reader, up to a line it leaves to lark
        if read < len(lines):                       # lark from there on (empty lines keep the numbers)
            raw_blocks += _lark_blocks("\n" * read + "\n".join(lines[read:]), lines)
        return _assemble(raw_blocks, source, lines, name)


_collector_lock = threading.Lock()
_collector_readers = 0
_collector_was_on = False


@contextmanager
def _collector_paused():
    """Python's cycle collector waits while programs are read: reading makes many small objects
    and no cycles, and each collection walks the whole heap (a third of the time of a 200 KB
    program, bench/bench_nc_parse.py). Counted, so readers in several threads share one pause."""
    global _collector_readers, _collector_was_on
    with _collector_lock:
        if _collector_readers == 0:
            _collector_was_on = gc.isenabled()
            gc.disable()
        _collector_readers += 1
    try:
        yield
    finally:
        with _collector_lock:
            _collector_readers -= 1
            if _collector_readers == 0 and _collector_was_on:
                gc.enable()


def _lark_blocks(source: str, lines: list[str]) -> list:
    """lark's reading: the blocks as ``build.ToNodes`` gives them, or the error in operator words."""
    try:
        blocks: list = _lark().parse(source + "\n")      # type: ignore[assignment]  # the transformer gives a list
        return blocks
    except UnexpectedInput as e:
        raise _worded(e, lines) from None
    except NcSyntaxError as err:
        if err.line is not None and err.block_text is None and 0 < err.line <= len(lines):
            err.block_text = lines[err.line - 1].strip()
        raise


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
        return lc(pos_of(first))
    return lc(first[0].pos)                    # the words of the body


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


#: the word a block may hold once, by its kind (node classes have no subclasses)
_ONCE: dict[type, Callable[[Any], str | None]] = {
    n.AxisWord: lambda w: w.axis, n.Address: lambda w: w.letter, n.Spos: lambda w: "SPOS",
    n.Meas: lambda w: "MEAS/MEAW", n.Goto: lambda w: "GOTO", n.IfGoto: lambda w: "GOTO", n.Msg: lambda w: "MSG",
    n.MCode: lambda w: "M6" if w.number == 6 else None,
}


def _once_key(w) -> str | None:
    key = _ONCE.get(type(w))
    return None if key is None else key(w)


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


#: the block checks, group by group, in the order the operator is told about them; each with the
#: kinds of word it looks at (a block with none of them passes it: no need to ask)
_BLOCK_CHECKS: tuple[tuple[Callable[[_Words], None], frozenset[type]], ...] = (
    (_check_g_groups, frozenset({n.GCode})), (_check_m_functions, frozenset({n.MCode})),
    (_check_once, frozenset(_ONCE)), (_check_spos, frozenset({n.Spos})), (_check_calls, frozenset({n.CycleCall})),
    (_check_g101_g102, frozenset({n.GCode})), (_check_g100, frozenset({n.GCode})),
    (_check_meas, frozenset({n.Meas})),
)


def _check_block(block: n.Block) -> None:
    """Words that may not stand together in one block (independent of the configuration)."""
    kinds = {type(w) for w in block.words}
    words = _Words(block)
    for check, looks_at in _BLOCK_CHECKS:
        if not kinds.isdisjoint(looks_at):
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

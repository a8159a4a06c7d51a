"""The fast reader of programs (app.nc.fastparse, issue 24 item 5) reads exactly what lark's
parser reads: on every program it takes, the nodes are equal to lark's (positions included);
what it is not sure of it leaves to lark, whose errors the operator sees. The truth here is
lark's reading of the grammar (grammar.lark), the reader the NC had before.
"""

from __future__ import annotations

import ast
import random
from pathlib import Path

import pytest

from app.nc import nodes as n
from app.nc import parser as p
from app.nc.errors import NcSyntaxError
from app.nc.fastparse import read_blocks
from tests.listings.manual_listings import ALL as MANUAL_LISTINGS

ROOT = Path(__file__).resolve().parents[2]


def _lark(text: str):
    """What ``parse_program`` gave before the fast reader: the program, or its error."""
    lines = text.split("\n")
    try:
        return p._assemble(p._lark_blocks(text, lines), text, lines, "T")
    except NcSyntaxError as e:
        return ("error", str(e), e.line, e.column)


def _fast(text: str):
    """The fast reader's program, its error, or None when it leaves a line to lark."""
    lines = text.split("\n")
    blocks, read = read_blocks(lines)
    if read < len(lines):
        return None
    try:
        return p._assemble(blocks, text, lines, "T")
    except NcSyntaxError as e:
        return ("error", str(e), e.line, e.column)


def _scans(text: str) -> bool:
    try:
        for number, line in enumerate(text.split("\n"), start=1):
            p._scan_line(line, number)
    except NcSyntaxError:
        return False
    return True


def _compare(text: str) -> str:
    """"same" (both read it alike), "lark" (the fast reader left it to lark), or a failure."""
    fast = _fast(text)
    if fast is None:
        return "lark"
    truth = _lark(text)
    assert fast == truth, f"{text!r}: fast {fast!r} != lark {truth!r}"
    return "same"


def _texts_in(paths) -> list[str]:
    """The string constants of the Python files (the programs of the NC tests among them)."""
    texts = []
    for path in paths:
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and 0 < len(node.value) < 5000:
                text = node.value.replace("\r\n", "\n").replace("\r", "\n")
                if _scans(text):
                    texts.append(text)
    return texts


def test_the_manual_listings_read_alike():
    results = [_compare(listing.text) for listing in MANUAL_LISTINGS if _scans(listing.text)]
    assert results.count("same") == len(results)            # none left to lark: they are plain NC


def test_the_programs_of_the_tests_read_alike():
    paths = sorted((ROOT / "tests" / "nc").glob("*.py")) + sorted((ROOT / "tests" / "listings").glob("*.py")) \
        + sorted((ROOT / "app" / "nc").rglob("*.py"))
    results = [_compare(text) for text in _texts_in(paths)]
    assert results.count("same") > 1000


@pytest.mark.parametrize("text, node", [
    ("R1=P+1", n.Binary("+", n.Var("P", (), n.Pos(1, 4)), n.Num(1, n.Pos(1, 6)), n.Pos(1, 5))),
    ("R1=Q-.5*2", n.Binary("-", n.Var("Q", (), n.Pos(1, 4)),
                           n.Binary("*", n.Num(0.5, n.Pos(1, 6)), n.Num(2, n.Pos(1, 9)), n.Pos(1, 8)), n.Pos(1, 5))),
])
def test_an_address_with_a_sign_in_an_expression_is_a_name_and_an_operator(text, node):
    """lark's lexer is contextual: inside an expression ``P+1`` is the name P plus 1."""
    assert _compare(text) == "same"
    assert _fast(text).blocks[0].words[0].values == (node,)


@pytest.mark.parametrize("text", ["R1=TRUE+AND", "AND", "G1 X10 IF", "R1=SET", "DEF REAL SET", "GOTOF IF",
                                  "R1=X-5", "N10 R1=5 N20", "R1=5 GOTOF END\nEND:"])
def test_what_the_fast_reader_is_not_sure_of_goes_to_lark(text):
    """Keywords where lark reads names, an address in an expression, errors: lark reads them
    (so the program and its error are lark's)."""
    assert _fast(text) is None or _fast(text) == _lark(text)
    truth = _lark(text)
    if isinstance(truth, tuple):
        with pytest.raises(NcSyntaxError) as caught:
            p.parse_program(text, "T")
        assert (str(caught.value), caught.value.line, caught.value.column) == truth[1:]
    else:
        assert p.parse_program(text, "T") == truth


_FRAGMENTS = ["N10", "n5", "R1", "r12", "X10", "X-5", "X+.5", "x.5", "G1", "G0", "G53", "M30", "F500", "T1",
              "D1", "L977", "A", "B", "P", "CYCLE977", "SUPA", "_EV", "$AA_MM", "LBL", "END", "IF", "DEF", "REAL",
              "INT", "STRING", "MSG", "STOPRE", "SET", "TRUE", "FALSE", "NOT", "AND", "OR", "XOR", "DIV", "MOD",
              "GOTOF", "GOTOB", "GOTO", "ANDB", "SETX", "5", "5.", ".5", "1.5", "5.5.5", '"txt"', '"a;b"', "<<",
              "<", "<=", "<>", "==", ">", ">=", "+", "-", "*", "/", "=", "(", ")", "[", "]", ",", ":", ";c",
              "%HDR", "SIN", "SIN(", "MEAS", "MEAS=1", "X=", "R1=", "_EV[", "SPOS", "E5", "I1", "N", "R", "X",
              "1X", "\t", "  "]
_OPERANDS = ["1", "2.5", ".5", "R1", "A", "P", "_EV[1]", '"s"', "TRUE", "X", "SIN(R2)", "R[2]", "$AA_MM[X]"]
_OPERATORS = ["+", "-", "*", "/", " AND ", " OR ", " XOR ", " DIV ", " MOD ", "<", "==", "<>", ">=", "<<", " and "]
_BLOCKS = ["N{n} G1 X{e} Y{e} F500", "R{n}={e}", "IF {e} GOTOF LBL", "{v}={e}", "X={e} Y={e}", "_EV[{n}]={e}",
           "DEF REAL A{n}, B[2]={e}", "MSG({e})", "CYCLE977({e},{e})", "LBL{n}: {v}={e}", "N{n} LBL{n}: G0 X{e}",
           "R{n}=P+{n} Q=P-{n}"]


def _expression(rng: random.Random, depth: int = 0) -> str:
    if depth > 3 or rng.random() < 0.3:
        return rng.choice(_OPERANDS)
    r = rng.random()
    if r < 0.15:
        return rng.choice(["-", "NOT ", "<<", "+"]) + _expression(rng, depth + 1)
    if r < 0.3:
        return "(" + _expression(rng, depth + 1) + ")"
    return _expression(rng, depth + 1) + rng.choice(_OPERATORS) + _expression(rng, depth + 1)


def _random_block(rng: random.Random) -> str:
    if rng.random() < 0.5:
        return "".join(rng.choice(_FRAGMENTS) + rng.choice(["", " ", " "]) for _ in range(rng.randint(1, 9)))
    fill = {"n": lambda: str(rng.randint(1, 99)), "e": lambda: _expression(rng),
            "v": lambda: rng.choice(["R3", "A", "_EV[1]", "X", "F", "G", "SPOS", "MEAS", "B[1,2]"])}
    parts = rng.choice(_BLOCKS).split("{")
    return parts[0] + "".join(fill[part[0]]() + part[2:] for part in parts[1:])


def test_random_blocks_read_alike():
    """Blocks of random words (most of them wrong) and of random expressions: whatever the fast
    reader takes, it reads as lark does."""
    rng = random.Random(24)
    results = [_compare("\n".join(_random_block(rng) for _ in range(rng.randint(1, 3)))) for _ in range(3000)]
    assert results.count("same") > 300


def test_a_long_program_is_read_by_the_fast_reader():
    text = "\n".join(f"N{i} G1 X{i % 100}.5 Y-{i % 37}.25 Z=R1+{i % 7}*2 F500 ; point {i}" for i in range(1, 2000))
    assert read_blocks(text.split("\n"))[1] == 1999
    assert p.parse_program(text, "T") == _lark(text)


def test_the_same_text_is_read_once_and_shared():
    """The channel reads one text several times (check, load, NC Start after the end): the last
    two readings are kept; the nodes are immutable, so sharing them changes nothing."""
    p.forget_programs()
    text = "N10 G1 X10 F100\nN20 R1=R2+1\nM30"
    first = p.parse_program(text, "KEPT")
    assert p.parse_program(text, "KEPT") is first
    assert p.parse_program(text, "OTHER") is not first and p.parse_program(text, "OTHER") == \
        p._parse(text, "OTHER")
    p.parse_program("M30", "A")
    p.parse_program("M30", "B")
    assert p.parse_program(text, "KEPT") is not first            # two others read since: read again
    assert p.parse_program(text, "KEPT") == first
    with pytest.raises(NcSyntaxError):
        p.parse_program("G1 X=", "BAD")
    with pytest.raises(NcSyntaxError):                           # errors are not kept: the same error again
        p.parse_program("G1 X=", "BAD")


@pytest.mark.parametrize("odd, error", [
    ("TRUE", False),                        # a keyword where lark reads a name: lark reads that line on
    ("R1=AND+1", False),
    ("G1 X10 )", True),                     # an error: lark's words, line and column
    ("G1.5 X10", True),
])
def test_lark_reads_on_from_the_line_the_fast_reader_leaves(odd, error):
    """A long program with one such line in the middle or at the end: the blocks before it are
    the fast reader's, lark reads from there on, and the program (or the error) is lark's."""
    lines = [f"N{i} G1 X{i % 100}.5 Y-{i % 37}.25 F500" for i in range(1, 400)]
    for at in (150, len(lines)):
        text = "\n".join([*lines[:at], odd, *lines[at:]])
        assert read_blocks(text.split("\n"))[1] == at
        truth = _lark(text)
        assert isinstance(truth, tuple) is error
        if error:
            with pytest.raises(NcSyntaxError) as caught:
                p._parse(text, "T")
            assert (str(caught.value), caught.value.line, caught.value.column) == truth[1:]
        else:
            assert p._parse(text, "T") == truth


def _read(text: str):
    """``parse_program``'s reading (fast reader, then lark from the line it leaves), or its error."""
    try:
        return p._parse(text, "T")
    except NcSyntaxError as e:
        return ("error", str(e), e.line, e.column)


def test_random_programs_read_as_lark_reads_them():
    """Programs of several random blocks, most of them wrong somewhere: the program or the error
    parse_program gives is lark's, whichever line the fast reader left to lark."""
    rng = random.Random(28)
    for _ in range(800):
        text = "\n".join(_random_block(rng) for _ in range(rng.randint(2, 6)))
        if _scans(text):
            assert _read(text) == _lark(text), text

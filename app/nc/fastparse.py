"""The fast reader of correct programs: the grammar of ``grammar.lark`` read by hand, one block
per line, building the same nodes through ``build`` (issue 24 item 5: a 200 KB program in well
under 1 s, where lark's LALR parser takes several).

It reads only what it is sure lark reads the same way. Anything else (a syntax error, a word
``build`` refuses, a keyword standing where lark's contextual lexer would read it as a name)
makes it stop at that line: ``read_blocks`` answers the blocks before it and ``parse_program``
runs lark from that line on (lark reads each line alike whatever came before), which words every
error as before. So a program reads the same whichever reader took it (tests/nc/test_nc_fastparse.py
compares the two on the test programs, the manual's listings and random blocks).
"""

from __future__ import annotations

import re

from lark import Token

from . import build as b
from . import nodes as n
from .errors import NcSyntaxError


class _GiveUp(Exception):
    """This reader leaves the program to lark."""


#: the terminals of grammar.lark, in the order lark's lexer tries them (priority, then length);
#: keywords come out as NAME and are told apart by ``_KEYWORDS``; no group: white space
_TOKEN = re.compile(r"""
    [ \t\f\r]+
  | (?P<COMMENT>[;\uff1b])
  | (?P<PROGRAM_HEADER>%.*)
  | (?P<BLOCKNO>[Nn][0-9]+)
  | (?P<RPARAM>[Rr][0-9]+)
  | (?P<ADDRESS>[A-Za-z][+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+))
  | (?P<NAME>(?![A-Za-z][0-9])[$_A-Za-z][A-Za-z0-9_]*)
  | (?P<INT_NUMBER>[0-9]+(?![.0-9]))
  | (?P<NUMBER>(?:[0-9]+\.[0-9]*|\.[0-9]+)(?![.0-9]))
  | (?P<STRING>"[^"\n]*")
  | (?P<CONCAT><<)
  | (?P<CMP_OP>==|<>|<=|>=|<|>)
  | (?P<ADD_OP>[+-])
  | (?P<MUL_OP>[*/])
  | (?P<PUNCT>[=()\[\],:])
""", re.VERBOSE)

_KEYWORDS = frozenset({"IF", "DEF", "MSG", "STOPRE", "SET", "TRUE", "FALSE", "NOT", "AND", "OR", "XOR", "DIV",
                       "MOD", "GOTOF", "GOTOB", "GOTO"})
_BINARY = frozenset({"CMP_OP", "CONCAT", "OR", "XOR", "AND", "ADD_OP", "MUL_OP", "DIV", "MOD"})
_PREFIX = frozenset({"ADD_OP", "CONCAT", "NOT"})
_JUMPS = frozenset({"GOTOF", "GOTOB", "GOTO"})
_END = ("END", "", 0)
#: the line's end, repeated: a look ahead past the end finds it (the reader gives up on it)
_ENDS = (_END,) * 3


def _tokens(line: str, at: int = 0) -> list[tuple[str, str, int]]:
    """(terminal, text, column) of one line from ``at``; punctuation is its own terminal ("(",
    "=", ...); then ``_ENDS``."""
    out: list[tuple[str, str, int]] = []
    match = _TOKEN.match
    end = len(line)
    while at < end:
        m = match(line, at)
        if m is None:
            raise _GiveUp
        kind = m.lastgroup
        if kind == "COMMENT":
            break
        if kind is not None:
            text = m.group()
            if kind == "PUNCT":
                kind = text
            elif kind == "NAME" and text.upper() in _KEYWORDS:
                kind = text.upper()
            out.append((kind, text, at + 1))
        at = m.end()
    out.extend(_ENDS)
    return out


def read_blocks(lines: list[str]) -> tuple[list, int]:
    """The program's blocks as lark's transformer gives them (``("HEADER", token)`` or
    ``("BLOCK", items)``) and the number of lines read: fewer than all when lark is to read the
    rest (from the line after them)."""
    blocks: list = []
    for number, line in enumerate(lines, start=1):
        try:
            block = _Line(line, number).block()
        except (_GiveUp, NcSyntaxError):
            return blocks, number - 1
        if block is not None:
            blocks.append(block)
    return blocks, len(lines)


class _Line:
    """One line's tokens read by recursive descent, as the grammar's rules say."""

    __slots__ = ("text", "toks", "at", "line")

    def __init__(self, text: str, line: int):
        self.text = text
        self.toks = _tokens(text)
        self.at = 0
        self.line = line

    # --- tokens ---------------------------------------------------------------------------------
    def peek(self, ahead: int = 0) -> tuple[str, str, int]:
        return self.toks[self.at + ahead]

    def take(self) -> tuple[str, str, int]:
        tok = self.toks[self.at]
        if tok is _END:
            raise _GiveUp
        self.at += 1
        return tok

    def expect(self, kind: str) -> tuple[str, str, int]:
        tok = self.take()
        if tok[0] != kind:
            raise _GiveUp
        return tok

    def pos(self, tok: tuple[str, str, int]) -> n.Pos:
        return n.Pos(self.line, tok[2])

    def token(self, tok: tuple[str, str, int], kind: str) -> Token:
        return Token(kind, tok[1], line=self.line, column=tok[2])

    # --- blocks ---------------------------------------------------------------------------------
    def block(self):
        """``block``: the program name line, or [N number] [label:] [body]; then the line ends."""
        kind = self.peek()[0]
        if kind == "END":
            return None
        if kind == "PROGRAM_HEADER":
            result: tuple = ("HEADER", self.token(self.take(), "PROGRAM_HEADER"))
        else:
            items: list = []
            if kind == "BLOCKNO":
                items.append(self.token(self.take(), "BLOCKNO"))
            if self.peek()[0] == "NAME" and self.peek(1)[0] == ":":
                tok = self.token(self.take(), "NAME")
                self.take()
                b.check_user_name(tok.value.upper(), b.pos_of(tok))
                items.append(("LABEL", tok))
            if self.peek()[0] != "END":
                items.append(self.body())
            result = ("BLOCK", items)
        if self.peek() is not _END:
            raise _GiveUp
        return result

    def body(self) -> list:
        kind = self.peek()[0]
        if kind == "IF":
            return self.if_goto()
        if kind == "DEF":
            return self.definition()
        words = [self.word()]
        while self.peek()[0] != "END":
            words.append(self.word())
        return words

    def if_goto(self) -> list:
        kw = self.take()
        condition = self.expr()
        return [n.IfGoto(condition, self.goto(), self.pos(kw))]

    def definition(self) -> list:
        kw = self.take()
        type_tok = self.expect("NAME")
        length = None
        if self.peek()[0] == "[":
            self.take()
            length = int(self.expect("INT_NUMBER")[1])
            self.expect("]")
        items = [self.def_item()]
        while self.peek()[0] == ",":
            self.take()
            items.append(self.def_item())
        return b.definition(type_tok[1], self.pos(type_tok), length, items, self.pos(kw))

    def def_item(self) -> n.DefItem:
        tok = self.expect("NAME")
        dims = None
        if self.peek()[0] == "[":
            self.take()
            numbers = [int(self.expect("INT_NUMBER")[1])]
            while self.peek()[0] == ",":
                self.take()
                numbers.append(int(self.expect("INT_NUMBER")[1]))
            self.expect("]")
            dims = tuple(numbers)
        init = None
        if self.peek()[0] == "=":
            self.take()
            init = self.expr()
        return b.def_item(tok[1], dims, init, self.pos(tok))

    # --- words ----------------------------------------------------------------------------------
    def word(self):
        tok = self.peek()
        kind = tok[0]
        if kind == "ADDRESS":
            self.take()
            return b.address_word(tok[1], self.pos(tok))
        if kind == "NAME":
            return self.name_word()
        if kind == "RPARAM":
            self.take()
            return self.assignment(b.rparam(tok[1], self.line, tok[2]))
        if kind in _JUMPS:
            return self.goto()
        if kind == "MSG":
            self.take()
            self.expect("(")
            value = None if self.peek()[0] == ")" else self.expr()
            self.expect(")")
            return n.Msg(value, self.pos(tok))
        if kind == "STOPRE":
            self.take()
            return n.Stopre(self.pos(tok))
        raise _GiveUp

    def name_word(self):
        """A word that starts with a name: a call, an assignment or the name alone."""
        tok = self.take()
        follow = self.peek()[0]
        if follow == "(":
            return n.CycleCall(tok[1].upper(), tuple(self.call_args()), self.pos(tok))
        if follow == "[":
            return self.assignment(n.Var(tok[1].upper(), tuple(self.indices()), self.pos(tok)))
        if follow == "=":
            return self.assignment(n.Var(tok[1].upper(), (), self.pos(tok)))
        return b.bare_name(tok[1], self.pos(tok))

    def assignment(self, target: n.Var):
        self.expect("=")
        tok = self.peek()
        if tok[0] != "SET":
            return b.assignment(target, self.expr())
        self.take()
        self.expect("(")
        values = self.exprs()
        self.expect(")")
        return b.assignment(target, ("SET", tuple(values), self.pos(tok)))

    def goto(self) -> n.Goto:
        kw = self.take()
        target = self.take()
        if kw[0] not in _JUMPS or target[0] not in ("NAME", "BLOCKNO"):
            raise _GiveUp
        return b.goto(kw[1], target[1], target[0] == "BLOCKNO", self.pos(kw))

    # --- expressions ----------------------------------------------------------------------------
    def exprs(self) -> list:
        values = [self.expr()]
        while self.peek()[0] == ",":
            self.take()
            values.append(self.expr())
        return values

    def call_args(self) -> list:
        """``"(" [exprs] ")"``."""
        self.take()
        values = [] if self.peek()[0] == ")" else self.exprs()
        self.expect(")")
        return values

    def indices(self) -> list:
        """``"[" exprs "]"``."""
        self.take()
        values = self.exprs()
        self.expect("]")
        return values

    def expr(self) -> n.Expr:
        """``unary (operator unary)*``, the operators applied by ``build.climb``."""
        first = self.unary()
        toks = self.toks
        if toks[self.at][0] not in _BINARY:
            return first
        items: list = [first]
        while toks[self.at][0] in _BINARY:
            op = toks[self.at]
            self.at += 1
            items.append((op[0], op[1], n.Pos(self.line, op[2])))
            items.append(self.unary())
        return b.climb(items)

    def unary(self) -> n.Expr:
        tok = self.toks[self.at]
        if tok[0] in _PREFIX:
            self.at += 1
            return b.unary(tok[1], self.unary(), n.Pos(self.line, tok[2]))
        return self.atom()

    def atom(self) -> n.Expr:
        tok = self.toks[self.at]
        self.at += 1                            # past the end only to give up below
        kind = tok[0]
        if kind == "INT_NUMBER" or kind == "NUMBER":
            return n.Num(b.number_value(tok[1]), n.Pos(self.line, tok[2]))
        if kind == "RPARAM":
            return b.rparam(tok[1], self.line, tok[2])
        if kind == "NAME":
            return self.named(tok)
        if kind == "(":
            value = self.expr()
            self.expect(")")
            return value
        if kind == "STRING":
            return n.Str(tok[1][1:-1], self.pos(tok))
        if kind == "TRUE" or kind == "FALSE":
            return n.Num(1 if kind == "TRUE" else 0, self.pos(tok))
        if kind == "ADDRESS" and tok[1][1] in "+-":
            return self.split_address(tok)
        raise _GiveUp

    def split_address(self, tok: tuple[str, str, int]) -> n.Expr:
        """``A+1`` in an expression: lark's lexer reads no address there but the name A, then
        ``+1`` (its lexer is contextual; this one is not)."""
        self.toks[self.at:] = _tokens(self.text, tok[2])        # again from the sign
        return n.Var(tok[1][0].upper(), (), self.pos(tok))

    def named(self, tok: tuple[str, str, int]) -> n.Expr:
        """A name in an expression: a variable, an element of an array, a function's value."""
        follow = self.peek()[0]
        if follow == "[":
            return n.Var(tok[1].upper(), tuple(self.indices()), self.pos(tok))
        if follow == "(":
            return n.Func(tok[1].upper(), tuple(self.call_args()), self.pos(tok))
        return n.Var(tok[1].upper(), (), self.pos(tok))

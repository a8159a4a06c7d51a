"""Bounded NC input (issue 24 item 5, issue 25 item 3): what a program may not be, refused with
line and column before anything runs, and the run-time bounds that end a runaway program."""

from __future__ import annotations

import pytest
from nc_runtimes import FakeRuntime

from app.nc.errors import NcSyntaxError
from app.nc.interpreter import Interpreter
from app.nc.parser import MAX_BLOCK_CHARS, MAX_NESTING, parse_program
from app.nc.variables import Variables
from engine import alarms


def syntax_error(text: str) -> NcSyntaxError:
    with pytest.raises(NcSyntaxError) as e:
        parse_program(text)
    return e.value


# --- characters ------------------------------------------------------------------------------------

@pytest.mark.parametrize("text, column", [
    ("G0 X１２", 5),          # fullwidth digits (issue 25)
    ("G0 X1٢", 6),            # an Arabic-Indic digit after an ASCII one
    ("R1=１", 4),
    ("G0 Ｘ12", 4),           # a fullwidth letter
])
def test_digits_and_letters_are_ascii(text, column):
    err = syntax_error(f"N10 G90\n{text}\nM30")
    assert (err.line, err.column) == (2, column)
    assert err.alarm == alarms.NC_SYNTAX and "ASCII" in err.message


def test_texts_in_quotes_and_comments_may_hold_any_character():
    program = parse_program('MSG("Maß prüfen: 测量") ; Prüfung（１）\nM30')
    assert program.blocks[0].words[0].value.value == "Maß prüfen: 测量"


# --- length and nesting ----------------------------------------------------------------------------

def test_a_20000_term_expression_is_a_located_refusal_not_a_crash():
    err = syntax_error("G90\nR1=" + "+".join(["1"] * 20_000) + "\nM30")
    assert (err.line, err.column) == (2, MAX_BLOCK_CHARS + 1)
    assert str(MAX_BLOCK_CHARS) in err.message


def test_a_block_of_the_longest_length_is_read():
    terms = (MAX_BLOCK_CHARS - 3) // 2                   # "R1=" then "1+1+...+1"
    program = parse_program("R1=" + "+".join(["1"] * terms))
    interp = Interpreter(FakeRuntime(), Variables(axes=("X", "Y", "Z")))
    interp.load(program)
    interp.run()
    assert interp.variables.read("R1") == terms


def test_nesting_beyond_the_limit_names_the_parenthesis():
    deep = "R1=" + "(" * (MAX_NESTING + 1) + "1" + ")" * (MAX_NESTING + 1)
    err = syntax_error(deep)
    assert (err.line, err.column) == (1, 4 + MAX_NESTING)      # the first parenthesis one too deep
    ok = "R1=" + "(" * MAX_NESTING + "2" + ")" * MAX_NESTING
    interp = Interpreter(FakeRuntime(), Variables(axes=("X", "Y", "Z")))
    interp.load(ok)
    interp.run()
    assert interp.variables.read("R1") == 2


def test_two_comparisons_in_a_chain_are_refused():
    err = syntax_error("R1=1 < 2 < 3")
    assert (err.line, err.column) == (1, 10)


@pytest.mark.parametrize("expr, value", [
    ("2+3*4", 14), ("(2+3)*4", 20), ("2*3+4", 10), ("10-4-3", 3), ("24/4/2", 3), ("-2*3", -6),
    ("1+1==2", 1), ("(2 > 1) AND (1 > 2)", 0), ("2 > 1 AND 0", 1), ("1 OR 0 AND 0", 1), ("7 MOD 4 * 2", 6), ("1 XOR 1 OR 1", 1),
])
def test_operator_priorities(expr, value):
    interp = Interpreter(FakeRuntime(), Variables(axes=("X", "Y", "Z")))
    interp.load(f"R1={expr}")
    interp.run()
    assert interp.variables.read("R1") == value


# --- jumps -----------------------------------------------------------------------------------------

def test_jumps_take_the_nearest_target_in_their_direction():
    text = "N10 R1=R1+1\nN20 IF R1 < 3 GOTOB N10\nN10 R2=R2+1\nN30 IF R2 < 2 GOTOB N10\nM30"
    interp = Interpreter(FakeRuntime(), Variables(axes=("X", "Y", "Z")))
    interp.load(text)
    assert interp.run().state == "done"
    # the first N10 runs 3 times (jumps from N20), the second twice (the nearest N10 backwards from N30)
    assert (interp.variables.read("R1"), interp.variables.read("R2")) == (3, 2)


# --- run-time bounds -------------------------------------------------------------------------------

def test_an_endless_loop_ends_with_an_alarm_at_the_jump_limit():
    rt = FakeRuntime()
    interp = Interpreter(rt, Variables(axes=("X", "Y", "Z")), max_jumps=500)
    interp.load("START: R1=R1+1\nIF R1 > 0 GOTOB START\nG0 X10\nM30")
    result = interp.run()
    assert result.state == "alarm" and result.alarm.alarm == alarms.NC_RUNAWAY
    assert result.block.line == 2
    assert interp.variables.read("R1") == 501              # 500 jumps allowed, the 501st refused
    assert rt.moves == []


def test_the_watchdog_ends_a_loop_that_never_moves():
    rt = FakeRuntime()
    interp = Interpreter(rt, Variables(axes=("X", "Y", "Z")), watchdog_s=0.0)
    interp.load("START: R1=R1+1\nGOTOB START\nM30")
    result = interp.run()
    assert result.state == "alarm" and result.alarm.alarm == alarms.NC_RUNAWAY
    assert "watchdog" in result.alarm.message

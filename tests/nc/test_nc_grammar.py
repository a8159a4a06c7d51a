"""Grammar and parser: a table of valid programs (every construct) and of invalid ones with the
line and column the operator is shown."""

from __future__ import annotations

import pytest

from app.nc import nodes as n
from app.nc.errors import NcSyntaxError
from app.nc.parser import parse_program, parse_reference
from engine import alarms


def words(text: str, block: int = 0):
    return parse_program(text).blocks[block].words


def num(word) -> float:
    assert isinstance(word.value, n.Num), word
    return word.value.value


# --- valid programs ---------------------------------------------------------------------------------

def test_block_numbers_comments_and_empty_lines():
    p = parse_program("%_N_TEST_MPF\n; a comment line\n\nN10 G0 X10 ; comment after the words\nN20\n"
                      "G1 X5 F100\n")
    assert p.header == "%_N_TEST_MPF"
    assert [(b.line, b.number) for b in p.blocks] == [(4, 10), (5, 20), (6, None)]
    assert p.blocks[0].text == "N10 G0 X10 ; comment after the words"
    assert p.blocks[1].words == ()


def test_words_in_any_order_and_without_spaces():
    a = words("G1X10Y-2.5Z.5F100")
    b = words("F100 Z.5 Y-2.5 X10 G1")
    assert {type(w).__name__ for w in a} == {"GCode", "AxisWord", "Address"}
    axes_a = {w.axis: num(w) for w in a if isinstance(w, n.AxisWord)}
    axes_b = {w.axis: num(w) for w in b if isinstance(w, n.AxisWord)}
    assert axes_a == axes_b == {"X": 10, "Y": -2.5, "Z": 0.5}
    assert [w.letter for w in a if isinstance(w, n.Address)] == ["F"]


@pytest.mark.parametrize("text, number", [
    ("G0", 0), ("G1", 1), ("G17", 17), ("G18", 18), ("G19", 19), ("G90", 90), ("G91", 91),
    ("G53", 53), ("G54", 54), ("G57", 57), ("G505", 505), ("G599", 599), ("G500", 500),
    ("G70", 70), ("G71", 71), ("G700", 700), ("G710", 710), ("G100 X1", 100), ("G101 X1", 101),
    ("G102", 102),
])
def test_every_g_function(text, number):
    assert words(text)[0] == n.GCode(number, n.Pos(1, 1))


@pytest.mark.parametrize("m", [0, 2, 3, 4, 5, 6, 17, 30])
def test_every_m_function(m):
    assert words(f"S100 M{m}" if m in (3, 4) else f"M{m}")[-1].number == m


def test_addresses_with_constants_and_expressions():
    ws = words("T9 D1 S1000 F=R1*2 X=R1+2 Y10 A=-R2")
    t, d, s, f, x, y, a = ws
    assert (t.letter, num(t)) == ("T", 9) and (d.letter, num(d)) == ("D", 1) and num(s) == 1000
    assert isinstance(f, n.Address) and isinstance(f.value, n.Binary) and f.value.op == "*"
    assert isinstance(x, n.AxisWord) and x.axis == "X" and isinstance(x.value, n.Binary)
    assert isinstance(a.value, n.Unary) and a.value.op == "-"


def test_spos_meas_meaw():
    sp, = words("SPOS=90")
    assert isinstance(sp, n.Spos) and num(sp) == 90
    meas, g1, x = words("MEAS=1 G1 X100")
    assert isinstance(meas, n.Meas) and meas.kind == "MEAS" and num(meas) == 1
    meaw = words("MEAW=+1 G1 X100")[0]
    assert meaw.kind == "MEAW" and isinstance(meaw.value, n.Unary)


def test_r_parameters_and_gud_variables_with_indices():
    r1, r5, ev, wp, ind = words("R1=5 R[5]=3 _EV[9]=0.004 _WP[0,1]=2 R[R1+1]=R1")
    assert r1.target == n.Var("R", (n.Num(1, n.Pos(1, 2)),), n.Pos(1, 1))
    assert r5.target.name == "R" and r5.target.indices[0].value == 5
    assert ev.target.name == "_EV" and ev.target.indices[0].value == 9 and ev.values[0].value == 0.004
    assert wp.target.name == "_WP" and [i.value for i in wp.target.indices] == [0, 1]
    assert isinstance(ind.target.indices[0], n.Binary)
    mw = words("R2=$AA_MW[X]")[0].values[0]
    assert mw.name == "$AA_MW" and mw.indices[0] == n.Var("X", (), n.Pos(1, 11))


def test_case_insensitive():
    ws = words("r1=2 g1 x=r1 _setval=3 f100")
    assert ws[0].target.name == "R" and ws[1] == n.GCode(1, n.Pos(1, 6))
    assert ws[2].axis == "X" and ws[3].target.name == "_SETVAL"


def test_arithmetic_precedence_and_parentheses():
    (a,) = words("R1=1+2*3-(4-5)/-2")
    e = a.values[0]
    assert e.op == "-" and e.left.op == "+" and e.left.right.op == "*"
    assert e.right.op == "/" and e.right.right.op == "-"     # unary minus


def test_comparisons_bind_weakest_as_on_the_840d():
    e = words("R1=1==2 OR 3")[0].values[0]
    assert e.op == "==" and e.right.op == "OR"
    e = words("R1=(R2==1) AND (R3<>2)")[0].values[0]
    assert e.op == "AND" and e.left.op == "==" and e.right.op == "<>"
    e = words("R1=7 DIV 2 + 7 MOD 2")[0].values[0]
    assert e.op == "+" and e.left.op == "DIV" and e.right.op == "MOD"


def test_functions():
    e = words("R1=ATAN2(1, SQRT(ABS(-4)))+SIN(30)")[0].values[0]
    assert isinstance(e.left, n.Func) and e.left.name == "ATAN2" and len(e.left.args) == 2
    assert e.left.args[1].name == "SQRT" and e.right.name == "SIN"


def test_cycle_calls():
    assert words("CYCLE977") == (n.CycleCall("CYCLE977", (), n.Pos(1, 1)),)
    (call,) = words("CYCLE119(_SETV[0], 2)")
    assert call.name == "CYCLE119" and len(call.args) == 2
    assert words("L977")[0] == n.CycleCall("L977", (), n.Pos(1, 1))
    # SW 6.3 style: parameters as separate assignments, then the call
    p = parse_program("N60 _TUL=0.03 _TLL=-0.03 _EVNUM=10 _K=3\nN61 _MVAR=1 _SETVAL=132 _KNUM=2001\nN70 CYCLE977")
    assert [len(b.words) for b in p.blocks] == [4, 3, 1]


def test_labels_jumps_if_def_msg_stopre():
    p = parse_program("DEF INT KK, AA[10]=3\nDEF REAL MM[2,3]\nDEF STRING[8] TXT\nN20 ANF: G0 X0\n"
                      "STOPRE\nIF KK<10 GOTOB ANF\nGOTOF ENDE\nMSG(\"text\")\nENDE: M2")
    d = p.blocks[0].words[0]
    assert d.type == "INT" and [i.name for i in d.items] == ["KK", "AA"] and d.items[1].dims == (10,)
    assert p.blocks[1].words[0].items[0].dims == (2, 3) and p.blocks[2].words[0].length == 8
    assert p.labels == {"ANF": 3, "ENDE": 8}
    assert isinstance(p.blocks[4].words[0], n.Stopre)
    ig = p.blocks[5].words[0]
    assert isinstance(ig, n.IfGoto) and ig.goto.direction == "GOTOB" and ig.goto.target == "ANF"
    assert p.blocks[6].words[0] == n.Goto("GOTOF", "ENDE", n.Pos(7, 1))
    assert p.blocks[7].words[0].value == n.Str("text", n.Pos(8, 5))
    assert parse_program("GOTOF N30\nN30 M30").blocks[0].words[0].target == "N30"


def test_set_fills_an_array():
    (a,) = words("_SETV[0]=SET(1,2,R1)")
    assert a.is_set and len(a.values) == 3


def test_measuring_offsets_syntax():
    g, x, y = words("N10 G101 X1 Y7")
    assert g.number == 101 and (x.axis, num(x)) == ("X", 1) and (y.axis, num(y)) == ("Y", 7)
    assert words("G102") == (n.GCode(102, n.Pos(1, 1)),)
    assert [w.axis for w in words("G102 X1 Y0")[1:]] == ["X", "Y"]
    g, f, x = words("G100 F100 X50")
    assert g.number == 100 and num(x) == 50


def test_reference_for_the_api():
    assert parse_reference("R1") == n.Var("R", (n.Num(1, n.Pos(1, 10)),), n.Pos(1, 9))
    assert parse_reference("_EV[9]").indices[0].value == 9
    assert parse_reference("$AA_MM[X]").indices[0].name == "X"
    with pytest.raises(NcSyntaxError):
        parse_reference("R1+2")


# --- invalid programs: line, column, and what the operator reads -------------------------------------

INVALID = [
    # (program, line, column, words the message contains, alarm)
    ("G1 X10\nG1 X10 Y20 *", 2, 12, "unexpected '*' after Y20", alarms.NC_SYNTAX),
    ("N10 G0 X0\nN20 G1 X=", 2, 10, "ends too early after '='", alarms.NC_SYNTAX),
    ("G1 X=R1+ Y5", 1, 10, "unexpected 'Y5' after '+'", alarms.NC_SYNTAX),
    ("R1=(2+3", 1, 8, "expected ')'", alarms.NC_SYNTAX),
    ("G1 @X", 1, 4, "unexpected character '@' after G1", alarms.NC_SYNTAX),
    ("R1=1+*2", 1, 6, "unexpected '*' after '+'", alarms.NC_SYNTAX),
    ("IF R1 X10", 1, 7, "expected GOTO, GOTOB or GOTOF", alarms.NC_SYNTAX),
    ("G1 X10 )", 1, 8, "unexpected ')' after X10", alarms.NC_SYNTAX),
    ("/N10 G1 X1", 1, 1, "block skip", alarms.NC_SYNTAX),
    ("G1 X10 Y", 1, 8, "Y needs a value", alarms.NC_SYNTAX),
    ("G101 X", 1, 6, "X needs a value", alarms.NC_SYNTAX),
    ("G102 X1 Y", 1, 9, "Y needs a value", alarms.NC_SYNTAX),
    ("G0\nG2 X5 Y5", 2, 1, "G2 is not a G function", alarms.NC_G_FUNCTION_UNKNOWN),
    ("G54 G55", 1, 5, "G55 and G54 exclude each other", alarms.NC_SYNTAX),
    ("G1 G0 X1", 1, 4, "G0 and G1 exclude each other", alarms.NC_SYNTAX),
    ("M7", 1, 1, "M7 is not an M function", alarms.NC_SYNTAX),
    ("X10 X20", 1, 5, "X is programmed twice", alarms.NC_SYNTAX),
    ("G1.5 X1", 1, 1, "G takes a whole number", alarms.NC_SYNTAX),
    ("I5", 1, 1, "circle", alarms.NC_SYNTAX),
    ("G1 X10 N20", 1, 8, "must stand at the start", alarms.NC_SYNTAX),
    ("G100 X1 Y2", 1, 9, "G100 measures one axis", alarms.NC_SYNTAX),
    ("G100", 1, 1, "G100 measures one axis", alarms.NC_SYNTAX),
    ("G100 G1 X5", 1, 6, "G100 is itself the measuring move", alarms.NC_SYNTAX),
    ("G100 A5", 1, 6, "geometry axis", alarms.NC_SYNTAX),
    ("G101", 1, 1, "G101 needs at least one axis", alarms.NC_SYNTAX),
    ("G101 X1 G1", 1, 9, "G101 takes axis factors only", alarms.NC_SYNTAX),
    ("G102 X1 M3", 1, 9, "G102 takes axis factors only", alarms.NC_SYNTAX),
    ("MEAS=1 G1", 1, 1, "MEAS needs an axis motion", alarms.NC_SYNTAX),
    ("MEAS=1 G0 X10", 1, 8, "program G1, not G0", alarms.NC_SYNTAX),
    ("MEAS=1 MEAW=1 G1 X1", 1, 8, "MEAS/MEAW is programmed twice", alarms.NC_SYNTAX),
    ("SPOS=0 M3 S100", 1, 1, "SPOS positions the stopped spindle", alarms.NC_SYNTAX),
    ("CYCLE977 CYCLE978", 1, 10, "only one cycle call per block", alarms.NC_SYNTAX),
    ("G0 X0\nGOTOF ENDE", 2, 1, "no label or block ENDE after this block", alarms.NC_JUMP_TARGET),
    ("AB: G0 X0\nGOTOB BA", 2, 1, "no label or block BA before this block", alarms.NC_JUMP_TARGET),
    ("A: G0 X0", 1, 1, "A is a word of the language", alarms.NC_SYNTAX),
    ("ANF: G0 X0\nANF: G0 X1", 2, 1, "label ANF is defined twice", alarms.NC_SYNTAX),
    ("R1=5\nDEF REAL Q", 2, 1, "DEF must come before the first instruction", alarms.NC_SYNTAX),
    ("DEF FRAME QQ", 1, 5, "the type must be REAL, INT, BOOL or STRING", alarms.NC_SYNTAX),
    ("DEF REAL X", 1, 10, "X is a word of the language and cannot be used as a name", alarms.NC_SYNTAX),
    ("DEF REAL[3] Q", 1, 5, "only STRING takes a length", alarms.NC_SYNTAX),
    ("G0 X0\n%_N_LATE_MPF", 2, 1, "must be the first line", alarms.NC_SYNTAX),
    ("G=1", 1, 1, "G= is not allowed", alarms.NC_SYNTAX),
    ("X=SET(1,2)", 1, 1, "SET", alarms.NC_SYNTAX),
    ("ENDIF", 1, 1, "structured control statements", alarms.NC_SYNTAX),
]


@pytest.mark.parametrize("text, line, column, message, alarm", INVALID)
def test_invalid_programs(text, line, column, message, alarm):
    with pytest.raises(NcSyntaxError) as info:
        parse_program(text)
    err = info.value
    assert (err.line, err.column) == (line, column), str(err)
    assert message in err.message, str(err)
    assert err.alarm is alarm
    assert str(err).endswith(f"in line {line}, column {column}")
    assert err.block_text == text.split("\n")[line - 1].strip()
    assert err.to_dict()["code"] == alarm.number


def test_message_reads_like_the_operator_expects():
    with pytest.raises(NcSyntaxError) as info:
        parse_program("N10 G0 X0\nN20 G0 Y0\nN30 G1 X=5 ( Y2")
    assert str(info.value) == "unexpected '(' after 5 in line 3, column 12"

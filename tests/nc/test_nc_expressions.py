"""Expressions and variables against hand-computed values."""

from __future__ import annotations

import math

import pytest
from nc_runtimes import FakeRuntime

from app.nc.errors import NcAlarm, NcSyntaxError
from app.nc.expressions import Evaluator
from app.nc.interpreter import Interpreter
from app.nc.parser import parse_program
from app.nc.variables import (
    CallbackBacking,
    IndexOutOfRange,
    InvalidValue,
    UnknownVariable,
    VarDef,
    Variables,
    WriteProtected,
)
from engine import alarms


def value_of(expr: str, variables: Variables | None = None):
    v = variables or Variables()
    assign = parse_program(f"R99={expr}").blocks[0].words[0]
    return Evaluator(v).eval(assign.values[0])


@pytest.mark.parametrize("expr, expected", [
    ("1+2*3", 7), ("(1+2)*3", 9), ("10-4-3", 3), ("2*-3", -6), ("-2+5", 3), ("--2", 2),
    ("7/2", 3.5), ("8/4/2", 1.0), ("7 DIV 2", 3), ("-7 DIV 2", -3), ("7 MOD 3", 1), ("-7 MOD 3", -1),
    ("7.5 MOD 2", 1.5), ("1+2 == 3", True), ("3 <> 3", False), ("2 < 3", True), ("3 <= 3", True),
    ("4 >= 5", False), ("5 > 4", True), ("0.1+0.2 == 0.3", True), ("1 AND 0", False), ("1 OR 0", True),
    ("1 XOR 1", False), ("NOT 0", True), ("NOT 2", False), ("TRUE", 1), ("FALSE", 0),
    ("(1==1) AND (2==2)", True),
    ("1 == 1 AND 2", True),          # 840D priorities: 1 == (1 AND 2)
    ("\"ABC\" == \"ABC\"", True), ("\"ABC\" <> \"ABD\"", True),
])
def test_operators(expr, expected):
    assert value_of(expr) == pytest.approx(expected)


@pytest.mark.parametrize("expr, expected", [
    ("SIN(30)", 0.5), ("COS(60)", 0.5), ("TAN(45)", 1.0), ("ASIN(0.5)", 30.0), ("ACOS(0.5)", 60.0),
    ("ATAN2(1, 1)", 45.0), ("ATAN2(1, -1)", 135.0), ("ATAN2(-1, -1)", -135.0), ("ATAN2(0, -1)", 180.0),
    ("SQRT(16)", 4.0), ("ABS(-2.5)", 2.5), ("POT(3)", 9.0), ("TRUNC(-2.7)", -2.0), ("ROUND(2.5)", 3.0),
    ("ROUND(-2.5)", -3.0), ("LN(EXP(2))", 2.0), ("MINVAL(3, -1)", -1.0), ("MAXVAL(3, -1)", 3.0),
    ("SQRT(POT(3)+POT(4))*COS(0)", 5.0),
])
def test_functions_in_degrees(expr, expected):
    assert value_of(expr) == pytest.approx(expected, abs=1e-12)


@pytest.mark.parametrize("expr, message", [
    ("1/0", "division by zero"), ("1 DIV 0", "division by zero"), ("1 MOD 0", "division by zero"),
    ("SQRT(-1)", "square root of a negative"), ("ASIN(2)", "within -1..1"), ("LN(0)", "greater than 0"),
    ("EXP(1000)", "EXP"),
])
def test_arithmetic_errors(expr, message):
    from app.nc.expressions import EvalError
    with pytest.raises(EvalError) as info:
        value_of(expr)
    assert message in info.value.message
    assert info.value.alarm is alarms.NC_ARITHMETIC


def test_r_parameters_and_arrays():
    v = Variables()
    v.set("R", 2.5, (1,))
    assert value_of("R1*2 + R[1] + R[R1-1.5]", v) == pytest.approx(5 + 2.5 + 2.5)   # R[1.0] is R1
    assert v.get("R", (99,)) == 0.0
    with pytest.raises(IndexOutOfRange):
        v.get("R", (100,))
    with pytest.raises(IndexOutOfRange):
        v.set("R", 1, (1.5,))


def test_measuring_cycle_gud_defaults():
    v = Variables()
    assert v.get("_FA") == 2.0 and v.get("_TSA") == 2.0 and v.get("_TZL") == 0.001 and v.get("_TMV") == 0.7
    assert v.get("_TUL") == 1.0 and v.get("_TLL") == -1.0 and v.get("_TDIF") == 1.2 and v.get("_TNVL") == 1.2
    assert v.get("_PRNUM") == 1 and v.get("_NMSP") == 1 and v.get("_K") == 1 and v.get("_EVNUM") == 0
    assert v.get("_VMS") == 0.0 and v.get("_MVAR") == 0 and v.get("_KNUM") == 0 and v.get("_SETVAL") == 0.0
    assert len(v.snapshot("_OVR")) == 32 and len(v.snapshot("_OVI")) == 14 and len(v.snapshot("_SETV")) == 9
    assert len(v.snapshot("_EV")) == 20 and len(v.snapshot("_MV")) == 20
    assert v.snapshot("_CM") == [100, 1000, 1, 0.005, 20, 4, 10, 0]
    assert v.snapshot("_SPEED") == [50, 1000, 1000, 900]
    assert v.get("_CBIT", (3,)) is True and v.get("_CBIT", (8,)) is True and v.get("_CBIT", (14,)) is False
    assert v.get("_CHBIT", (2,)) is True and v.get("_CHBIT", (24,)) is True and v.get("_CHBIT", (4,)) is False
    # probe records: the defaults per record (measuring-math §4.3)
    assert v.snapshot("_WP")[2] == [6, 3, -3, 3, -3, 3, -3, 0, 0, 0, 0]
    assert v.get("_TP", (1, 7)) == 133 and v.get("_TP", (1, 9)) == 2
    assert v.get("_PROTSYM", (0,)) == ";" and v.get("_DIGIT") == 3
    assert v.definition("_MVAR").type == "INT" and v.definition("_TNAME").length == 32


def test_types_are_enforced():
    v = Variables()
    v.set("_MVAR", 1001.6)                 # INT rounds half away from zero (840D)
    assert v.get("_MVAR") == 1002
    v.set("_KNUM", -2.5)
    assert v.get("_KNUM") == -3
    v.set("_CHBIT", 5, (4,))
    assert v.get("_CHBIT", (4,)) is True
    v.set("_TNAME", "PROBE")
    assert v.get("_TNAME") == "PROBE"
    with pytest.raises(InvalidValue):
        v.set("_TNAME", "X" * 33)
    with pytest.raises(InvalidValue):
        v.set("_SETVAL", "abc")
    with pytest.raises(InvalidValue):
        v.set("_SETVAL", math.inf)
    with pytest.raises(InvalidValue):
        v.set("_MVAR", 2.0**40)
    with pytest.raises(UnknownVariable):
        v.get("_NOPE")


def test_system_variables_are_read_only_for_programs():
    v = Variables()
    with pytest.raises(WriteProtected):
        v.set("$AA_MM", 1.0, ("X",))
    v.set_system("$AA_MM", 12.5, ("X",))
    assert v.get("$AA_MM", ("X",)) == 12.5
    assert v.snapshot("$AA_MM") == {"X": 12.5, "Y": 0.0, "Z": 0.0}
    assert v.get("$AC_MEA", (1,)) is False
    with pytest.raises(IndexOutOfRange):
        v.get("$AC_MEA", (0,))


def test_persistent_arrays_through_a_mapping_and_callbacks():
    ev: dict = {9: 0.004}
    writes = []
    db = {3: 0.5}
    mv = CallbackBacking(lambda k: db.get(k), lambda k, value: (writes.append((k, value)), db.__setitem__(k, value)))
    v = Variables(backings={"_EV": ev, "_MV": mv})
    assert v.get("_EV", (9,)) == 0.004 and v.get("_EV", (0,)) == 0.0
    assert v.get("_MV", (3,)) == 0.5
    v.set("_EV", 0.01, (2,))
    v.set("_MV", 0.25, (9,))
    assert ev == {9: 0.004, 2: 0.01}
    assert writes == [(9, 0.25)] and db[9] == 0.25
    assert v.snapshot("_MV")[9] == 0.25


def test_two_dimensional_arrays_and_set():
    v = Variables()
    ev = Evaluator(v)
    ev.assign(parse_program("_WP[1,0]=SET(5.99, 2.9, -2.9)").blocks[0].words[0])
    assert v.get("_WP", (1, 0)) == 6          # not yet: pending until commit
    ev.commit()
    assert [v.get("_WP", (1, i)) for i in range(4)] == [5.99, 2.9, -2.9, 3]
    ev = Evaluator(v)
    with pytest.raises(Exception, match="beyond the end"):
        ev.assign(parse_program("_SETV[7]=SET(1,2,3)").blocks[0].words[0])


def test_api_references():
    v = Variables()
    v.write("_EV[9]", 0.004)
    v.write("R1", 3)
    v.write("_WP[0,1]", 2.95)
    assert v.read("_EV[9]") == 0.004 and v.read("R1") == 3.0 and v.read("R[1]") == 3.0
    assert v.read("_WP[0,1]") == 2.95
    assert v.read("_OVR") == [0.0] * 32
    assert v.read("$AA_MM") == {"X": 0.0, "Y": 0.0, "Z": 0.0}
    assert v.read("$AA_MM[X]") == 0.0
    with pytest.raises(WriteProtected):
        v.write("$AA_MW[X]", 1)
    with pytest.raises(IndexOutOfRange):
        v.write("_OVR", 1)
    with pytest.raises(UnknownVariable):
        v.read("R1+")


def test_custom_definitions():
    v = Variables([VarDef("MYVAR", "REAL", (2, 2), (1, 2, 3, 4))])
    assert v.snapshot("MYVAR") == [[1, 2], [3, 4]]
    assert v.names() == ["MYVAR"]


# --- through the interpreter: assignments in programs ------------------------------------------------

def run(text: str, **kw):
    rt = FakeRuntime(**kw)
    interp = Interpreter(rt)
    interp.load(text)
    result = interp.run()
    return interp, result, rt


def test_assignment_blocks_evaluate_left_to_right():
    interp, result, _ = run("R1=5 R2=R1*2 _SETVAL=R2+0.5\nR3=R1 R1=1\n_EV[9]=0.004 _OVR[4]=_EV[9]*1000")
    v = interp.variables
    assert result.state == "done"
    assert v.get("R", (2,)) == 10.0 and v.get("_SETVAL") == 10.5
    assert v.get("R", (3,)) == 5.0 and v.get("R", (1,)) == 1.0
    assert v.get("_EV", (9,)) == 0.004 and v.get("_OVR", (4,)) == pytest.approx(4.0)


def test_sw63_parameters_then_cycle_call_the_manual_way():
    seen = {}

    def cycle(ctx):
        seen.update({k: ctx.variables.get(k) for k in ("_MVAR", "_SETVAL", "_TUL", "_TLL", "_KNUM", "_EVNUM", "_K",
                                                        "_TZL", "_TMV", "_TDIF", "_TSA", "_PRNUM", "_VMS", "_NMSP",
                                                        "_FA", "_TNUM")})
        seen["_CHBIT4"] = ctx.variables.get("_CHBIT", (4,))

    interp = Interpreter(FakeRuntime(), cycles={"CYCLE977": cycle})
    interp.load("N50 _CHBIT[4]=1\nN60 _TUL=0.03 _TLL=-0.03 _EVNUM=10 _K=3 _TZL=0.01 _TMV=0.02 _TDIF=0.06 _TSA=1 "
                "_PRNUM=1 _VMS=0 _NMSP=1 _FA=1\nN61 _MVAR=1 _SETVAL=132 _TNUM=20 _KNUM=2001\nN70 CYCLE977\nN570 M2")
    assert interp.run().state == "done"
    assert seen == {"_MVAR": 1, "_SETVAL": 132.0, "_TUL": 0.03, "_TLL": -0.03, "_KNUM": 2001, "_EVNUM": 10, "_K": 3,
                    "_TZL": 0.01, "_TMV": 0.02, "_TDIF": 0.06, "_TSA": 1.0, "_PRNUM": 1, "_VMS": 0.0, "_NMSP": 1,
                    "_FA": 1.0, "_TNUM": 20, "_CHBIT4": True}


@pytest.mark.parametrize("text, line, column, message, alarm", [
    ("R1=1\nN61 MVAR=1 _SETVAL=132", 2, 5, "MVAR is not a known variable", alarms.NC_NAME_UNKNOWN),
    ("R100=1", 1, 2, "within 0..99", alarms.NC_ARRAY_INDEX),
    ("_OVR[32]=1", 1, 6, "within 0..31", alarms.NC_ARRAY_INDEX),
    ("R1=_OVR", 1, 4, "is an array", alarms.NC_ARRAY_INDEX),
    ("_FA[1]=2", 1, 1, "not an array", alarms.NC_ARRAY_INDEX),
    ("$AA_MM[X]=1", 1, 1, "written by the control only", alarms.NC_WRITE_PROTECTED),
    ("R1=$AA_MM[1]", 1, 4, "axis name", alarms.NC_ARRAY_INDEX),
    ("R1=FOO(2)", 1, 4, "FOO is not a function", alarms.NC_NAME_UNKNOWN),
    ("R1=SIN(1,2)", 1, 4, "SIN takes 1 argument", alarms.NC_SYNTAX),
    ("R1=X", 1, 4, "an axis is only an index here", alarms.NC_NAME_UNKNOWN),
    ("G0 A10", 1, 4, "this machine has no axis A", alarms.NC_NAME_UNKNOWN),
    ("CYCLE999", 1, 1, "CYCLE999 is not a cycle of this control", alarms.NC_NAME_UNKNOWN),
    ("DEF REAL R1X", 1, 10, "unexpected 'R1' after REAL", alarms.NC_SYNTAX),
    ("DEF REAL _FA", 1, 10, "a variable _FA already exists", alarms.NC_SYNTAX),
])
def test_names_are_checked_at_load(text, line, column, message, alarm):
    interp = Interpreter(FakeRuntime())
    with pytest.raises(NcSyntaxError) as info:
        interp.load(text)
    err = info.value
    assert (err.line, err.column, err.alarm) == (line, column, alarm), str(err)
    assert message in err.message


@pytest.mark.parametrize("text, line, column, message, alarm", [
    ("R1=0\nR2=5/R1", 2, 5, "division by zero", alarms.NC_ARITHMETIC),
    ("R1=100\nR[R1]=2", 2, 1, "within 0..99", alarms.NC_ARRAY_INDEX),
    ("R1=1.5\n_EV[R1]=2", 2, 1, "whole number", alarms.NC_ARRAY_INDEX),
    ("R1=2**2", 1, 6, "unexpected", alarms.NC_SYNTAX),
    ("_TNAME=\"T\"\n_SETVAL=_TNAME", 2, 9, "not the text", alarms.NC_VALUE_RANGE),
    ("R1=SQRT(-R2-1)", 1, 4, "square root", alarms.NC_ARITHMETIC),
])
def test_runtime_errors_in_expressions_are_located(text, line, column, message, alarm):
    interp = Interpreter(FakeRuntime())
    try:
        interp.load(text)
    except NcSyntaxError as err:
        assert (err.line, err.column, err.alarm) == (line, column, alarm)
        assert message in err.message
        return
    result = interp.run()
    assert result.state == "alarm"
    err = result.alarm
    assert isinstance(err, NcAlarm)
    assert (err.line, err.column, err.alarm) == (line, column, alarm), str(err)
    assert message in err.message


def test_local_variables_with_def():
    interp, result, _ = run("DEF INT KK, NN=3\nDEF REAL VALUES[10]\nDEF STRING[8] TXT=\"ok\"\n"
                            "ANF: VALUES[KK]=KK*1.5 KK=KK+1\nIF KK<NN GOTOB ANF\nR1=VALUES[2] R2=KK\nM30")
    v = interp.variables
    assert result.state == "done"
    assert v.get("R", (1,)) == 3.0 and v.get("R", (2,)) == 3.0
    assert v.get("TXT") == "ok" and v.definition("KK").scope == "LUD"
    interp.load("R1=1")          # a new program: the old locals are gone
    assert not v.has("KK")

"""Logging measuring results, CYCLE100…CYCLE118 (manual §7.1, spec measuring-math §15).

The manual's example §7.1.8 runs on a part made for it: G54 puts the top face at Z 79.987 and a
shaft Ø70 with its axis at X 64.009 / Y 37.998 (the values the manual's log shows); the protocol
file must have the manual's layout line by line, its values those of the part (truth), not the
product's.
"""

from __future__ import annotations

import re

import pytest
from truthkit import TOP_Z, Operator, scenario

SURFACE_Z = 79.987                 # the manual's CYCLE978 actual value
SHAFT = (64.009, 37.998)           # the manual's CYCLE977 actual values
SHAFT_D = 70.0

# the manual's program §7.1.8 (texts in English, the probe is T9 here, "..." lines left out)
EXAMPLE = """%_N_MESSPROGRAMM_1_MPF
;$PATH=/_N_MPF_DIR
DEF INT TEILNUM, AUFTRAGSNUM, MP_ZAEHLER
_CBIT[11]=0
TEILNUM=123456789 AUFTRAGSNUM=6878
_PROTNAME[0]="MESSPROGRAMM_1"
_PROTNAME[1]="PROTOKOLL_1"
_HEADLINE[0]="Part no.:   "<<TEILNUM
_HEADLINE[1]="Order no.:    "<<AUFTRAGSNUM
_HEADLINE[2]="Operator: Tel. 1234"
_PROTSYM[0]="," _PROTSYM[1]="*"
_PROTFORM[0]=60
_PROTFORM[1]=80
_PROTFORM[2]=1
_PROTFORM[3]=3
_PROTFORM[4]=1
_PROTFORM[5]=12
_PROTVAL[0]="Measuring  , Axis       , Setpoint   , Actual     , Difference , Time"
_PROTVAL[1]="point      ,            , value"
MP_ZAEHLER=1 _TXT[0]=<<MP_ZAEHLER
N100 G0 G17 G90 G54 T9 D1 Z100 F1000
N110 X70 Y90
_MVAR=100 _SETVAL=80 _MA=3 _TSA=2 _FA=2 _KNUM=1
_PROTVAL[2]="_TXT[0],_AXIS,_OVR[0],_OVR[4],_OVR[16],_TIME"
N150 CYCLE100
N160 CYCLE978
N170 Z200
N180 X64 Y38
N185 Z130
_MVAR=102 _SETVAL=70 _FA=2 _TSA=2 _ID=-20 _KNUM=1
_PROTFORM[4]=2
_PROTVAL[2]="_TXT[0],_AXIS1,_OVR[1],_OVR[5],_OVR[17],_TIME"
_PROTVAL[3]=" ,_AXIS2,_OVR[2],_OVR[6],_OVR[18]"
MP_ZAEHLER=MP_ZAEHLER+1 _TXT[0]=<<MP_ZAEHLER
N190 CYCLE977
N210 CYCLE101
N220 Z200
N290 M2
"""


def example_part() -> dict:
    data = scenario(rot=(0.0, 0.0, 0.0))
    data["machine"]["limits"]["Z"] = [-400, 250]
    data["workpiece"]["features"] = [{"type": "block", "size": [200.0, 120.0, 60.0]},
                                     {"type": "spigot", "center": list(SHAFT), "diameter": SHAFT_D, "height": 40.0}]
    return data


@pytest.fixture
def op(client):
    operator = Operator(client, example_part())
    operator.load()
    pose = operator.scen["workpiece"]["pose"]["trans"]
    operator.put_offset("G54", trans=(pose[0], pose[1], TOP_Z - SURFACE_Z))     # WCS Z 79.987 = the top face
    return operator


def run(op: Operator, text: str, name: str = "MESSPROGRAMM_1") -> dict:
    assert op.c.put(f"/api/programs/{name}", json={"text": text}).status_code in (200, 201)
    return op.ok(op.c.post("/api/nc/run", json={"program": name}))


def collapsed(line: str) -> str:
    return re.sub(r"\s+", " ", line)


def test_the_manuals_example_gives_the_manuals_log(op):
    answer = run(op, EXAMPLE)
    assert answer["state"] == "done", answer
    listed = op.ok(op.c.get("/api/protocols"))
    assert [(p["name"], p["program"]) for p in listed] == [("PROTOKOLL_1", "MESSPROGRAMM_1")]
    text = op.c.get("/api/protocols/PROTOKOLL_1").text
    lines = text.rstrip("\n").split("\n")
    assert re.fullmatch(r"Date: \d\d/\d\d/\d\d  Time: \d\d:\d\d:\d\d  Page: 1", lines[0])
    assert lines[1:7] == ["", "Program: MESSPROGRAMM_1", "", "Part no.:   123456789", "Order no.:    6878",
                          "Operator: Tel. 1234"]
    assert lines[7] == lines[10] == "-" * 80
    assert lines[8] == "Measuring  , Axis       , Setpoint   , Actual     , Difference , Time"
    assert lines[9] == "point      ,            , value"
    time = r"\d\d:\d\d:\d\d"
    assert collapsed(lines[11]) == "CYCLE978 , _MVAR , 100"
    assert re.fullmatch(rf"1 , Z , 80\.000 , 79\.987 , -0\.013 , {time}", collapsed(lines[12])), lines[12]
    assert collapsed(lines[13]) == "CYCLE977 , _MVAR , 102"
    assert re.fullmatch(rf"2 , X , 64\.000 , 64\.009 , 0\.009 , {time}", collapsed(lines[14])), lines[14]
    assert collapsed(lines[15]) == " , Y , 38.000 , 37.998 , -0.002"
    assert len(lines) == 16
    # the columns: 12 characters each, joined by " , "
    assert lines[12].startswith("1" + " " * 11 + " , Z" + " " * 11 + " , 80.000")
    # the program screen lists the file, the browser downloads it
    assert "PROTOKOLL_1" in [p["name"] for p in op.ok(op.c.get("/api/programs"))]
    download = op.c.get("/api/protocols/PROTOKOLL_1", params={"download": "true"})
    assert download.headers["content-disposition"] == 'attachment; filename="PROTOKOLL_1.MPF"'


def test_cycle100_deletes_the_old_file_and_a_second_run_writes_it_anew(op):
    run(op, EXAMPLE)
    first = op.c.get("/api/protocols/PROTOKOLL_1").text
    run(op, EXAMPLE)
    second = op.c.get("/api/protocols/PROTOKOLL_1").text
    assert len(second.split("\n")) == len(first.split("\n"))


CYCLE118 = """DEF STRING[12] TEXTVAR
DEF REAL VAR1
VAR1=100/$PI
CYCLE118(VAR1,2,TEXTVAR)
R1=0 R2=0
IF TEXTVAR=="31.83" GOTOF SECOND
M0
SECOND:
R11=0.1/$PI R12=1/$PI R13=10/$PI
CYCLE118(0,_DIGIT,TEXTVAR,3,11)
M30
"""


def test_cycle118_formats_as_the_manuals_two_examples(op):
    assert run(op, CYCLE118, "FORMAT")["state"] == "done"
    values = op.ok(op.c.get("/api/nc/variables", params={"names": "_TXT[0],_TXT[1],_TXT[2]"}))
    assert [values["_TXT[0]"], values["_TXT[1]"], values["_TXT[2]"]] == ["0.032", "0.318", "3.183"]


def test_cycle113_gives_date_and_time_and_cycle105_writes_value_lines(op):
    text = """DEF STRING[10] DAY, CLOCK
CYCLE113(1,DAY)
CYCLE113(2,CLOCK)
_PROTNAME[0]="CHECK" _PROTNAME[1]="MY_PROT" _CBIT[6]=1 _PROTFORM[5]=0
_PROTVAL[0]="Day       ,Time    ,R1"
_PROTVAL[2]="DAY_TEXT,CLOCK_TEXT,R1"
R1=2.5
CYCLE100
_TXT[1]=DAY _TXT[2]=CLOCK _PROTVAL[2]="_TXT[1],_TXT[2],R1"
CYCLE105(1)
CYCLE101
M30
"""
    assert run(op, text, "CHECK")["state"] == "done"
    last = op.c.get("/api/protocols/MY_PROT").text.rstrip("\n").split("\n")[-1]
    day, clock, r1 = (cell.strip() for cell in last.split(";"))
    assert re.fullmatch(r"\d\d/\d\d/\d\d", day) and re.fullmatch(r"\d\d:\d\d:\d\d", clock)
    assert r1 == "2.500"
    assert last.index(";") == len("Day       ") + 1          # the widths of _PROTVAL[0]'s fields


@pytest.mark.parametrize("text, code", [
    ('_PROTNAME[1]=""\nCYCLE100\nM30', 61354),
    ('_PROTNAME[1]="9X"\nCYCLE100\nM30', 61355),
    ("CYCLE105(1)\nM30", 61360),
    ("R1=1\nCYCLE118(0,3,_TXT[0],11,1)\nM30", 61362),
    ('_PROTNAME[1]="AB"\n_PROTVAL[2]="_FOO"\nCYCLE100\nCYCLE105(1)\nM30', 61361),
])
def test_the_manuals_alarms(op, text, code):
    answer = op.ok(op.c.post("/api/nc/run", json={"mda": text}))
    assert answer["state"] == "alarm" and answer["alarm"]["code"] == code, answer

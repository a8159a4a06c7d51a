"""Execution: single block, M0 and resume, NC Stop from another thread, alarms with line and
column, a consistent state after an alarm, the cycle-call hook."""

from __future__ import annotations

import threading

import numpy as np
import pytest
from nc_runtimes import FakeRuntime
from nc_scenes import BALL_R, G54, LEFT_FACE, PRE, scene

from app.nc.errors import NcAlarm, NcRuntimeError
from app.nc.interpreter import CycleContext, Interpreter, NcStateError
from app.nc.nodes import Program
from app.nc.parser import parse_program
from app.nc.variables import Variables
from engine import alarms
from engine.types import MeasuringError

PROGRAM = "N10 G500 G0 X1\nN20 X2\nN30 M0\nN40 X3\n\n; comment\nN50 X4\nN60 M30\nN70 X99"


def xs(rt):
    return [e[1]["X"] for e in rt.moves]


def test_single_block_executes_exactly_one_block():
    rt = FakeRuntime()
    interp = Interpreter(rt)
    interp.load(PROGRAM)
    assert interp.current_block.number == 10 and interp.state == "ready"
    seen = []
    for _ in range(3):
        result = interp.step()
        seen.append((result.state, result.reason, result.block.number, interp.current_block.number))
    assert seen == [("stopped", "single_block", 10, 20), ("stopped", "single_block", 20, 30),
                    ("stopped", "M0", 30, 40)]
    assert xs(rt) == [1.0, 2.0]
    result = interp.step()
    assert (result.block.number, xs(rt)) == (40, [1.0, 2.0, 3.0])
    result = interp.run()
    assert (result.state, result.reason, result.block.number) == ("done", "M30", 60)
    assert xs(rt) == [1.0, 2.0, 3.0, 4.0]            # N70 after M30 never runs
    with pytest.raises(NcStateError):
        interp.run()


def test_m0_stops_and_nc_start_resumes():
    rt = FakeRuntime()
    interp = Interpreter(rt)
    interp.load(PROGRAM)
    result = interp.run()
    assert (result.state, result.reason, result.block.line) == ("stopped", "M0", 3)
    assert interp.state == "stopped" and interp.current_block.number == 40
    assert interp.run().state == "done"
    assert xs(rt) == [1.0, 2.0, 3.0, 4.0]
    assert interp.last_result.to_dict()["block"]["number"] == 60


def test_end_of_program_without_m30_and_an_empty_program():
    interp = Interpreter(FakeRuntime())
    interp.load("G0 X1")
    result = interp.run()
    assert (result.state, result.reason) == ("done", "end")
    interp.load("; nothing\n")
    assert interp.run().state == "done" and interp.current_block is None


class BlockingRuntime(FakeRuntime):
    """A move waits until the test lets it finish: a block is 'executing' meanwhile."""

    def __init__(self):
        super().__init__()
        self.entered = threading.Semaphore(0)
        self.release = threading.Semaphore(0)

    def move(self, target_mcs, feed):
        self.entered.release()
        assert self.release.acquire(timeout=5.0)
        super().move(target_mcs, feed)


def test_request_stop_from_another_thread_stops_between_blocks():
    rt = BlockingRuntime()
    interp = Interpreter(rt)
    interp.load("N10 G500 G0 X1\nN20 X2\nN30 X3\nN40 X4")
    results = []
    worker = threading.Thread(target=lambda: results.append(interp.run()))
    worker.start()
    assert rt.entered.acquire(timeout=5.0)
    assert interp.state == "running" and interp.current_block.number == 10   # observable while it runs
    with pytest.raises(NcStateError):
        interp.run()
    rt.release.release()                       # N10 ends
    assert rt.entered.acquire(timeout=5.0)            # N20 moving
    interp.request_stop()
    rt.release.release()                       # N20 completes; the program stops before N30
    worker.join(5.0)
    (result,) = results
    assert (result.state, result.reason, result.block.number) == ("stopped", "stop_request", 20)
    assert interp.current_block.number == 30 and xs(rt) == [1.0, 2.0]
    worker = threading.Thread(target=lambda: results.append(interp.run()))
    worker.start()
    for _ in range(2):
        assert rt.entered.acquire(timeout=5.0)
        rt.release.release()
    worker.join(5.0)
    assert results[-1].state == "done" and xs(rt) == [1.0, 2.0, 3.0, 4.0]


def test_on_block_sees_every_block_before_it_runs():
    rt = FakeRuntime()
    seen = []
    interp = Interpreter(rt, on_block=lambda ref: seen.append((ref.line, len(rt.moves))))
    interp.load("G500 G0 X1\nX2\nX3")
    interp.run()
    assert seen == [(1, 0), (2, 1), (3, 2)]


# --- alarms: located, and the state stays consistent ------------------------------------------------

def test_alarm_in_a_block_leaves_the_modal_state_and_variables_as_before():
    rt = FakeRuntime()
    ev: dict = {}
    interp = Interpreter(rt, Variables(backings={"_EV": ev}))
    interp.load("N10 G500 G90 G0 X1\nN20 G91 G18 G70 F100 R1=5 _EV[9]=0.004 G1 X10")
    rt.fail["move"] = None
    interp.step()
    rt.fail["move"] = NcRuntimeError("Probe collision", alarms.PROBE_COLLISION)
    result = interp.run()
    assert result.state == "alarm"
    err = result.alarm
    assert (err.line, err.column, err.alarm) == (2, 43, alarms.PROBE_COLLISION)
    assert str(err) == "Probe collision in line 2, column 43"
    assert err.block_text == "N20 G91 G18 G70 F100 R1=5 _EV[9]=0.004 G1 X10"
    m = interp.modal
    assert (m.distance, m.plane, m.units, m.feed, m.motion) == ("G90", "G17", "G71", None, "G0")
    assert interp.variables.get("R", (1,)) == 0.0 and ev == {}          # nothing of the block written
    assert interp.state == "alarm" and interp.current_block.number == 20
    assert interp.status()["alarm"]["code"] == alarms.PROBE_COLLISION.number
    with pytest.raises(NcStateError):
        interp.run()
    interp.reset()
    assert interp.state == "ready" and interp.current_block.number == 10


def test_half_a_g101_is_never_applied():
    rt = FakeRuntime()
    interp = Interpreter(rt)
    interp.load("G500 F100 G100 X5")
    rt.switch = lambda start, end: 0.5
    interp.run()
    interp.load("G101 X1 Y1")
    result = interp.run()
    assert result.alarm.alarm is alarms.NO_MEASURED_VALUE and result.alarm.column == 9
    assert dict(interp.measuring_offsets.included) == {}


def test_a_tool_change_that_happened_stays_when_the_move_of_its_block_fails():
    rt = FakeRuntime(tools={9: {1: 100.0}, 3: {1: 50.0}}, tool=9, edge=1)
    interp = Interpreter(rt)
    interp.load("N10 T3 M6 G91 G0 X5")
    rt.fail["move"] = NcRuntimeError("Software limit switch X", alarms.SOFTWARE_LIMIT)
    result = interp.run()
    assert result.alarm.alarm is alarms.SOFTWARE_LIMIT
    assert (interp.modal.tool, interp.modal.edge) == (3, 1)        # the physical fact
    assert interp.modal.distance == "G90"                           # the program's part is not committed


def test_unknown_tool_is_an_alarm_before_anything_moves():
    rt = FakeRuntime(tools={9: {1: 100.0}}, tool=9, edge=1)
    interp = Interpreter(rt)
    interp.load("G0 X1\nN20 T7 M6 X5")
    result = interp.run()
    assert result.alarm.alarm is alarms.NO_TOOL_FOR_IDENTIFIER and result.alarm.line == 2
    assert len(rt.moves) == 1 and interp.modal.tool == 9
    interp.load("D3")
    assert interp.run().alarm.alarm is alarms.NC_D_NUMBER


def test_alarm_on_the_simulator_has_line_and_column():
    machine, runtime = scene()
    interp = Interpreter(runtime)
    interp.load("N10 G54 G0 Z20\nN20 X100 Y0\nN30 G1 Z-20 F500")        # straight down into the block
    result = interp.run()
    assert result.state == "alarm" and result.alarm.alarm is alarms.PROBE_COLLISION
    assert (result.alarm.line, result.alarm.column) == (3, 8)
    assert "in line 3, column 8" in str(result.alarm)


def test_a_program_given_as_nodes_is_checked_too():
    program: Program = parse_program("G0 X1\nCYCLE977")
    interp = Interpreter(FakeRuntime())
    with pytest.raises(Exception, match="CYCLE977 is not a cycle"):
        interp.load(program)


# --- the cycle-call hook ----------------------------------------------------------------------------

def probing_cycle(ctx: CycleContext) -> None:
    """A test cycle in the style of CYCLE978 (1 point, paraxial surface): probes along the axis
    _MA in direction _MD towards _SETVAL and writes actual value and difference to _OVR[4]/_OVR[16].
    The ball-radius compensation is the nominal one (no calibration): enough for a hook test."""
    v = ctx.variables
    a, o, p = ctx.plane_axes
    axis = (a, o, p)[v.get("_MA") - 1]
    sign = 1.0 if v.get("_MD") == 0 else -1.0
    fa, setval = v.get("_FA"), v.get("_SETVAL")
    radius = 2.0
    i = ("X", "Y", "Z").index(axis)
    start = ctx.position_wcs()
    expected = setval - sign * radius
    start[i] = expected - sign * fa
    ctx.move(start, 1000.0)
    end = start.copy()
    end[i] = expected + sign * fa
    triggered, latched = ctx.measure(end, 300.0)
    if not triggered:
        raise ctx.alarm(alarms.PROBE_NOT_SWITCHED, f"{ctx.name}: probe not switched")
    actual = latched[i] + sign * radius
    v.set("_OVR", actual, (4,))
    v.set("_OVR", actual - setval, (16,))
    v.set("_OVI", 978, (2,))
    ctx.move(start, 1000.0)


def test_cycle_call_with_sw63_parameters_on_the_simulator():
    machine, runtime = scene(pretravel={})
    interp = Interpreter(runtime, cycles={"CYCLE978": probing_cycle})
    interp.load("N10 G54 G17 G0 Z20\nN20 X40 Y0\nN30 Z-10\n"
                "N40 _MVAR=100 _SETVAL=52 _MA=1 _MD=0 _FA=2\nN50 CYCLE978\nN60 R1=_OVR[16]")
    result = interp.run()
    assert result.state == "done", result.alarm
    face_wcs = LEFT_FACE - G54[0]
    assert interp.variables.get("_OVR", (4,)) == pytest.approx(face_wcs, abs=1e-9)
    assert interp.variables.get("R", (1,)) == pytest.approx(face_wcs - 52.0, abs=1e-9)
    assert interp.variables.get("_OVI", (2,)) == 978
    assert interp.variables.get("$AA_MW", ("X",)) == pytest.approx(face_wcs - BALL_R, abs=1e-9)
    assert machine.status().wcs["X"] == pytest.approx(52.0 - BALL_R - 2.0, abs=1e-9)


def test_the_context_gives_state_args_and_helpers():
    seen = {}

    def handler(ctx: CycleContext):
        seen["name"], seen["args"], seen["block"] = ctx.name, ctx.args, ctx.block.number
        seen["plane"], seen["offset"], seen["feed"] = ctx.modal.plane, ctx.modal.offset, ctx.modal.feed
        seen["setval"] = ctx.variables.get("_SETVAL")
        seen["wcs"] = ctx.position_wcs()
        seen["mcs"] = ctx.to_mcs([1.0, 2.0, 3.0])
        seen["axes"] = ctx.plane_axes

    from engine.frames import Frame
    rt = FakeRuntime(offsets={"G54": Frame(coarse=[10.0, 20.0, 30.0])}, tools={9: {1: 100.0}}, tool=9, edge=1,
                     position={"X": 10.0, "Y": 20.0, "Z": 130.0})
    interp = Interpreter(rt, cycles={"CYCLE977": handler, "MYCYC": handler})
    interp.load("N10 G54 G18 F250 _SETVAL=132 CYCLE977\nN20 MYCYC(1, R1+2, \"A\")")
    assert interp.run().state == "done"
    assert (seen["name"], seen["args"], seen["block"]) == ("MYCYC", (1, 2, "A"), 20)
    assert (seen["plane"], seen["offset"], seen["feed"], seen["setval"]) == ("G18", "G54", 250.0, 132.0)
    np.testing.assert_allclose(seen["wcs"], [0.0, -100.0, 100.0])        # G18: length along Y
    assert seen["mcs"] == pytest.approx({"X": 11.0, "Y": 122.0, "Z": 33.0})
    assert seen["axes"] == ("Z", "X", "Y")


@pytest.mark.parametrize("raised, definition", [
    (MeasuringError(alarms.SAFE_AREA, "safe area exceeded"), alarms.SAFE_AREA),
    (NcRuntimeError("Probe collision", alarms.PROBE_COLLISION), alarms.PROBE_COLLISION),
    (ValueError("bug"), alarms.NC_INTERNAL),
])
def test_errors_in_a_cycle_stop_the_program_at_the_call(raised, definition):
    def handler(ctx):
        ctx.variables.set("_OVI", 61303, (9,))          # results written before the alarm stay
        raise raised

    interp = Interpreter(FakeRuntime(), cycles={"CYCLE977": handler})
    interp.load("G0 X0\nN20 _MVAR=1 CYCLE977\nG0 X5")
    result = interp.run()
    assert result.state == "alarm" and result.alarm.alarm is definition
    assert (result.alarm.line, result.alarm.column) == (2, 13)
    assert interp.variables.get("_OVI", (9,)) == 61303
    assert interp.variables.get("_MVAR") == 1             # the block's own words were committed


def test_ctx_alarm_is_located_at_the_call():
    def handler(ctx):
        raise ctx.alarm(alarms.WRONG_VARIANT, f"{ctx.name}: _MVAR {ctx.variables.get('_MVAR')} is not allowed")

    interp = Interpreter(FakeRuntime(), cycles={"CYCLE977": handler})
    interp.load("_MVAR=7\n   CYCLE977")
    err = interp.run().alarm
    assert isinstance(err, NcAlarm) and err.alarm is alarms.WRONG_VARIANT
    assert (err.line, err.column) == (2, 4) and err.block_text == "CYCLE977"


def test_a_cycle_removed_from_the_registry_after_load_is_an_alarm_at_its_block():
    cycles = {"CYCLE977": lambda ctx: None}
    interp = Interpreter(FakeRuntime(), cycles=cycles)
    interp.load("G0 X0\nN20 CYCLE977")
    del cycles["CYCLE977"]
    err = interp.run().alarm
    assert err.alarm is alarms.NC_NAME_UNKNOWN and err.line == 2 and "CYCLE977 is not a cycle" in err.message


def test_old_l97x_calls_use_the_registry():
    called = []
    interp = Interpreter(FakeRuntime(), cycles={"L977": lambda ctx: called.append(ctx.variables.get("R", (30,)))})
    interp.load("R30=1 R42=132\nL977")
    assert interp.run().state == "done" and called == [1.0]


def test_system_variables_read_the_machine():
    from engine.frames import Frame
    rt = FakeRuntime(offsets={"G54": Frame(coarse=[10.0, 0.0, 0.0])}, tools={9: {1: 100.0}}, tool=9, edge=1,
                     position={"X": 15.0, "Y": 2.0, "Z": 150.0})
    interp = Interpreter(rt)
    interp.load("G54\nR1=$AA_IM[X] R2=$AA_IW[X] R3=$AA_IW[Z] R4=$P_TOOLNO R5=$P_TOOL")
    interp.run()
    assert [interp.variables.get("R", (i,)) for i in range(1, 6)] == [15.0, 5.0, 50.0, 9.0, 1.0]


def test_pretravel_is_in_the_latched_values():
    """A sanity check of the scene used above: with pre-travel the latch is behind the contact."""
    machine, runtime = scene()
    interp = Interpreter(runtime)
    interp.load("G54 G0 Z20\nX40 Y0\nZ-10\nMEAS=1 G1 X60 F100")
    interp.run()
    assert interp.variables.get("$AA_MM", ("X",)) == pytest.approx(LEFT_FACE - BALL_R + PRE["X+"], abs=1e-9)


def test_jumps_to_block_numbers_and_labels_both_ways_msg_and_def_arrays():
    import json
    interp = Interpreter(FakeRuntime())
    interp.load("DEF INT NN, CNT[3]=7\nN10 MSG(\"start\")\nN20 NN=NN+1\nN30 IF NN<3 GOTOB N20\n"
                "N40 GOTO ENDE\nN50 R9=1\nENDE: R1=NN R2=CNT[2]\nMSG()\nGOTOF N90\nR8=1\nN90 M30")
    result = interp.run()
    assert result.state == "done"
    v = interp.variables
    assert (v.get("R", (1,)), v.get("R", (2,)), v.get("R", (8,)), v.get("R", (9,))) == (3.0, 7.0, 0.0, 0.0)
    assert interp.message is None
    json.dumps(interp.status())
    json.dumps(result.to_dict())

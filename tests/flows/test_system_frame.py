"""61016 "System frame for cycles missing" (manual ch. 10's alarm table: source "all", "MD 28082:
set MM_SYSTEM_FRAME_MASK, bit 5 = 1"; §9.1.1: bit 0 = 1 and bit 5 = 1 must be set at
commissioning; jog-measuring.md §9.1). A control commissioned without bit 5 refuses every
measurement, in JOG and as a cycle in a program: nothing moves, nothing is written. With the
manual's 21H the same measurement runs."""

from __future__ import annotations

from flowkit import Flow, cal_scenario, make_client, ok


def without_cycle_frame(mask: int = 0x01) -> dict:
    sc = cal_scenario()
    sc["machine"]["machine_data"] = {"28082": mask}
    return sc


def test_a_measurement_in_jog_is_refused_with_61016_and_nothing_moves(tmp_path):
    sc = without_cycle_frame()
    with make_client(tmp_path, sc) as client:
        flow = Flow(client, sc)
        top = flow.part_to_mcs((100.0, 60.0, 0.0))
        flow.travel(top[0], top[1], top[2] + 4.0)
        where = ok(client.get("/api/machine"))["mcs"]
        g54 = ok(client.get("/api/offsets/G54"))
        log = len(ok(client.get("/api/log")))
        session = flow.create("edge.set", {"axis": "Z", "direction": "-", "setpoint": 0.0}, "G54")
        refused = flow.start(session["id"], status=409)
        assert refused["error"]["code"] == "alarm"
        assert refused["error"]["message"].startswith("61016 System frame for cycles missing")
        assert "MD 28082" in refused["error"]["message"] and "bit 5" in refused["error"]["message"]
        assert ok(client.get("/api/machine"))["mcs"] == where
        assert ok(client.get("/api/offsets/G54")) == g54
        assert len(ok(client.get("/api/log"))) == log


def test_a_cycle_in_a_program_stops_with_61016(tmp_path):
    sc = without_cycle_frame(0x00)
    with make_client(tmp_path, sc) as client:
        flow = Flow(client, sc)
        top = flow.part_to_mcs((100.0, 60.0, 0.0))
        flow.travel(top[0], top[1], top[2] + 4.0)
        where = ok(client.get("/api/machine"))["mcs"]
        program = f"_MVAR=0 _SETVAL={top[2]:.4f} _MA=3 _KNUM=0 _FA=6\nCYCLE978"
        refused = ok(client.post("/api/nc/run", json={"mda": program}))
        assert refused["state"] == "alarm" and refused["alarm"]["code"] == 61016
        assert ok(client.get("/api/machine"))["mcs"] == where


def test_with_bit_5_set_the_same_measurement_runs(tmp_path):
    sc = without_cycle_frame(0x21)                  # the manual's commissioning value
    with make_client(tmp_path, sc) as client:
        flow = Flow(client, sc)
        flow.calibrate_radius()
        flow.calibrate_length()
        top = flow.part_to_mcs((100.0, 60.0, 0.0))
        flow.travel(top[0], top[1], top[2] + 4.0)
        session = flow.create("edge.set", {"axis": "Z", "direction": "-", "setpoint": 0.0}, "G54")
        answer = flow.start(session["id"])
        assert abs(answer["result"]["position"]["Z"] - top[2]) < 0.002

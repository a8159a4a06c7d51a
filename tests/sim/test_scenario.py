import json

import pytest

from app.machine.scenario import Scenario, demo_scenario, load_scenario
from app.machine.sim import SimulatedMachine


def test_demo_round_trips_through_json():
    demo = demo_scenario()
    again = load_scenario(json.loads(json.dumps(demo.model_dump(mode="json"))))
    assert again == demo


def test_defaults_of_design_section_4():
    sc = load_scenario({})
    m = sc.machine
    assert (m.rapid, m.latency_s, m.decel, m.kv, m.time_scale) == (10000, 0.004, 1.0, 1.0, 1.0)
    assert sc.probe.nominal_length == sc.probe.length
    ring = load_scenario({"ring_gauge": {"center": [0, 0, 0], "diameter": 25}}).ring_gauge
    assert ring.outer_diameter == 55.0
    assert load_scenario({"tool_probe": {"center": [0, 0, 0], "disc_diameter": 20}}).tool_probe.height == 40


def test_demo_is_sensible():
    demo = demo_scenario()
    kinds = [f.type for f in demo.workpiece.features]
    assert kinds.count("block") == 1 and {"hole", "pocket", "spigot", "boss"} <= set(kinds)
    assert demo.probe.nominal_length != demo.probe.length
    assert all(t.nominal.length is not None for t in demo.tools)
    # the start position is collision-free: nothing within 5 mm of the probe ball
    machine = SimulatedMachine(demo)
    geo = machine.scene_geometry()
    assert machine.scene.sdf(geo["probe"]["tip"]) > demo.probe.ball_diameter / 2 + 5.0


@pytest.mark.parametrize("bad, field", [
    ({"probe": {"ball_diameter": -4}}, "probe.ball_diameter"),
    ({"machine": {"limits": {"X": [10, -10]}}}, "limits.X"),
    ({"machine": {"limits": {"Y": [float("-inf"), 10]}}}, "limits.Y"),
    ({"rotary_axes": {"C": {"limits": [0, float("nan")]}}}, "rotary_axes.C.limits"),
    ({"machine": {"latency_s": "soon"}}, "machine.latency_s"),
    ({"workpiece": {"features": [{"type": "cone"}]}}, "workpiece.features.0"),
    ({"probe": {"pretravel": {"W+": 0.1}}}, "probe.pretravel"),
    ({"probe": {"pretravel_frame": "body"}}, "probe.pretravel_frame"),
    ({"machine": {"spindle_axis": "A"}}, "machine.spindle_axis"),
    ({"workpiece": {"features": [{"type": "prism", "polygon": [[0, 0], [1, 0], [0, 1]]}]}},
     "workpiece.features.0.prism.height"),
    ({"workpiece": {"features": [{"type": "sphere", "center": [0, 0, 0], "diameter": 0}]}},
     "workpiece.features.0.sphere.diameter"),
    ({"tools": [{"t": 9, "length": 50, "radius": 3}]}, "tools"),
    ({"start": {"X": 1e6}}, "start.X"),
    ({"rotary_axes": {"Q": {}}}, "rotary_axes"),
    ({"seeed": 1}, "seeed"),
])
def test_bad_scenarios_name_the_field(bad, field):
    with pytest.raises(ValueError) as err:
        load_scenario(bad)
    assert field in str(err.value)


def test_rotary_axes_join_the_axes():
    sc = load_scenario({"rotary_axes": {"C": {"limits": [-360, 360]}}, "start": {"C": 90}})
    assert isinstance(sc, Scenario) and sc.axes == ("X", "Y", "Z", "C")
    m = SimulatedMachine(sc)
    assert m.status().mcs["C"] == 90.0

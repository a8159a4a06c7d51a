"""Tool measuring on LinuxCNC: the tool probe calibrated with an exact tool, then a cutter's
length, within 2 µm of the truth (the tool probe switches the same probe input, fed from the
scene; the simulator's flow helpers of tests/flows/test_tool_measuring_truth.py)."""

from __future__ import annotations

from conftest import brisk, linuxcnc_client
from test_tool_measuring_truth import CUTTER_T, SCENARIO, TOL, TRUE, Api


def test_tool_length_within_2_um_of_truth(tmp_path):
    with linuxcnc_client(tmp_path, brisk(SCENARIO)) as client:
        api = Api(client)
        api.calibrate("length")
        nominal = api.tool(CUTTER_T)
        assert abs(nominal["length"] - TRUE[CUTTER_T]["length"]) > 0.02
        answer = api.length(CUTTER_T)
        tool = api.tool(CUTTER_T)
        error = tool["length"] - TRUE[CUTTER_T]["length"]
        print(f"\nLinuxCNC tool length T{CUTTER_T}: error {error * 1000:+.3f} µm")
        assert abs(error) <= TOL
        assert answer["result"]["length"] == tool["length"]
        machine = client.app.state.services.machine.machine
        assert machine.nc_tool(CUTTER_T)["length"] == tool["length"]     # LinuxCNC's tool table holds it
        assert client.get("/api/machine").json()["tool_length"] == tool["length"]

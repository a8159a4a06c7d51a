"""One truth for frames (issue 34 §5, design.md §10.7): a frame LinuxCNC cannot hold (a rotation
about X) that is in the database (stored before, or by another HMI on the plant's database) is
refused on activation with the NC's alarm 61321, never shown as active; a frame it can hold is
activated in LinuxCNC too."""

from __future__ import annotations

import pytest
from conftest import linuxcnc_client
from flowkit import cal_scenario


def test_a_frame_linuxcnc_cannot_hold_is_refused_on_activation(tmp_path):
    with linuxcnc_client(tmp_path, cal_scenario()) as client:
        db = client.app.state.services.db
        with db.unit() as unit:
            unit.put_offset("G54", {"trans": {"X": 10.0}, "fine": {}, "rot": {"X": 0.5}}, source="test")
        answer = client.post("/api/machine/activate", json={"offset": "G54"})
        assert answer.status_code == 409 and "61321" in answer.text
        state = client.get("/api/machine").json()
        assert state["active_offset"] == "G500"
        assert [a["code"] for a in state["alarms"]] == [61321]
        machine = client.app.state.services.machine.machine
        assert machine.nc_offset("G54")["trans"] == {"X": 0.0, "Y": 0.0, "Z": 0.0}      # LinuxCNC's G54 untouched
        assert client.post("/api/machine/reset").status_code == 200
        held = {"trans": {"X": 5.0, "Y": -2.0, "Z": 1.0}, "fine": {}, "rot": {"Z": 1.5}}
        assert client.put("/api/offsets/G55", json=held).status_code == 200
        answer = client.post("/api/machine/activate", json={"offset": "G55"})
        assert answer.status_code == 200 and answer.json()["active_offset"] == "G55"
        lc = machine.linuxcnc_stat()
        assert lc.g5x_index == 2 and lc.rotation_xy == pytest.approx(1.5, abs=1e-9)

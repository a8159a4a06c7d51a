"""The control's kinematic data are machine data (design.md §10.6): writing them, directly or by
``kinematics.measure`` in ``optimise`` mode, needs the ``settings`` level (3); a lower level gets
403 ``access_level`` and nothing changes; measuring in ``check`` mode needs only ``measure``."""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "flows"))
from test_kinematics_truth import SPHERE_D, TRUE_HEAD, kin_scenario, sphere_mcs  # noqa: E402

LINE = {"A": {"point": [0.0, 0.01, 0.0], "direction": [1.0, 0.0, 0.0]}}


def test_writing_kinematics_needs_the_settings_level(signin_client, tokens):
    client = signin_client
    sc = kin_scenario(sigma=0.0, true=TRUE_HEAD)
    assert client.post("/api/sim/scenario", json=sc, headers=tokens[1]).status_code == 200
    nominal = client.get("/api/kinematics", headers=tokens[7]).json()

    r = client.put("/api/kinematics", json=LINE, headers=tokens[5])
    assert r.status_code == 403 and r.json()["error"]["code"] == "access_level"
    assert client.get("/api/kinematics", headers=tokens[7]).json() == nominal

    params = {"sphere": {"center": [float(v) for v in sphere_mcs(sc)], "diameter": SPHERE_D}, "axis": "A",
              "positions": [-45, 0, 45]}
    for mode, level, status in (("optimise", 5, 403), ("check", 7, 200), ("optimise", 3, 200)):
        session = client.post("/api/measure", json={"task": "kinematics.measure", "params": {**params, "mode": mode}},
                              headers=tokens[level]).json()
        for _ in session["points"]:
            assert client.post(f"/api/measure/{session['id']}/start", json={}, headers=tokens[level]).status_code == 200
        r = client.post(f"/api/measure/{session['id']}/calculate", json={}, headers=tokens[level])
        assert r.status_code == status, (mode, level, r.text)
        stored = client.get("/api/kinematics", headers=tokens[7]).json()
        changed = stored["A"]["point"] != nominal["A"]["point"]
        assert changed == (mode == "optimise" and status == 200)
        client.delete(f"/api/measure/{session['id']}", headers=tokens[level])

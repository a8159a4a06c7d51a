"""The machine a manual listing runs on: a scenario built so that the printed positions fit.

The printed G54 is where the listing needs it: ``frame="block"`` puts the block's top face at
Z20 with its front-left corner at X−100 Y0 (the printed X100 Y80 lies on the top face, the
manual's "surface Z = 20"); ``frame="ring"`` puts the centre of a ring gauge of the printed
Ø110.246 at X100 Y80 with its bore reaching from Z30 down to Z0 (the printed calibration height
Z10 lies inside). Everything is read back through the JSON API (design.md §4).
"""

from __future__ import annotations

import copy

PROBE_LENGTH = 100.0
G54 = {"block": (300.0, 100.0, -140.0),     # WCS origin in MCS: block top (MCS −120) = Z20
       "ring": (550.0, 270.0, -180.0)}      # ring top centre (MCS 650, 350, −150) = X100 Y80 Z30
TOP_Z = -120.0
RING_TOP = (650.0, 350.0, -150.0)
RING_D = 110.246


def scenario(*, probe_t: int = 9, pretravel: dict | None = None, eccentricity=(0.0, 0.0),
             part: dict | None = None) -> dict:
    """``part``: the workpiece ``{"origin": G54 coordinates of the part origin (top-front-left
    corner), "size": block, "features": [...]}``; default the block for the surface listings."""
    probe = {"t": probe_t, "ball_diameter": 4.0, "length": PROBE_LENGTH, "max_deflection": 5.0,
             "eccentricity": list(eccentricity), "noise_sigma": 0.0,
             "nominal": {"length": PROBE_LENGTH + 0.2, "ball_diameter": 4.0}}
    if pretravel:
        probe["pretravel"] = dict(pretravel)
    return copy.deepcopy({
        "seed": 5,
        "machine": {"limits": {"X": [-300, 900], "Y": [-200, 600], "Z": [-400, 300]}, "rapid": 10000,
                    "latency_s": 0.0, "time_scale": 0},
        "probe": probe,
        "workpiece": _workpiece(part),
        "ring_gauge": {"center": list(RING_TOP), "diameter": RING_D, "height": 30},
        "tools": [{"t": 1, "type": 120, "length": 85.0, "radius": 5.0}],
        "start": {"X": 0.0, "Y": 0.0, "Z": 250.0},
    })


def _workpiece(part: dict | None) -> dict:
    if part is None:
        return {"pose": {"trans": [G54["block"][0] - 100.0, G54["block"][1], TOP_Z], "rot": [0.0, 0.0, 0.0]},
                "features": [{"type": "block", "size": [300, 150, 60]}]}
    origin = [g + o for g, o in zip(G54["block"], part["origin"], strict=True)]
    return {"pose": {"trans": origin, "rot": [0.0, 0.0, 0.0]},
            "features": [{"type": "block", "size": list(part["size"])}, *part.get("features", [])]}


class Machine:
    """The simulated machine with the listing's set-up, driven through the API."""

    def __init__(self, client, frame: str = "block", **scenario_kw):
        self.c = client
        self.frame = frame
        self.kw = scenario_kw
        self.load()

    def ok(self, response, status: int = 200):
        assert response.status_code == status, response.text
        return response.json()

    def load(self, **changes) -> None:
        self.kw = {**self.kw, **changes}
        self.scen = scenario(**self.kw)
        self.ok(self.c.post("/api/sim/scenario", json={**self.scen, "reset_data": True}))
        self.put_offset("G54", G54[self.frame])

    def put_offset(self, name: str, trans) -> None:
        self.ok(self.c.put(f"/api/offsets/{name}", json={
            "trans": dict(zip("XYZ", map(float, trans), strict=True)), "rot": {"X": 0.0, "Y": 0.0, "Z": 0.0}}))

    def mda(self, text: str) -> dict:
        return self.ok(self.c.post("/api/nc/run", json={"mda": text}))

    def run(self, listing, replace: dict[str, str] | None = None) -> dict:
        text = listing.text
        for old, new in (replace or {}).items():
            assert old in text, old
            text = text.replace(old, new)
        return self.mda(text)

    def probe(self, n: int) -> dict:
        return self.ok(self.c.get(f"/api/probes/{n}"))

    def put_probe(self, n: int, **fields) -> None:
        self.ok(self.c.put(f"/api/probes/{n}", json={**self.probe(n), **fields}))

    def tool(self, t: int) -> dict:
        return self.ok(self.c.get(f"/api/tools/{t}"))

    def ovr(self) -> list[float]:
        return self.ok(self.c.get("/api/nc/variables", params={"names": "_OVR"}))["_OVR"]

    def ovi(self) -> list[int]:
        return self.ok(self.c.get("/api/nc/variables", params={"names": "_OVI"}))["_OVI"]

    def offset(self, name: str = "G54") -> dict:
        return self.ok(self.c.get(f"/api/offsets/{name}"))

    def wcs(self) -> dict:
        return self.ok(self.c.get("/api/machine"))["wcs"]

    def operator_positions_ball(self, x: float = 100.0, y: float = 80.0, z: float = 40.0) -> None:
        """The operator loads the probe and jogs its (nominal) ball centre to G54 x, y, z."""
        self.ok(self.c.post("/api/machine/tool", json={"tool": self.scen["probe"]["t"]}))
        self.ok(self.c.post("/api/machine/activate", json={"offset": "G54"}))
        self.ok(self.c.post("/api/machine/goto", json={"X": x, "Y": y, "Z": z, "coords": "WCS"}))

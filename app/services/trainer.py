"""What the machine views may show, and the trainer's set-up error (issue 17 item 10).

With the setting ``trainer_hide_part`` the views get no truth of the part: the workpiece is left
out (the fixtures stay: the ring gauge and the tool probe are the trainee's known equipment) and
the probe is drawn where the NC puts it (axes − the tool data's length), not at the true ball
centre. The set-up error is the simulator's answer (app/machine/sim_trainer.py).
"""

from __future__ import annotations

from app.errors import ConflictError, InvalidInput, NotFoundError
from app.machine.protocol import MachineAlarm, SimulatorControl
from app.machine.scenario import Scenario

from .machine_service import MachineService

FIXTURES = frozenset({"ring_bore", "ring_outer", "tool_probe"})


def nc_tip(status: dict) -> list[float]:
    """The tool reference as the NC computes it: axes + head shift − L·tool axis (what the position
    display shows; the head shift of the NC's kinematic data, design.md §10.6)."""
    mcs, length = status["mcs"], float(status.get("tool_length") or 0.0)
    axis = status.get("tool_axis") or (0.0, 0.0, 1.0)
    shift = status.get("head_shift") or (0.0, 0.0, 0.0)
    return [float(mcs[a]) + float(shift[i]) - length * float(axis[i]) for i, a in enumerate("XYZ")]


def visible_scene(services, hide_part: bool | None = None) -> dict:
    """The scene of the machine views: the truth, or in trainer mode only the fixtures and the
    NC's probe. ``hidden`` says which."""
    machine: MachineService = services.machine
    scene = machine.scene_geometry()
    if hide_part is None:
        hide_part = bool(services.settings.get().trainer_hide_part)
    if not hide_part:
        return {**scene, "hidden": False}
    if scene.get("kind") == "lathe":       # the chuck, grooves and tool probe stay; the clamped part goes
        return {**scene, "part": [], "hidden": True}
    status = machine.status()
    probe = scene.get("probe") or {}
    scenario = machine.scenario
    if probe.get("is_probe") and isinstance(scenario, Scenario):          # a milling machine's (lathe above)
        diameter = float(scenario.probe.nominal_ball_diameter)      # what the operator typed in
    else:
        diameter = 2.0 * _tool_radius(services, status.get("tool"))
    return {"block": None, "prism": None, "rects": [], "spheres": [],
            "circles": [c for c in scene.get("circles", []) if c["kind"] in FIXTURES],
            "probe": {"tip": nc_tip(status), "diameter": diameter, "is_probe": bool(probe.get("is_probe")),
                      "tool_radius": diameter / 2.0 if not probe.get("is_probe") else 0.0,
                      "axis": [float(v) for v in status.get("tool_axis") or (0.0, 0.0, 1.0)]},
            "hidden": True}


def _tool_radius(services, t) -> float:
    if t is None:
        return 0.0
    try:
        row = services.tools.get(t)
    except (NotFoundError, InvalidInput):   # no tool data: drawn as a point
        return 0.0
    return float(row.get("radius") or 0.0)


def setup_error(services, offset: str | None) -> dict:
    """The simulator's error of ``offset`` (default: the active WO) against the hidden part."""
    machine: MachineService = services.machine
    simulator = machine.machine
    answer = getattr(simulator, "setup_error", None)
    if not isinstance(simulator, SimulatorControl) or answer is None:
        raise ConflictError("the set-up error needs the simulator: a real machine does not know the part",
                            code="not_simulated")
    name = (offset or machine.active_offset or "").strip().upper()
    if name == "G500" or not name:
        raise InvalidInput("offset: no zero offset is active (G500); choose one such as G54", field="offset")
    if name not in services.offsets.names():
        raise InvalidInput(f"offset: there is no zero offset {name}", field="offset")
    try:
        return answer(name)
    except MachineAlarm as exc:
        raise ConflictError(exc.alarm.text, code="alarm") from None
    except ValueError as exc:
        raise InvalidInput(str(exc), field="offset") from None

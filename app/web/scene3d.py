"""The 3D machine view's data (static/view3d.js draws it): everything in MCS, mm.

- ``solids``: the true part and the fixtures (``app.services.trainer.visible_scene``: in trainer
  mode only the fixtures);
- ``probe``: where the NC puts the tool reference (the live position comes from ``/api/machine``,
  the view adds ``probe.offset`` = true ball centre − NC position, zero in trainer mode);
- ``wcs``: the active zero offset as a coordinate cross (where the HMI puts the part's zero);
- ``plan``: the probing path of the open measurement's next point from where the probe stands
  (before NC Start), as ``task_svg`` draws it in 2D;
- ``touches``: the latched ball centres of the open measurement and of the last log entries;
- ``measured``: what those log entries found (circles, rectangles, corner lines, edge faces): the
  part as measured.

A lathe (``kind: "lathe"``, ``build_lathe``) has the same keys with its own ``solids``: the
turned part as bodies of revolution about the spindle axis (MCS X = radius, Z along the
spindle; the profile's cylinders and bores, eccentric by the spindle angle's e_X), the chuck,
the reference grooves' rings and the tool probe's cube; ``probe`` adds F (the turret reference)
and the tool lengths L1/L2 (the live NC tip is F − (L1, 0, L2)); ``measured`` holds the
diameters (circles about the axis) and faces the 1- and 2-point measurements found.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np

from app.services import trainer
from app.services.measuring import MeasuringEnv
from app.workflow import guard, planning
from app.workflow.executor import StepExecutor
from app.workflow.tasks import LATHE_SPECS, TASKS, Category
from engine.frames import Frame, chain_of, is_basic
from engine.plan import ideal_path
from engine.planes import Plane
from engine.types import MoveStep, ProbeStep

from .failsafe import EXPECTED, PictureFailed, drawn
from .lathe_screens import next_path_steps

LOG_ENTRIES = 3          # the last measurements drawn as touches and results
AXES = ("X", "Y", "Z")


def _vec(values) -> list[float]:
    return [round(float(v), 4) for v in values]


def _xyz(point: dict, fill: float = 0.0) -> np.ndarray:
    return np.array([float(point.get(a, fill)) for a in AXES])


def build(services) -> dict:
    machine = services.machine
    gud = services.settings.get()
    hide = bool(gud.trainer_hide_part)
    scene = trainer.visible_scene(services, hide)
    status = machine.status()
    if scene.get("kind") == "lathe":
        return build_lathe(services, scene, status, hide)
    nc = trainer.nc_tip(status)
    probe = scene.get("probe") or {}
    offset = np.asarray(probe.get("tip", nc), dtype=float) - np.asarray(nc)
    limits = {a: list(v) for a, v in machine.limits().items() if a in AXES}
    session = services.workflow.session if services.workflow is not None else None
    plane = machine.plane()
    return {
        "kind": "mill",
        "hidden": hide,
        "limits": limits,
        "solids": {k: scene.get(k) for k in ("block", "prism", "circles", "rects", "spheres")},
        "probe": {"tip": _vec(nc), "offset": _vec(offset), "diameter": float(probe.get("diameter", 0.0)),
                  "is_probe": bool(probe.get("is_probe")), "axis": _vec(status.get("tool_axis") or (0, 0, 1)),
                  "tool_length": float(status.get("tool_length") or 0.0)},
        "wcs": _wcs(machine),
        "plan": _plan(services, session),
        "touches": _session_touches(session) + _log_touches(services),
        "measured": _measured(services, plane),
    }


def _wcs(machine) -> dict | None:
    name = machine.active_offset
    if not name or name == "G500":
        return None
    frame = machine.chain.wcs2bcs
    return {"name": name, "origin": _vec(frame.translation), "axes": [_vec(c) for c in frame.rotation.T]}


# --- the open measurement ----------------------------------------------------------------------

def _plan(services, session) -> dict | None:
    """The next point's path from the probe's position (ideal latches: ``engine.plan.ideal_path``)."""
    if session is None or session.running:
        return None
    n = session.next_point()
    spec = TASKS.get(session.task)
    if n is None or spec is None:
        return None
    if spec.name in LATHE_SPECS:
        return _lathe_plan(services, session, spec, n)

    def plan():
        ctx = MeasuringEnv(services.db, services.machine, services.settings).measuring_context()
        wcs2bcs = ctx.chain().wcs2bcs
        executor = StepExecutor(services.machine.machine, wcs2bcs, ctx.tool_length, ctx.plane.infeed_unit)
        start = np.asarray(executor.current(spec.coords))
        return ctx, wcs2bcs, start, ideal_path(spec.program(session.params, n, start, planning.context_from(ctx)), start)

    try:        # on a domain error the measuring screen shows why NC Start refuses
        planned = drawn("the 3D view's planned path", plan, None)
    except PictureFailed:      # a bug, logged: the view goes on without the path
        return None
    if planned is None:
        return None
    ctx, wcs2bcs, start, steps = planned
    to_mcs = wcs2bcs.child2parent if spec.coords == "WCS" else (lambda p: np.asarray(p, dtype=float))
    if guard.guarded(spec) and spec.coords == "WCS":
        try:       # the start guard's path and verdicts (issue 24 §1): the refused segment is marked
            report, _coords = guard.check_point(services.machine.machine, spec, session.params, n, ctx)
        except EXPECTED:
            report = None
        if report is not None:
            return {"task": session.task, "point": n, "refused_step": getattr(report.refusal, "index", None),
                    "segments": [{"kind": seg.kind, "verdict": seg.verdict, "from": _vec(to_mcs(seg.start)),
                                  "to": _vec(to_mcs(seg.where if seg.kind == "probe" and seg.where is not None
                                                    else seg.end))} for seg in report.segments]}
    segments, pos = [], start
    for step in steps:
        if isinstance(step, MoveStep):
            target = np.asarray(step.target, dtype=float)
            segments.append({"kind": "move", "from": _vec(to_mcs(pos)), "to": _vec(to_mcs(target))})
            pos = target
        elif isinstance(step, ProbeStep):
            d = np.asarray(step.direction, dtype=float)
            travel = step.expected if step.expected is not None else step.distance / 2.0
            end = pos + travel * d
            segments.append({"kind": "probe", "from": _vec(to_mcs(pos)), "to": _vec(to_mcs(end))})
            pos = end
    return {"task": session.task, "point": n, "segments": segments}


def _session_touches(session) -> list[dict]:
    if session is None:
        return []
    spec = TASKS.get(session.task)
    out = []
    for slot in session.slots:
        if not slot.stored or slot.context is None:
            continue
        wcs2bcs = slot.context.chain().wcs2bcs
        for latch in slot.raw:
            at = latch.get("tip_mcs")
            if at is None and latch.get("rec") is not None:
                rec = np.asarray(latch["rec"], dtype=float)
                at = wcs2bcs.child2parent(rec) if spec is None or spec.coords == "WCS" else rec
            if latch.get("triggered") and at is not None:
                out.append({"at": _vec(at), "label": f"P{slot.n}", "source": "session"})
    return out


# --- the log: the part as measured -------------------------------------------------------------

def _recent(services) -> list[dict]:
    try:
        return [e for e in services.log.list(limit=LOG_ENTRIES) if e.get("status") == "ok"]
    except EXPECTED:
        return []


def _log_touches(services) -> list[dict]:
    out = []
    for entry in _recent(services):
        for label, latches in (entry.get("raw") or {}).items():
            for latch in latches or []:
                if latch.get("triggered") and latch.get("tip_mcs"):
                    out.append({"at": _vec(latch["tip_mcs"]), "label": label, "source": "log",
                                "log_id": entry["id"], "task": entry["task"]})
    return out


def _entry_frame(entry: dict, frames: dict[str, Frame]) -> Frame | None:
    """WCS -> BCS while the entry was measured: today's frames, with the corrected one as it was
    before the correction (its ``before``), so the results land where they were measured."""
    task = entry.get("task")
    spec = TASKS.get(task) if isinstance(task, str) else None
    if spec is None:
        return None
    if spec.coords != "WCS":
        return Frame.identity()
    wo = entry.get("measuring_wo") or "G500"
    corr = entry.get("correction") or {}
    target = corr.get("target")
    if isinstance(target, str) and corr.get("before") and (target == wo or is_basic(target)):
        try:
            frames = {**frames, target: Frame.from_api(corr["before"])}
        except (ValueError, KeyError, TypeError):     # an entry older than today's frame format
            return None
    try:
        return chain_of(frames, wo).wcs2bcs
    except (ValueError, KeyError):                    # its WO no longer exists
        return None


def _framed_entries(services) -> Iterator[tuple[dict, Frame]]:
    """The recent measurements, each with its frame (WCS -> BCS) as it was measured."""
    try:
        frames = services.machine.stored_frames()
    except EXPECTED:
        return
    for entry in _recent(services):
        frame = _entry_frame(entry, frames)
        if frame is not None:
            yield entry, frame


def _touch_tips(entry: dict) -> list:
    """The entry's triggered touches, the ball centre in MCS each."""
    return [latch["tip_mcs"] for latches in (entry.get("raw") or {}).values() for latch in latches or []
            if latch.get("triggered") and latch.get("tip_mcs")]


def _measured(services, plane: Plane) -> list[dict]:
    out = []
    for entry, frame in _framed_entries(services):
        result = entry.get("result") or {}
        if not isinstance(result, dict):
            continue
        out += [{**shape, "log_id": entry["id"], "task": entry["task"]}
                for shape in _shapes(result, frame, plane, _touch_height(entry, frame, plane))]
    return out


def _touch_height(entry: dict, frame: Frame, plane: Plane) -> float | None:
    """The mean infeed coordinate (WCS of the measurement) of the entry's touches: where a result
    without points (a hole's centre and diameter) is drawn."""
    tips = _touch_tips(entry)
    if not tips:
        return None
    mean = frame.parent2child(np.mean(np.asarray(tips, dtype=float), axis=0))
    return float(mean[AXES.index(plane.infeed)])


def _feature_shapes(r: dict, points: list[dict], frame: Frame, at, along, normal: list[float]) -> list[dict]:
    """The one feature of a result: a corner, a circle, a rectangle or the faces of a position."""
    centre = r.get("center")
    if isinstance(r.get("corner"), dict):
        angle = float(r.get("angle", 0.0))
        second = float(r["angle_2"]) if "angle_2" in r else angle + 90.0
        return [{"kind": "corner", "at": at(r["corner"]), "dirs": [along(angle), along(second)]}]
    if isinstance(centre, dict) and isinstance(r.get("diameter"), int | float):
        return [{"kind": "circle", "at": at(centre), "normal": normal, "diameter": float(r["diameter"])}]
    if isinstance(centre, dict) and isinstance(r.get("length"), int | float) and isinstance(r.get("width"), int | float):
        return [{"kind": "rect", "at": at(centre), "normal": normal, "dirs": [along(0.0), along(90.0)],
                 "size": [float(r["length"]), float(r["width"])]}]
    if isinstance(r.get("position"), dict) and points:
        return [{"kind": "face", "at": at(points[0]),
                 "normal": _vec(frame.dir_child2parent(np.eye(3)[AXES.index(axis)]))}
                for axis in r["position"] if axis in AXES]
    return []


def _shapes(r: dict, frame: Frame, plane: Plane, touch_height: float | None = None) -> list[dict]:
    """The result of one entry as 3D shapes (design.md §4 result keys, WCS of the measurement)."""
    points = [p for p in r.get("points") or [] if isinstance(p, dict)]
    if points:
        height = float(np.mean([p.get(plane.infeed, 0.0) for p in points]))
    else:
        height = touch_height if touch_height is not None else 0.0
    normal = _vec(frame.dir_child2parent(plane.infeed_unit))

    def at(p: dict) -> list[float]:
        q = _xyz({plane.infeed: height, **p})
        return _vec(frame.child2parent(q))

    def along(deg: float) -> list[float]:
        c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
        return _vec(frame.dir_child2parent(c * plane.unit(plane.first) + s * plane.unit(plane.second)))

    shapes: list[dict] = [{"kind": "point", "at": at(p)} for p in points]
    shapes += _feature_shapes(r, points, frame, at, along, normal)
    if isinstance(r.get("p1"), dict) and isinstance(r.get("p2"), dict):
        shapes.append({"kind": "line", "from": at(r["p1"]), "to": at(r["p2"])})
    return shapes


# --- the lathe ---------------------------------------------------------------------------------

CHUCK_LENGTH = 40.0      # mm below the chuck face drawn (the 2D view draws the same)
CHUCK_OVERSIZE = 25.0    # the chuck's radius beyond the part's largest


def build_lathe(services, scene: dict, status: dict, hide: bool) -> dict:
    """The lathe's 3D data (MCS, X radius): see the module's docstring."""
    machine = services.machine
    lengths = status.get("tool_lengths") or {}
    l1, l2 = float(lengths.get("L1") or 0.0), float(lengths.get("L2") or 0.0)
    mcs = status["mcs"]
    nc = [float(mcs["X"]) - l1, 0.0, float(mcs["Z"]) - l2]
    probe = scene.get("probe") or {}
    tip = probe.get("tip") or nc
    part = scene.get("part") or []
    r_max = max([p["diameter"] / 2 + abs(p["axis_x"]) for p in part] or [20.0])
    chuck = scene.get("chuck_face_z")
    session = services.workflow.session if services.workflow is not None else None
    return {
        "kind": "lathe",
        "hidden": hide,
        "limits": {a: list(v) for a, v in machine.limits().items() if a in ("X", "Z")},
        "solids": {
            "part": [{"type": p["type"], "z": _vec(p["z"]), "diameter": float(p["diameter"]),
                      "axis_x": float(p["axis_x"])} for p in part],
            "chuck": None if chuck is None else {"face_z": float(chuck), "length": CHUCK_LENGTH,
                                                 "diameter": 2.0 * (r_max + CHUCK_OVERSIZE)},
            "grooves": [{"number": g["number"], "rings": [_vec(r) for r in g["rings"]]}
                        for g in scene.get("grooves") or []],
            "tool_probe": scene.get("tool_probe"),
        },
        "spindle_angle": scene.get("spindle_angle"),
        "probe": {"tip": _vec(nc), "offset": _vec(np.asarray(tip, dtype=float) - np.asarray(nc)),
                  "f": _vec(probe.get("f") or [mcs["X"], 0.0, mcs["Z"]]), "lengths": [l1, l2],
                  "diameter": float(probe.get("diameter") or 0.0), "is_probe": bool(probe.get("is_probe")),
                  "sl": probe.get("sl")},
        "wcs": _wcs(machine),
        "plan": _plan(services, session),
        "touches": _session_touches(session) + _log_touches(services),
        "measured": _lathe_measured(services),
    }


def _lathe_plan(services, session, spec, n: int) -> dict | None:
    """The lathe task's next path as its screen draws it (``lathe_screens.next_path_steps``)."""
    def plan():
        ctx = MeasuringEnv(services.db, services.machine, services.settings).measuring_context()
        return next_path_steps(services.machine, ctx, spec, session.params)

    try:
        steps = drawn("the 3D view's planned lathe path", plan, None)
    except PictureFailed:
        return None
    if not steps:
        return None
    segments = [{"kind": "probe" if kind == "probe" else "move", "from": _vec(a), "to": _vec(b)}
                for (_k, a), (kind, b) in zip(steps, steps[1:], strict=False)]
    return {"task": session.task, "point": n, "segments": segments}


def _lathe_measured(services) -> list[dict]:
    """The diameters (circles about the spindle axis) and faces (planes normal to Z) that the
    last 1- and 2-point measurements found, where they were measured."""
    out = []
    for entry, frame in _framed_entries(services):
        spec = LATHE_SPECS.get(str(entry.get("task")))      # the lathe's 1- and 2-point measurements
        if spec is None or spec.category != Category.WORKPIECE:
            continue
        result, params = entry.get("result") or {}, entry.get("params") or {}
        actual = result.get("diameter", result.get("actual"))
        tips = _touch_tips(entry)
        if not tips or not isinstance(actual, int | float):
            continue
        touch = frame.parent2child(np.mean(np.asarray(tips, dtype=float), axis=0))
        tag = {"log_id": entry["id"], "task": entry["task"]}
        if params.get("axis") == "X":        # a diameter: the circle about the axis at the touches' Z
            centre = frame.child2parent(np.array([0.0, 0.0, touch[2]]))
            out.append({"kind": "circle", "at": _vec(centre), "normal": _vec(frame.dir_child2parent(np.eye(3)[2])),
                        "diameter": float(actual), **tag})
        elif params.get("axis") == "Z":      # a face at the measured Z
            at = frame.child2parent(np.array([touch[0], 0.0, float(actual)]))
            out.append({"kind": "face", "at": _vec(at), "normal": _vec(frame.dir_child2parent(np.eye(3)[2])), **tag})
    return out

"""Finishers of the workpiece probe calibration: ``probe.length`` and ``probe.radius``.

Spec: spec/jog-measuring.md §5.2/jog-measuring §5.3, measuring-math §7.2/measuring-math §7.3/measuring-math §7.5; math in engine.calibration.
The finisher writes the probe record ``_WP[k]`` (``app.records.ProbeData``) and, for
length calibration, the probe's tool length L1 (the machine gets it via refresh_tool_offset).
Every record remembers how it was calibrated: measuring feed and feed override (the measuring
tasks warn when the override differs, jog-measuring §5.1), time, gauge (ring diameter or surface
height and the WO it refers to), plane, and the tool number of the probe it belongs to (the
active record follows the tool in the spindle, app.services.measuring).
"""

from __future__ import annotations

from datetime import UTC, datetime

from app.records import ProbeData
from app.workflow.context import MeasuringContext
from app.workflow.session import MeasureSession
from engine import alarms
from engine.calibration import calibrate_bore, calibrate_surface, evaluate_probe_task, probe_values
from engine.compensation import skew_in_wcs
from engine.types import MeasuringError, ProbeRecord

# the ring passes could not tell whether the pre-travel turns with the spindle (engine.calibration)
UNDECIDED_FRAME = {
    "probe": "The ring passes cannot tell whether the pre-travel turns with the spindle: "
             "calibrated as turning with it",
    "machine": "The ring passes cannot tell whether the pre-travel turns with the spindle: "
               "calibrated as fixed to the machine axes",
}


def _probe_of(ctx: MeasuringContext) -> ProbeRecord:
    if ctx.probe is None or ctx.tool is None:
        raise MeasuringError(alarms.PROBE_TYPE, "No workpiece probe (type 710) in the spindle: load the probe")
    return ctx.probe


def _record(ctx: MeasuringContext, probe: ProbeRecord, extra: dict) -> tuple[int, dict]:
    """The stored record ``_WP[k]`` with the calibration results merged in (ProbeData keys)."""
    n = int(ctx.extra.get("probe_number") or probe.number)
    stored = dict(ctx.probe_data or {})
    record = {
        **stored,
        "number": n,
        "ball_diameter": _nominal_ball(ctx, probe),
        "effective_diameter": float(probe.effective_diameter),
        "trigger": {k: float(v) for k, v in probe.trigger.items()},
        "skew": [float(probe.skew[0]), float(probe.skew[1])],
        "length_to_tip": bool(probe.length_to_tip),
        "calibrated_radius": bool(probe.calibrated_radius),
        "calibrated_length": bool(probe.calibrated_length),
        "calibrated_plane": ctx.plane.name,
        "calibration_feed": float(ctx.settings.measuring_feed),
        "calibration_override": float(ctx.feed_override),
        "calibrated_at": datetime.now(UTC).isoformat(timespec="seconds"),
        "tool": int(ctx.tool["t"]) if ctx.tool else stored.get("tool"),
        **extra,
    }
    return n, ProbeData.model_validate(record).model_dump(mode="json")


def _nominal_ball(ctx: MeasuringContext, probe: ProbeRecord) -> float:
    """The ball diameter of the tool data (what the operator entered); ``probe.ball_diameter`` is
    the measured one once a ring calibration measured it (app.services.measuring)."""
    radius = (ctx.tool or {}).get("radius")
    return 2.0 * float(radius) if radius else float((ctx.probe_data or {}).get("ball_diameter") or probe.ball_diameter)


def surface_height(params: dict, infeed: str) -> float:
    """The calibration surface on the infeed axis: validate_params gives ``{axis: value}``."""
    value = params.get("setpoint", 0.0)
    return float(value.get(infeed, 0.0) if isinstance(value, dict) else value)


def _first_harmonic(point) -> str:
    """Off-centre chords observe the pre-travel's first harmonic apart from the eccentricity."""
    chords = any("/" in str(key) for ring_pass in point.passes for key in ring_pass.rec)
    return "estimate" if chords else "convention"


def finish_probe_radius(session: MeasureSession, ctx: MeasuringContext, points: list) -> tuple[dict, dict]:
    probe = _probe_of(ctx)
    point = points[0]
    try:
        # least squares from every touch of both spindle passes (measuring-math §7.3, engine.calibration)
        new, values = evaluate_probe_task("probe.radius", session.params, point, probe, ctx.plane,
                                          wcs2bcs=ctx.chain().wcs2bcs, pretravel_frame=ctx.settings.pretravel_frame,
                                          first_harmonic=_first_harmonic(point))
    except ValueError as exc:
        raise MeasuringError(alarms.PROBE_NOT_SWITCHED, str(exc)) from exc
    planes = sorted({*(ctx.probe_data or {}).get("calibrated_planes", []), ctx.plane.name})
    # more than 4 directions: the direction-dependent map is stored and used for every touch
    # (engine.lobing); 4 directions replace an older map by the 4 trigger values
    lobing = values.get("lobing") if int(session.params.get("directions", 4) or 4) > 4 else None
    ball = values.get("ball_diameter") or {}
    n, record = _record(ctx, new, {"cal_ring_diameter": float(session.params["diameter"]),
                                   "cal_wo": ctx.active_offset, "calibrated_planes": planes,
                                   "calibrated_spindle_angle": 0.0,      # the ring program ends at SPOS 0
                                   "lobing": lobing,
                                   "measured_ball_diameter": float(ball["value"]) if ball.get("measured") else None,
                                   "pretravel_frame": values.get("pretravel_frame")})
    values["probe"] = {**values["probe"], **_calibration_view(record)}
    decision = values.get("pretravel_frame_decision") or {}
    if ctx.settings.pretravel_frame == "auto" and not decision.get("decided"):
        session.warnings.append(UNDECIDED_FRAME[decision.get("frame") or "probe"])
    answer = {"result": values, "correction": None, "activated": False, "setup_support": None}
    return answer, {"offset": None, "probe_update": (n, record)}


def finish_probe_length(session: MeasureSession, ctx: MeasuringContext, points: list) -> tuple[dict, dict]:
    probe = _probe_of(ctx)
    point = points[0]
    height = surface_height(session.params, ctx.plane.infeed)
    try:
        new, values = evaluate_probe_task("probe.length", {**session.params, "setpoint": height}, point,
                                          probe, ctx.plane, length_old=float(ctx.tool_length))
    except ValueError as exc:
        raise MeasuringError(alarms.PROBE_NOT_SWITCHED, str(exc)) from exc
    # the NC measured with L1 + wear; the difference goes into the geometry L1 (DP3)
    tool = dict(ctx.tool or {})
    t = int(tool["t"])
    before = {"length": float(tool.get("length", 0.0)),
              "wear": {"length": float((tool.get("wear") or {}).get("length", 0.0))}}
    length_new = before["length"] + values["difference"]
    if length_new <= 0.0:
        raise MeasuringError(alarms.PROBE_NOT_SWITCHED, f"calibrated length L1 = {length_new:.4f} is not positive: "
                                    "check the surface height")
    values["length"] = length_new
    n, record = _record(ctx, new, {"cal_height": height,
                                   "cal_wo": ctx.active_offset})
    values["probe"] = {**values["probe"], **_calibration_view(record)}
    values["tool"] = {"t": t, "length": length_new}
    correction = {"target": f"T{t}", "before": before,
                  "after": {"length": length_new, "wear": before["wear"]}}
    answer = {"result": values, "correction": correction, "activated": False, "setup_support": None}
    tool_row = {k: v for k, v in tool.items() if k in ("t", "name", "type", "length", "radius", "wear")}
    tool_row["length"] = length_new
    return answer, {"offset": None, "probe_update": (n, record), "tool_update": (t, tool_row)}


def finish_probe_surface(session: MeasureSession, ctx: MeasuringContext, points: list) -> tuple[dict, dict]:
    """CYCLE976 ``_MVAR=0`` (manual §5.3.3): the trigger value of one direction on a surface at
    ``params.setpoint`` (engine.calibration.calibrate_surface); L1 and the other directions stay."""
    probe = _probe_of(ctx)
    axis, setpoint = session.params["axis"], float(session.params["setpoint"])
    try:
        new, values = calibrate_surface(points[0], axis, setpoint, probe, safe_area=session.params.get("safe_area"))
    except ValueError as exc:
        raise MeasuringError(alarms.PROBE_NOT_SWITCHED, str(exc)) from exc
    n, record = _record(ctx, new, {"cal_height": setpoint, "cal_wo": ctx.active_offset})
    values["probe"] = {**probe_values(new), **_calibration_view(record)}
    answer = {"result": values, "correction": None, "activated": False, "setup_support": None}
    return answer, {"offset": None, "probe_update": (n, record)}


def finish_probe_bore(session: MeasureSession, ctx: MeasuringContext, points: list) -> tuple[dict, dict]:
    """CYCLE976 in a bore along 1, 2 or 4 directions, axis-parallel or at _STA1 (manual §5.3.1,
    §5.3.2; engine.calibration.calibrate_bore): the probed directions' trigger values, and the skew
    and effective diameter when the variant asks for them; the other fields stay."""
    probe = _probe_of(ctx)
    params = session.params
    point = points[0]
    wcs2bcs = ctx.chain().wcs2bcs
    # the stored skew where the touches were made: SPOS 0 after an unknown-centre calibration
    spos = 0.0 if point.pass_centres is not None else float(ctx.spindle_angle)
    try:
        new, values = calibrate_bore(point, probe, ctx.plane, skew_wcs=skew_in_wcs(probe, wcs2bcs, spos),
                                     with_skew=bool(params.get("skew")), with_ball=bool(params.get("ball")),
                                     safe_area=params.get("safe_area"), wcs2bcs=wcs2bcs, spindle_angle=spos)
    except ValueError as exc:
        raise MeasuringError(alarms.PROBE_NOT_SWITCHED, str(exc)) from exc
    extra: dict = {"cal_ring_diameter": float(params["diameter"]), "cal_wo": ctx.active_offset}
    if params.get("skew"):
        extra["calibrated_spindle_angle"] = 0.0
    n, record = _record(ctx, new, extra)
    values["probe"] = {**probe_values(new), **_calibration_view(record)}
    answer = {"result": values, "correction": None, "activated": False, "setup_support": None}
    return answer, {"offset": None, "probe_update": (n, record)}


def _calibration_view(record: dict) -> dict:
    keys = ("number", "tool", "calibrated_plane", "calibration_feed", "calibration_override",
            "calibrated_at", "cal_ring_diameter", "cal_height", "cal_wo")
    return {k: record.get(k) for k in keys}

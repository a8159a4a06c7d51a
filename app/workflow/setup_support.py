"""Set-up support after measuring and chain measuring (spec/jog-measuring.md §6.1, jog-measuring §6.2, jog-measuring §6.3).

``finish_workpiece`` puts ``setup_support`` into the calculate answer when the correction went
into a WO not active while measuring, tilts the infeed axis, or needs a rotary axis positioned.
This module shows that answer as the activation screen (``screen_model``) and carries it out on
NC Start (``carry_out``):

- activate: select the corrected WO in the channel (no axis motion, jog-measuring §6.2 example 1). The
  activated WO becomes the WO of the next measurement (chain measuring, jog-measuring §6.1, ``_JM_I[6]``).
- re-align: CYCLE800-like swivel so that the tool axis is parallel to the new infeed axis. On a
  machine without swivel kinematics nothing moves; the screen says so and measuring continues
  with the probe as it is (a ball probe measures correctly obliquely in the tilted WCS).
- retract first (jog-measuring §11 Q9): only before a swivel, up along the tool axis to the top limit.
  The manual's toggle field 3 says "空运行" (dry run / traverse); the spec's function is kept.
- with a swivel head (scenario ``machine.kinematics``), NC Start activates first, then retracts
  and swivels the head so that the tool axis is ∥ the infeed axis of the (new) active WCS; the
  WCS follows the kinematics (engine.coords.length_axis), measuring goes on in the tilted WCS.
- position rotary axis (jog-measuring §2.5.2, jog-measuring §11 Q8): turn the axis by the correction's ``rotary_move``
  from where it stood while measuring, so that the edge lies at the setpoint angle.

Decisions: the "activate" toggle is offered in every case (the WO active while measuring was
not re-activated by Calculate when a set-up support was needed); a carried-out or left screen
cannot be carried out twice (a second NC Start would turn the rotary axis again).
"""

from __future__ import annotations

from dataclasses import dataclass

from app.errors import AlarmError, WorkflowError
from app.workflow.service import WorkflowService
from app.workflow.session import MeasureSession

TEXT_INACTIVE = "You are compensating in an inactive WO!"
TEXT_REALIGN = "The new WCS needs a new alignment!"
TEXT_ROTARY = "Rotary axis must be positioned!"
TEXT_NC_START = "Press NC Start to activate!"
TEXT_NO_SWIVEL = ("Re-alignment of the probe is not possible on this machine (no swivel "
                  "kinematics): measuring continues with the probe as it is")
TEXT_ACTIVATED = "{wo} activated: it is the WO of the next measurement"
TEXT_REALIGNED = "Probe re-aligned: tool axis parallel to {axis} of {wo} (head {angles})"
HELP_RETRACT = ("Retract along the tool axis to the limit before swivelling (manual toggle field 3: "
                "\u7a7a\u8fd0\u884c, dry run / traverse-free motion)")
STATE_CHAIN_WO = "jm_i6"          # _JM_I[6]: WO of the next measurement (chain measuring, jog-measuring §6.1)
AXES = ("X", "Y", "Z")


@dataclass(frozen=True)
class Choices:
    activate: bool = True
    realign: bool = True
    retract: bool = True
    position_rotary: bool = True


def _support_of(workflow: WorkflowService, session_id: str) -> tuple[MeasureSession, dict]:
    session = workflow.get(session_id)
    last = session.last or {}
    support = last.get("setup_support")
    if not support:
        raise WorkflowError(409, "no_setup_support",
                            "the last measurement needs no set-up support (nothing to carry out)")
    return session, support


def rotated_axes(before: dict | None, after: dict | None, tol: float = 1e-7) -> list[str]:
    """Geometry axes whose rotation component changed (the 'WCS rotated around …' hint)."""
    rb = (before or {}).get("rot") or {}
    ra = (after or {}).get("rot") or {}
    return [a for a in AXES if abs(float(ra.get(a, 0.0)) - float(rb.get(a, 0.0))) > tol]


def codes_of(support: dict) -> set[str]:
    return {r["code"] for r in support.get("reasons", [])}


def toggles(support: dict, swivel: bool) -> list[dict]:
    """The toggle fields of the screen (jog-measuring §6.2 [I] table), all preset to Yes."""
    codes = codes_of(support)
    out = [{"name": "activate", "label": "Activate compensated WO", "value": True,
            "text": TEXT_INACTIVE if "inactive_wo" in codes else ""}]
    if "realign" in codes:
        out.append({"name": "realign", "label": "Re-align probe", "value": swivel,
                    "text": TEXT_REALIGN, "enabled": swivel})
        out.append({"name": "retract", "label": "Retract before swivel", "value": swivel,
                    "text": "", "enabled": swivel, "help": HELP_RETRACT})
    for reason in support.get("reasons", []):
        if reason["code"] == "rotary":
            out.append({"name": "position_rotary", "label": reason.get("toggle", "Position rotary axis"),
                        "value": True, "text": TEXT_ROTARY, "axis": reason.get("axis"),
                        "move": reason.get("move")})
    return out


def top_line(support: dict, choices: Choices, swivel: bool) -> str:
    """The screen's top text line follows the answers (jog-measuring §6.2 example 2)."""
    codes = codes_of(support)
    if "realign" in codes and choices.realign and swivel:
        return TEXT_REALIGN
    if "rotary" in codes and choices.position_rotary:
        return TEXT_ROTARY
    if "inactive_wo" in codes and choices.activate:
        return TEXT_INACTIVE
    if "realign" in codes and not swivel:
        return TEXT_REALIGN
    return ""


def screen_model(workflow: WorkflowService, machine, session_id: str) -> dict:
    """Everything the activation screen shows (left: the measuring function, right: results)."""
    session, support = _support_of(workflow, session_id)
    last = session.last or {}
    correction = last.get("correction") or {}
    swivel = machine.has_swivel()
    hint_axes = rotated_axes(correction.get("before"), correction.get("after"))
    messages = []
    if "realign" in codes_of(support) and not swivel:
        messages.append(TEXT_NO_SWIVEL)
    return {
        "session": session.to_api(),
        "task": session.task,
        "measuring_wo": session.measuring_wo,
        "target": support.get("target"),
        "result": last.get("result"),
        "correction": correction,
        "reasons": support.get("reasons", []),
        "hint": ("WCS rotated around " + ", ".join(hint_axes)) if hint_axes else "",
        "toggles": toggles(support, swivel),
        "top_line": top_line(support, Choices(realign=swivel, retract=swivel), swivel),
        "message": support.get("message") or TEXT_NC_START,
        "messages": messages,
        "swivel": swivel,
        "done": bool(support.get("done")),
    }


def carry_out(workflow: WorkflowService, machine, session_id: str, choices: Choices, db=None) -> dict:
    """NC Start on the activation screen: carry out what the toggles say (jog-measuring §6.2)."""
    session, support = _support_of(workflow, session_id)
    _refuse_start(session, support, machine)
    codes = codes_of(support)
    target = support["target"]
    actions: list[str] = []
    messages: list[str] = []
    activated = _activate(machine, target, db, actions, messages) if choices.activate else None
    moved = False
    if "realign" in codes and choices.realign:
        if machine.has_swivel():
            _realign(machine, choices, actions, messages)
            moved = True
        else:
            messages.append(TEXT_NO_SWIVEL)
    if "rotary" in codes and choices.position_rotary:
        _position_rotary(machine, support, actions, messages)
        moved = True
    support["done"] = True
    support["carried_out"] = {"choices": choices.__dict__, "actions": actions}
    return {"done": True, "target": target, "activated": activated, "actions": actions,
            "messages": messages, "axis_motion": moved,
            "next_measuring_wo": machine.active_offset,
            "machine": machine.status()}


def _refuse_start(session, support: dict, machine) -> None:
    """NC Start refused: already carried out or left, the machine moving, an alarm shown."""
    if support.get("done"):
        raise WorkflowError(409, "setup_support_done", "the set-up support was already carried out or left")
    if session.running or machine.machine.status().busy:
        raise WorkflowError(409, "busy", "the machine is moving")
    alarms = machine.machine.status().alarms
    if alarms:
        raise WorkflowError(409, "alarm", f"{alarms[-1].code} {alarms[-1].text}: press Reset first")


def _activate(machine, target: str, db, actions: list[str], messages: list[str]) -> str:
    """The target WO activated (a basic frame: the chain refreshed); the chain's WO stored."""
    if target.startswith("BASIC") or target.startswith("NCBASIC"):
        machine.refresh_frame()          # basic frames are always part of the active chain
        activated = machine.active_offset
    else:
        machine.activate(target)
        activated = target
    actions.append("activate")
    messages.append(TEXT_ACTIVATED.format(wo=activated))
    if db is not None:
        with db.unit() as unit:
            unit.set_state(STATE_CHAIN_WO, activated)
    return activated


def _realign(machine, choices: Choices, actions: list[str], messages: list[str]) -> None:
    """The probe swivelled perpendicular to the active WO's plane (retracted first when chosen)."""
    try:
        if choices.retract:
            machine.retract_tool_axis()
            actions.append("retract")
        status = machine.swivel_to_wcs()
    except AlarmError as exc:
        raise WorkflowError(409, "alarm", f"{exc}: the probe was not re-aligned (press Reset; "
                            "retract or move clear, then NC Start again)") from None
    actions.append("realign")
    head = machine.head_axes()
    angles = ", ".join(f"{a}={status['mcs'][a]:.4f} deg" for a in head)
    messages.append(TEXT_REALIGNED.format(axis=machine.plane().infeed, wo=machine.active_offset, angles=angles))


def _position_rotary(machine, support: dict, actions: list[str], messages: list[str]) -> None:
    """The rotary axis turned by the move the support proposed."""
    reason = next(r for r in support["reasons"] if r["code"] == "rotary")
    axis, move = reason["axis"], float(reason["move"])
    start = float(machine.machine.status().mcs[axis])
    machine.goto({axis: start + move}, coords="MCS")
    actions.append(f"position {axis}")
    messages.append(f"Rotary axis {axis} turned by {move:.4f}° to {start + move:.4f}°")


GUIDED_STATE = "tilted_setup"      # guided tilted set-up: {"target": "G54", "since": last log id}


def guided_state(db) -> dict:
    """The guided tilted set-up in progress ({} when none was started)."""
    with db.unit(readonly=True) as unit:
        return dict(unit.get_state(GUIDED_STATE, None) or {})


def start_guided(db, target: str) -> None:
    """(Re)start the guided set-up for ``target``: later log entries count; _JM_I[6] reset."""
    with db.unit() as unit:
        entries = unit.list_log(limit=1)
        unit.set_state(GUIDED_STATE, {"target": target, "since": entries[0]["id"] if entries else 0})
        unit.set_state(STATE_CHAIN_WO, None)


def chain_wo(db) -> str | None:
    """``_JM_I[6]``: the WO the last set-up support activated for the next measurement."""
    with db.unit(readonly=True) as unit:
        return unit.get_state(STATE_CHAIN_WO, None)


def leave(workflow: WorkflowService, session_id: str) -> dict:
    """``<<``: leave without activating; the written correction stays (jog-measuring §6.2)."""
    _session, support = _support_of(workflow, session_id)
    support["done"] = True
    support["left"] = True
    return {"done": True, "activated": None, "actions": []}

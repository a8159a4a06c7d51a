"""Guided "tilted workpiece set-up" (spec/jog-measuring.md §6.1 chain measuring, jog-measuring §6.2, jog-measuring §6.3).

A step list that walks the operator through the chain that ends in a full 6-DOF zero offset:

1. Orient plane (measured under G500, corrected into the target WO, e.g. G54)
2. Activate the target WO (+ re-align the probe with a swivel head) on the set-up support screen
3. Right-angled corner (or Align edge) in the tilted plane, measuring WO = target
4. Set edge Z (infeed axis) in the tilted plane
-> done: the target WO holds translation and rotation (shown).

Each step opens the existing input screen; from step 2 on, the WO the previous step produced is
the proposal ``_JM_I[6]`` (db state ``jm_i6``, written by the set-up support) and is activated
before the input screen opens, so that its "Zero offset" field is preset to it. Step 1 has no
predecessor: it activates G500 (the measuring WO of jog-measuring §6.2 example 2) and the operator selects
the target WO in the orient-plane screen (the input screens take no preset from a URL).

Which steps are done comes from the measurement log (entries after the guided set-up was
started, by task, target and measuring WO) and the state (active WO, ``jm_i6``).
"""

from __future__ import annotations

from fastapi import APIRouter, Form, Request
from fastapi.responses import RedirectResponse

from app.access.deps import needs
from app.i18n import gettext
from app.workflow import setup_support as support
from engine.frames import Frame

from .task_screens import PAGES
from .templating import render_screen, softkey, url_path, vkeys

router = APIRouter()
G500 = "G500"
# the input screens the steps open: step n -> task (5: Align edge in place of step 3's corner)
STEP_TASKS = {1: "plane.align", 3: "corner.right", 4: "edge.set", 5: "edge.align"}


def _log_since(log, since: int) -> list[dict]:
    """Successful log entries after ``since``, oldest first."""
    return [e for e in reversed(log.list(200)) if e["id"] > since and e.get("status") == "ok"]


def _measuring_wo(entry: dict) -> str | None:
    return entry.get("measuring_wo")


def steps_model(services) -> dict:
    """The step list with done flags and the resulting WO."""
    state = support.guided_state(services.db)
    target = state.get("target")
    machine = services.machine
    plane = machine.plane()
    chain_wo = support.chain_wo(services.db)
    swivel = machine.has_swivel()
    entries = _log_since(services.log, int(state.get("since", 0))) if target else []
    done = _done(entries, target, plane, activated=chain_wo == target and machine.active_offset == target)
    aligned = _aligned(machine, plane) if done[1] and swivel else None
    steps = _steps(target, plane, swivel)
    current = next((i + 1 for i, d in enumerate(done) if not d), None)
    for step, is_done in zip(steps, done, strict=True):
        step["done"] = is_done
        step["current"] = step["n"] == current
    offset = services.offsets.list().get(target) if target else None
    return {"target": target, "steps": steps, "complete": all(done) and target is not None,
            "current": current, "chain_wo": chain_wo, "active": machine.active_offset,
            "aligned": aligned, "swivel": swivel, "offset": offset,
            "translation": dict(zip("XYZ", Frame.from_api(offset).translation, strict=True)) if offset else None,
            "targets": [n for n in services.offsets.names() if n.startswith("G5")]}


def _done(entries: list[dict], target, plane, *, activated: bool) -> list[bool]:
    """Which of the four steps are done, from the log entries since the set-up started (each step
    after the one before it)."""

    def find(pred, after: int = 0) -> dict | None:
        return next((e for e in entries if e["id"] > after and pred(e)), None)

    def in_target(e: dict) -> bool:
        return e.get("target") == target and _measuring_wo(e) == target

    plane_entry = find(lambda e: e["task"] == "plane.align" and e.get("target") == target)
    s1 = plane_entry is not None
    s2 = s1 and activated
    after_plane = plane_entry["id"] if plane_entry else 0
    corner = find(lambda e: e["task"] in ("corner.right", "edge.align") and in_target(e), after_plane) if s2 else None
    edge = find(lambda e: e["task"] == "edge.set" and (e.get("params") or {}).get("axis") == plane.infeed
                and in_target(e), corner["id"]) if corner else None
    return [s1, s2, corner is not None, edge is not None]


def _aligned(machine, plane) -> bool:
    """Whether the tool axis stands perpendicular to the active WO's plane."""
    status = machine.status()
    infeed = machine.chain.wcs2bcs.dir_child2parent(plane.infeed_unit)
    return abs(float(sum(a * b for a, b in zip(status["tool_axis"], infeed, strict=True))) - 1.0) < 1e-9


def _steps(target, plane, swivel: bool) -> list[dict]:
    return [
        {"n": 1, "label": "Orient plane", "detail": f"measure the top face under G500, Zero offset = {target}",
         "task": "plane.align"},
        {"n": 2, "label": "Activate" + (" + re-align probe" if swivel else ""),
         "detail": "set-up support: NC Start activates the WO" + (
             " and swivels the probe perpendicular to the new plane" if swivel else
             " (no swivel on this machine: the probe stays as it is)"), "task": "setup-support"},
        {"n": 3, "label": "Right-angled corner (or Align edge) in the tilted plane",
         "detail": f"measuring WO = {target}", "task": "corner.right"},
        {"n": 4, "label": f"Set edge {plane.infeed}", "detail": f"measuring WO = {target}", "task": "edge.set"},
    ]


def _render(request: Request, notice: str = ""):
    services = request.app.state.services
    model = steps_model(services)
    return render_screen(request, "tilted_setup.html", {
        "screen": "measure_workpiece", "m": model, "notice": notice,
        "vkeys": vkeys([], softkey(request, "Back", "measure_workpiece_menu")),
        "message": notice or _dialog(model)})


def _dialog(model: dict) -> str:
    if not model["target"]:
        return gettext("Select the zero offset to set up and press Start")
    if model["complete"]:
        return gettext("Set-up complete: %(target)s holds the full 6-DOF zero offset", target=model["target"])
    return gettext("Next: step %(step)s", step=model["current"])


@router.get("/measure/workpiece/tilted-setup", name="tilted_setup_screen")
def screen(request: Request):
    return _render(request)


@router.post("/measure/workpiece/tilted-setup/start", name="tilted_setup_start", dependencies=[needs("measure")])
def start(request: Request, target: str = Form("G54")):
    """Start (or restart) the guided set-up for ``target``; the chain proposal ``_JM_I[6]`` is reset."""
    services = request.app.state.services
    if target not in services.offsets.names() or not target.startswith("G5"):
        return _render(request, notice=f"{target!r} is not a settable zero offset")
    support.start_guided(services.db, target)
    return RedirectResponse(url_path(request, "tilted_setup_screen"), status_code=303)


@router.post("/measure/workpiece/tilted-setup/open/{n}", name="tilted_setup_open", dependencies=[needs("measure")])
def open_step(request: Request, n: int):
    """Open the input screen of step ``n`` with its measuring WO active (preset of the target)."""
    services = request.app.state.services
    model = steps_model(services)
    if not model["target"]:
        return _render(request, notice="Start the guided set-up first (select the zero offset)")
    machine = services.machine
    if n == 1:
        machine.activate(G500)
        return RedirectResponse(PAGES[STEP_TASKS[1]].href(request), status_code=303)
    if n == 2:
        session = services.workflow.session
        last = (session.last or {}) if session is not None else {}
        if session is None or session.task != "plane.align" or not last.get("setup_support"):
            return _render(request, notice="Measure step 1 (Orient plane) first: its set-up support "
                                           "screen activates the WO")
        href = url_path(request, "setup_support_screen", session_id=session.id)
        return RedirectResponse(href, status_code=303)
    if n in (3, 4, 5):
        proposal = model["chain_wo"] or model["target"]
        if machine.active_offset != proposal:
            machine.activate(proposal)
        return RedirectResponse(PAGES[STEP_TASKS[n]].href(request), status_code=303)
    return _render(request, notice=f"no step {n}")

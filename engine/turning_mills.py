"""CYCLE982: milling cutters and drills on a lathe (turning.md §3).

Tool model (SD 42950 TOOL_LENGTH_TYPE=2: lengths like a turning tool, L1 in X, L2 in Z
[L17482–L17490]): the NC reference P = F − (L1·x̂ + L2·ẑ) is the centre of the cutter's end
face; the cutter is a cylinder of radius R about its axis. Axial position (_MVAR digit 5 = 0):
axis ∥ Z, end face facing −Z, radius on X; radial position (digit 5 = 1): axis ∥ X, end face
facing −X, radius on Z (turning.md §3.1). Steps: "MCS" (_TP) or "WCS" (_TPW), X radius.

Measured value of a touch i (turning.md §3.2, **[I]** reading of "P"): ``P_i = F − f`` on the
measuring axis = ``rec + L_stored − f`` with f the probe face (_TP) touched:
- on the tool axis (end face, travel −): ``P = L`` (L2 axial, L1 radial);
- across it (periphery, travel d): ``P = L − d·R`` (L1 axial, L2 radial), so
  length only ``L = P + d·R`` (10101: L2 = P − R, other direction P + R [L18320–L18348]),
  radius only ``R = |P − L|`` (1101 [L18290–L18305]), two points on opposite faces
  ``L = (P1 + P2)/2``, ``R = |P1 − P2|/2`` (12001/2001 [L18395–L18480], 3-A).
With reversal (digit 3) every touch is made at the spindle angle and again at +180° + _CORA,
the mean is the value [L18080–L18085]. Without reversal a second point on the opposite side is
made at +180° so that the same edge touches [L18033–L18060]. Automatic (digit 1 = 2, digit 4 = 0):
Z first (P1, P2), then X (P3, P4) [L18732–L18740]; the end face twice (same edge, 180° apart)
and the periphery on both sides; with R = 0 one touch each; a drill only its length.
Contact height of a periphery touch: the cutter's end at the probe centre (turning.md §12 Q19).
Drills with SD 42950=0 in G17/G19: L1 on the applicate (Z / X), _MA ignored (turning §3.4).
Not supported: the upper-edge variants (digit 4 = 3/4, slot mills; 61307 in check_982).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from engine import alarms
from engine.turning import (
    LatheContext,
    LatheMotion,
    LathePoint,
    LatheProgram,
    LatheSteps,
    LatheTool,
    LatheTouch,
    axis_of_ma,
    check_fa,
    direction_of_md,
    key,
    measuring_feed,
    other_plane_axis,
    tp_centre,
    tp_face,
)
from engine.turning_tools import (
    Cycle982,
    ToolResult,
    check_982,
    finish_tool,
    tool_probe_record,
    travel_direction,
)
from engine.types import MeasuringError


def _axes(radial: bool) -> tuple[str, str]:
    """(tool axis T, radius axis Q): axial (T = Z, Q = X), radial (T = X, Q = Z) (turning.md §3.1)."""
    return ("X", "Z") if radial else ("Z", "X")


def _applicate_axis(ctx: LatheContext) -> str | None:
    """Drill with SD 42950=0: L1 on the applicate of G17 (Z) / G19 (X) (turning.md §3.4, turning §12 Q13)."""
    if ctx.tool is not None and ctx.tool.family == "drill" and ctx.tool_length_type == 0:
        return {"G17": "Z", "G19": "X"}.get(ctx.plane)
    return None


def mill_program(call: Cycle982, start: npt.ArrayLike, ctx: LatheContext, label: str = "P") -> LatheProgram:
    """The point program of a mill or drill (module docstring; turning.md §3.1–turning §3.4)."""
    variant, tool = check_982(call, ctx)
    if tool.family not in ("mill", "drill") or variant.kind == "calibrate":
        raise ValueError("mill_program measures mills and drills")
    run = _MillRun(call, variant, tool, start, ctx, label)
    yield from run.spos(run.sta1, f"{label}1")                 # SPOS _STA1 first (3-A) unless _CHBIT[20]=1
    app = _applicate_axis(ctx)
    if app is not None:                                         # drill, SD 42950=0 (turning.md §3.4)
        return (yield from run.drill_on_applicate(app))
    run.place_axes()
    if variant.incremental:
        return (yield from run.incremental())
    if variant.kind == "measure":
        return (yield from run.measure())
    return (yield from run.automatic())


class _MillRun:
    """One CYCLE982 run of a mill or drill: the motion, the touches so far and the probe's record."""

    def __init__(self, call: Cycle982, variant: Any, tool: Any, start: npt.ArrayLike, ctx: LatheContext,
                 label: str) -> None:
        _, self.record = tool_probe_record(call, variant, ctx)
        self.call, self.variant, self.label = call, variant, label
        self.fa = check_fa(call.fa)
        self.feed = measuring_feed(call.vms, self.fa)
        self.p0 = np.asarray(start, float)
        self.m = LatheMotion(self.p0, ctx, "WCS" if variant.workpiece else "MCS")
        self.touches: list[LatheTouch] = []
        self.use_spos = not ctx.bit(20)
        self.r = tool.effective("radius")
        self.drill = tool.family == "drill"
        self.sta1 = float(call.sta1)

    def place_axes(self) -> None:
        """Tool axis T and radius axis Q, the probe's centre and the end face's face, where the
        axes stand (after the first SPOS; not for a drill on the applicate)."""
        variant = self.variant
        self.t_ax, self.q_ax = _axes(variant.radial)
        self.c_t, self.c_q = tp_centre(self.record, self.t_ax), tp_centre(self.record, self.q_ax)
        self.f_t = tp_face(self.record, key(self.t_ax, -1))    # the face the end face touches travelling −T
        self.q0, self.t0 = float(self.p0["XYZ".index(self.q_ax)]), float(self.p0["XYZ".index(self.t_ax)])
        # the same edge on the opposite side [L18050–L18060]
        self.second = self.sta1 if variant.reversal else self.sta1 + 180.0
        self.info = {"tool_axis": self.t_ax, "radius_axis": self.q_ax, "radius": self.r}

    # --- the touches -------------------------------------------------------------------------
    def spos(self, angle: float, tag: str) -> LatheSteps:
        if self.use_spos:
            yield from self.m.spos(angle, f"{tag} SPOS")

    def angles(self, base: float) -> tuple[float, ...]:
        return (base, base + 180.0 + float(self.call.cora)) if self.variant.reversal else (base,)

    def probe_at(self, k: str, base: float, role: str, distance: float, expected: float | None) -> LatheSteps:
        for i, ang in enumerate(self.angles(base)):
            yield from self.spos(ang, role)
            tag = f"{role} {k}" + (" reversal" if i else "")
            self.touches.append((yield from self.m.touch(k, distance, self.feed, self.call.nmsp, tag,
                                                         expected=expected, role=role)))

    def finish(self, info: dict[str, Any]) -> LathePoint:
        return LathePoint(cycle=self.call.cycle, mvar=self.call.mvar, coords=self.m.coords, start=self.p0.copy(),
                          touches=tuple(self.touches), info=info)

    def end_touch(self, role: str, sigma: int, base: float) -> LatheSteps:
        """End face: out along T to the start of probing, then the measuring point (the edge
        on the probe side, axis − σ·R) on the probe centre; probe −T."""
        m, t_ax, fa = self.m, self.t_ax, self.fa
        yield from m.move_axis(t_ax, max(float(m.pos["XYZ".index(t_ax)]), self.f_t + fa), f"{role} clear in {t_ax}")
        yield from m.move_axis(self.q_ax, self.c_q + sigma * self.r, f"{role} measuring point on the probe centre")
        yield from m.move_axis(t_ax, self.f_t + fa, f"{role} start of probing")
        yield from self.probe_at(key(t_ax, -1), base, role, 2.0 * fa, fa)

    def side_touch(self, role: str, d: int, base: float) -> LatheSteps:
        """Periphery travelling d on Q: Q to the start of probing (cutter clear of the probe in T
        or already beside it), then the cutter's end to the probe centre in T; probe d."""
        f_q = tp_face(self.record, key(self.q_ax, d))
        yield from self.m.move_axis(self.q_ax, f_q - d * (self.r + self.fa), f"{role} start of probing")
        yield from self.m.move_axis(self.t_ax, self.c_t, f"{role} cutter end at the probe centre")
        yield from self.probe_at(key(self.q_ax, d), base, role, 2.0 * self.fa, self.fa)

    def round_to(self, d_next: int, role: str) -> LatheSteps:
        """Round the probe: out along +T beyond the probe, across Q to the next start of probing."""
        yield from self.m.move_axis(self.t_ax, self.f_t + self.fa, f"{role} round the probe ({self.t_ax})")
        yield from self.m.move_axis(self.q_ax, tp_face(self.record, key(self.q_ax, d_next)) - d_next * (self.r + self.fa),
                                    f"{role} round the probe ({self.q_ax})")

    # --- the variants ------------------------------------------------------------------------
    def drill_on_applicate(self, app: str) -> LatheProgram:
        """A drill with SD 42950=0: its length on the applicate, travelling towards its tip (turning.md §3.4)."""
        call, fa, record, label = self.call, self.fa, self.record, self.label
        incremental = self.variant.incremental
        d = direction_of_md(call.md) if incremental else -1
        if d != -1:
            raise MeasuringError(alarms.TOOL_TIP_POSITION, "a drill's length is measured travelling towards its tip (-)")
        if not incremental:
            travel_direction(float(self.p0["XYZ".index(app)]), 0, 0.0, tp_face(record, key(app, -1)),
                             tp_face(record, key(app, 1)), fa, (-1,), what="drill")
            other = other_plane_axis(app)
            yield from self.m.move_axis(other, tp_centre(record, other), f"{label}1 tip on the probe centre")
            yield from self.m.move_axis(app, tp_face(record, key(app, -1)) + fa, f"{label}1 start of probing")
        yield from self.probe_at(key(app, -1), self.sta1, f"{label}1", 2.0 * fa, None if incremental else fa)
        if incremental:
            yield from self.m.move(self.m.start, "back to the start", returning=True)
        return self.finish({"tool_axis": app, "applicate": True, "radius": 0.0})

    def incremental(self) -> LatheProgram:
        call, t_ax = self.call, self.t_ax
        a = axis_of_ma(call.ma, (1, 2))
        d = direction_of_md(call.md)
        if a == t_ax and d != -1:
            raise MeasuringError(alarms.TOOL_TIP_POSITION, f"the end face is measured travelling {key(t_ax, -1)}")
        if a == t_ax and self.variant.d4 == 1:
            raise MeasuringError(alarms.WRONG_VARIANT, f"the radius does not lie on _MA={call.ma} (turning.md §3.1)")
        yield from self.probe_at(key(a, d), self.sta1, f"{self.label}1", 2.0 * self.fa, None)
        yield from self.m.move(self.m.start, "back to the start", returning=True)
        return self.finish({**self.info, "measuring_axis": a})

    def measure(self) -> LatheProgram:
        call, record, label, t_ax, q_ax, fa = self.call, self.record, self.label, self.t_ax, self.q_ax, self.fa
        a = axis_of_ma(call.ma, (1, 2))
        if a == t_ax:
            if self.variant.d4 != 0:
                raise MeasuringError(alarms.WRONG_VARIANT,
                                     f"_MVAR={call.mvar}: the radius does not lie on _MA={call.ma} (turning.md §3.1)")
            travel_direction(self.t0, 0, 0.0, self.f_t, tp_face(record, key(t_ax, 1)), fa, (-1,), what="cutter")
            sigma = 1 if self.q0 >= self.c_q else -1
            yield from self.end_touch(f"{label}1", sigma, self.sta1)
        else:
            d1 = travel_direction(self.q0, 0, self.r, tp_face(record, key(q_ax, -1)), tp_face(record, key(q_ax, 1)),
                                  fa, what="cutter")
            yield from self.side_touch(f"{label}1", d1, self.sta1)
            if self.variant.d4 == 2:
                yield from self.round_to(-d1, f"{label}2")
                yield from self.side_touch(f"{label}2", -d1, self.second)
        return self.finish({**self.info, "measuring_axis": a})

    def automatic(self) -> LatheProgram:
        """Digit 1 = 2, digit 4 = 0: Z first, then X [L18732–L18740]; back Z, then X."""
        record, label, t_ax, q_ax, fa = self.record, self.label, self.t_ax, self.q_ax, self.fa
        travel_direction(self.t0, 0, 0.0, self.f_t, tp_face(record, key(t_ax, 1)), fa, (-1,), what="cutter")
        dq = travel_direction(self.q0, 0, self.r, tp_face(record, key(q_ax, -1)), tp_face(record, key(q_ax, 1)), fa,
                              what="cutter")
        two = self.r > 0.0 and not self.drill
        if self.drill:
            yield from self.end_touch(f"{label}1", 1 if self.q0 >= self.c_q else -1, self.sta1)
        elif t_ax == "Z":                               # axial: P1/P2 end face (L2), P3/P4 periphery (L1, R)
            yield from self._ends(f"{label}1", f"{label}2", two)
            yield from self._sides(f"{label}3", f"{label}4", dq, two)
        else:                                           # radial: P1/P2 periphery (L2, R), P3/P4 end face (L1)
            yield from self._sides(f"{label}1", f"{label}2", dq, two)
            yield from self._ends(f"{label}3", f"{label}4", two)
        yield from self.m.move_axis("Z", float(self.p0[2]), "back to the start Z", returning=True)
        yield from self.m.move_axis("X", float(self.p0[0]), "back to the start X", returning=True)
        return self.finish({**self.info, "automatic": True})

    def _ends(self, first: str, second_role: str, two: bool) -> LatheSteps:
        s_now = 1 if float(self.m.pos["XYZ".index(self.q_ax)]) >= self.c_q else -1
        yield from self.end_touch(first, s_now, self.sta1)
        if two:
            yield from self.end_touch(second_role, -s_now, self.second)

    def _sides(self, first: str, second_role: str, dq: int, two: bool) -> LatheSteps:
        yield from self.side_touch(first, dq, self.sta1)
        if two:
            yield from self.round_to(-dq, second_role)
            yield from self.side_touch(second_role, -dq, self.second)


def _p_value(touches: Sequence[LatheTouch], record: Mapping[str, float], tool: LatheTool) -> float:
    """P = rec + L_stored − f on the touch axis, averaged over the touches (reversal, _NMSP)."""
    values = [t.value + tool.length_on(t.axis) - tp_face(record, t.key) for t in touches]
    return float(np.mean(values))


def evaluate_mill(call: Cycle982, point: LathePoint, ctx: LatheContext, ev: float = 0.0) -> ToolResult:
    """The formulas of turning.md §3.2 (module docstring) -> engine.turning_tools.finish_tool."""
    variant, tool = check_982(call, ctx)
    _, record = tool_probe_record(call, variant, ctx)
    roles: dict[str, list[LatheTouch]] = {}
    for t in point.touches:
        roles.setdefault(t.role, []).append(t)
    ordered = list(roles)                              # P1, P2, ... in probing order
    r_stored = tool.effective("radius")
    measured: dict[str, float] = {}
    if point.info.get("applicate"):
        measured["l1"] = tool.effective("l1") + float(np.mean(     # L1 = L1_stored + rec − f on the
            [t.value - tp_face(record, t.key) for t in point.touches]))  # applicate [L20109–L20185], turning §3.4
        return finish_tool(call, variant, tool, measured, ev, ctx)
    t_ax, q_ax = _axes(variant.radial)
    name = {"X": "l1", "Z": "l2"}

    def end_length(rs: Sequence[str]) -> float:
        # end face: L = P, twice with the same edge 180° apart: L2 = (P1z + P2z)/2 [L18830–L18860]
        return float(np.mean([_p_value(roles[x], record, tool) for x in rs]))

    def side(rs: Sequence[str]) -> tuple[float, float | None]:
        ps = [(_p_value(roles[x], record, tool), roles[x][0].sign) for x in rs]
        if len(ps) == 2:
            (p1, _), (p2, _) = ps
            # L = (P1 + P2)/2, R = ABS(P1 − P2)/2 [L18395–L18480, L18830–L18860], turning.md §3.2
            return 0.5 * (p1 + p2), 0.5 * abs(p1 - p2)
        (p, d), = ps
        return p + d * r_stored, None            # L2 = P − R / P + R (10101) [L18320–L18348], turning.md §3.2

    if variant.kind == "measure" or variant.incremental:
        axis = roles[ordered[0]][0].axis
        if axis == t_ax:
            measured[name[t_ax]] = end_length(ordered)
        elif variant.d4 == 1:                # radius only: R = ABS(P − L1) (1101) [L18290–L18305], turning §3.2
            p = _p_value(roles[ordered[0]], record, tool)
            measured["radius"] = abs(p - tool.length_on(q_ax))
        else:
            length, radius = side(ordered)
            measured[name[q_ax]] = length
            if radius is not None:
                measured["radius"] = radius
    else:
        end_roles = [x for x in ordered if roles[x][0].axis == t_ax]
        side_roles = [x for x in ordered if roles[x][0].axis == q_ax]
        measured[name[t_ax]] = end_length(end_roles)
        if side_roles:
            length, radius = side(side_roles)
            measured[name[q_ax]] = length
            if radius is not None:
                measured["radius"] = radius
    return finish_tool(call, variant, tool, measured, ev, ctx)

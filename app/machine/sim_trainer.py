"""The trainer's answer (issue 17 item 10): how far a set-up's zero offset is from the hidden part.

Computed on the simulator's side from its truth (the scenario's pose, the rotary table's angle)
and the frames as the simulated NC holds them; it never uses the engine (design.md §2: the
simulator must not know the answer from the same code).

Decisions (the set-up's intent is not known to the machine):
- The reference is the part's point nearest to the WCS zero: a corner of the top face (block
  or prism), or the top centre of a hole, pocket, spigot or boss, or a sphere's centre. The set-up
  meant that point to be the zero (setpoints 0): the usual job (corner + Z edge into G54).
- The right WCS axes are the part's own, turned by a multiple of 90° about its z axis (the one
  nearest the stored rotation: a set-up may align to any edge).
- The error is the stored frame's entries minus those of the frame that puts the WCS there (mm
  and degrees of the offset table, in the offset's parent system), so a known error written by
  hand comes back as it was written.
- The chain is the NC's (design.md §3): BASIC_REF ∘ BASIC_0 ∘ BASIC_1 ∘ … ∘ the settable offset.
"""

from __future__ import annotations

import math

import numpy as np

from .physics import rpy_matrix
from .scene import workpiece_pose

AXES = ("X", "Y", "Z")
CORNER_NAMES = {1: "front left", 2: "front right", 3: "back right", 4: "back left"}


def _frame(data: dict | None) -> np.ndarray:
    """4×4 child -> parent of an NC frame ``{"trans", "fine", "rot"}`` (coarse + fine)."""
    m = np.eye(4)
    if not data:
        return m
    trans, fine, rot = data.get("trans") or {}, data.get("fine") or {}, data.get("rot") or {}
    m[:3, :3] = rpy_matrix([rot.get(a, 0.0) for a in AXES])
    m[:3, 3] = [trans.get(a, 0.0) + fine.get(a, 0.0) for a in AXES]
    return m


def _rpy(rotation: np.ndarray) -> np.ndarray:
    """(a, b, c) degrees of R = Rz(c)·Ry(b)·Rx(a) (design.md §3), b in [−90°, 90°]."""
    b = math.asin(max(-1.0, min(1.0, -rotation[2, 0])))
    a = math.atan2(rotation[2, 1], rotation[2, 2])
    c = math.atan2(rotation[1, 0], rotation[0, 0])
    return np.degrees([a, b, c])


def _outside(offsets: dict[str, dict]) -> np.ndarray:
    """BASIC_REF ∘ BASIC_0 ∘ BASIC_1 ∘ …: the frames outside a settable offset."""
    basics = sorted((n for n in offsets if n.startswith("BASIC_") and n != "BASIC_REF"),
                    key=lambda n: int(n.split("_")[1]) if n.split("_")[1].isdigit() else 0)
    m = _frame(offsets.get("BASIC_REF"))
    for name in basics:
        m = m @ _frame(offsets[name])
    return m


def reference_points(scenario, table_angle: float) -> list[tuple[str, np.ndarray]]:
    """(operator's name, MCS point) of the part's points a set-up can put the zero on."""
    wp = scenario.workpiece
    if wp is None:
        return []
    rot, trans = workpiece_pose(scenario, table_angle)

    def mcs(x: float, y: float, z: float) -> np.ndarray:
        return rot @ np.array([x, y, z], dtype=float) + trans

    out: list[tuple[str, np.ndarray]] = []
    base = wp.base
    if base is not None and base.type == "block":
        lx, ly, _lz = base.size
        for n, (x, y) in enumerate(((0, 0), (lx, 0), (lx, ly), (0, ly)), start=1):
            out.append((f"corner {n} of the top face ({CORNER_NAMES[n]})", mcs(x, y, 0.0)))
    elif base is not None:
        for n, (x, y) in enumerate(base.ccw_polygon, start=1):
            out.append((f"corner {n} of the top face (x {x:g}, y {y:g})", mcs(x, y, 0.0)))
    for f in wp.features:
        if f.type in ("hole", "spigot"):
            top = f.height if f.type == "spigot" else 0.0
            out.append((f"{f.type} Ø{f.diameter:g} at x {f.center[0]:g}, y {f.center[1]:g}",
                        mcs(f.center[0], f.center[1], top)))
        elif f.type in ("pocket", "boss"):
            top = f.height if f.type == "boss" else 0.0
            out.append((f"{f.type} {f.size[0]:g}×{f.size[1]:g} at x {f.center[0]:g}, y {f.center[1]:g}",
                        mcs(f.center[0], f.center[1], top)))
        elif f.type == "sphere":
            out.append((f"sphere Ø{f.diameter:g}", mcs(*f.center)))
    return out


def _quarter_turn(part_rot: np.ndarray, wcs_rot: np.ndarray) -> np.ndarray:
    """The part's axes turned by k·90° about its z, the k nearest the WCS's x axis."""
    best, best_dot = part_rot, -2.0
    for k in range(4):
        turned = part_rot @ rpy_matrix((0.0, 0.0, 90.0 * k))
        dot = float(turned[:, 0] @ wcs_rot[:, 0])
        if dot > best_dot:
            best, best_dot = turned, dot
    return best


def _wrap(deg: float) -> float:
    return (deg + 180.0) % 360.0 - 180.0


def setup_error(scenario, table_angle: float, offsets: dict[str, dict], name: str) -> dict:
    """The error of offset ``name`` against the hidden part (module docstring)."""
    if name not in offsets:
        raise ValueError(f"offset: the NC holds no zero offset {name!r}")
    refs = reference_points(scenario, table_angle)
    if not refs:
        raise ValueError("the scenario has no workpiece to compare the set-up with")
    outside = _outside(offsets)
    stored = _frame(offsets[name])
    wcs2mcs = outside @ stored
    origin = wcs2mcs[:3, 3]
    label, point = min(refs, key=lambda r: float(np.linalg.norm(r[1] - origin)))
    part_rot, _ = workpiece_pose(scenario, table_angle)
    right = np.eye(4)
    right[:3, :3] = _quarter_turn(part_rot, wcs2mcs[:3, :3])
    right[:3, 3] = point
    ideal = np.linalg.inv(outside) @ right                 # the settable frame of the right set-up
    stored_rot, ideal_rot = _rpy(stored[:3, :3]), _rpy(ideal[:3, :3])
    in_wcs = np.linalg.inv(wcs2mcs) @ np.append(point, 1.0)
    return {
        "offset": name,
        "reference": label,
        "error": {"trans": {a: float(stored[i, 3] - ideal[i, 3]) for i, a in enumerate(AXES)},
                  "rot": {a: _wrap(float(stored_rot[i] - ideal_rot[i])) for i, a in enumerate(AXES)}},
        "reference_in_wcs": {a: float(in_wcs[i]) for i, a in enumerate(AXES)},
        "ideal": {"trans": {a: float(ideal[i, 3]) for i, a in enumerate(AXES)},
                  "rot": {a: float(ideal_rot[i]) for i, a in enumerate(AXES)}},
    }

"""Undo of an audited change (``POST /api/audit/{id}/undo``, the History/Restore view, design.md
jog-measuring §9.2): the value before that change is written again, as a new audited write (source "undo",
detail ``{"undo_of": id}``), by the service that owns the data so that the NC gets it too.

Undoable: zero offsets, tools, workpiece and tool probe records, rotary-axis kinematic data. Not undoable (409
``not_undoable``): memories, settings, scenario loads, users, tokens, keyswitch: write them again.
"""

from __future__ import annotations

from app.errors import ConflictError

from .kinematics import KinematicsService

# the access function an undo of each kind needs (app/access/levels.py)
UNDO_FUNCTION = {"offset": "offsets", "tool": "tools", "probe": "probe_data", "tool_probe": "probe_data",
                 "memory": "offsets", "settings": "settings", "kinematics": "settings"}


def undo(services, entry: dict, force: bool = False) -> dict:
    kind = entry["kind"]
    if kind == "offset":
        return services.offsets.restore(entry, force)
    if kind == "tool":
        return services.tools.restore(entry, force)
    if kind == "probe":
        return services.probes.restore(entry, force)
    if kind == "tool_probe":
        return services.tool_probes.restore(entry, force)
    if kind == "kinematics":
        return KinematicsService(services.db, services.machine).restore(entry, force)
    raise ConflictError(f"a change of kind {kind!r} cannot be undone here: write the value again",
                        code="not_undoable")

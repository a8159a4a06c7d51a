"""What ``reset_data`` clears on either machine (mill and lathe alike): no tools, zero offsets,
empty probe and tool-probe records, no tool in the spindle. The scenario's nominal data are
seeded afterwards by each machine's own seeding (machine_service, lathe_data)."""

from __future__ import annotations

STATE_TOOL = "tool"        # the stored state key of the tool in the spindle


def clear_stored_data(unit) -> None:
    """Clear the stored machine data inside the caller's unit of work ``unit``."""
    for tool in unit.list_tools():
        unit.delete_tool(tool["t"])
    for name in unit.offset_names():
        unit.put_offset(name, {"trans": {}, "fine": {}, "rot": {}}, source="scenario",
                        detail={"reason": "reset_data"})
    for record in unit.list_probes():
        unit.put_probe(record["number"], {})
    for record in unit.list_tool_probes():
        unit.put_tool_probe(record["number"], {})
    unit.set_state(STATE_TOOL, None)

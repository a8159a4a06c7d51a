"""The control's machine data that the measuring cycles need (manual ch. 9, §9.1 and §9.3.1).

A real 840D holds these in its NC; the simulated control holds them as commissioned for the
measuring cycles with "Measure in JOG" (the values the manual gives under "当所用测量循环为" /
"在使用JOG中测量时"), and a scenario may set others (``machine.machine_data``: MD number → value)
to play a control that was commissioned wrongly. The commissioning check (app.services.
commissioning) compares them with the manual's rules. Array data (MD 13200[n], MD 20050[i]) are
lists.
"""

from __future__ import annotations

from typing import Any

# MD number -> (name, the value the measuring cycles need / the simulated control has)
MACHINE_DATA: dict[str, tuple[str, Any]] = {
    # §9.1.1 memory configuration (SRAM, DRAM)
    "18118": ("MM_NUM_GUD_MODULES", 7),
    "18120": ("MM_NUM_GUD_NAMES_NCK", 30),
    "18130": ("MM_NUM_GUD_NAMES_CHAN", 130),
    "18150": ("MM_GUD_VALUES_MEM", 28),
    "28082": ("MM_SYSTEM_FRAME_MASK", 0x21),
    "18170": ("MM_NUM_MAX_FUNC_NAMES", 80),
    "18180": ("MM_NUM_MAX_FUNC_PARAM", 800),
    "28020": ("MM_NUM_LUD_NAMES_TOTAL", 200),
    "28040": ("MM_NUM_LUD_VALUES_MEM", 16),
    # §9.1.2 other machine data
    "13200": ("MEAS_PROBE_LOW_ACTIVE", [0, 0]),
    "10132": ("MMC_CMD_TIMEOUT", 3.0),
    "11420": ("LEN_PROTOCOL_FILE", 5),
    # §9.3.1 machine data that make "Measure in JOG" work
    "11602": ("ASUP_START_MASK", 1),
    "11604": ("ASUP_START_PRIO_LEVEL", 100),
    "20050": ("AXCONF_GEOAX_ASSIGN_TAB", [1, 2, 3]),
    "20110": ("RESET_MODE_MASK", 0x4045),
    "20112": ("START_MODE_MASK", 0x400),
    "20310": ("TOOL_MANAGEMENT_MASK", 0),
    "24006": ("CHSFRAME_RESET_MASK", 1),
    "24007": ("CHSFRAME_RESET_CLEAR_MASK", 0),
}


def _value_ok(number: str, value: Any) -> bool:
    default = MACHINE_DATA[number][1]
    if isinstance(default, list):
        return (isinstance(value, list) and len(value) == len(default)
                and all(isinstance(v, int | float) and not isinstance(v, bool) for v in value))
    return isinstance(value, int | float) and not isinstance(value, bool)


def check_machine_data(values: dict[str, Any]) -> dict[str, Any]:
    """``values`` (a scenario's ``machine.machine_data``) checked: known MD numbers, numbers (a list
    of as many for an array datum); a ValueError names the bad entry."""
    for number, value in values.items():
        if number not in MACHINE_DATA:
            raise ValueError(f"machine_data.{number}: unknown machine datum (known: {', '.join(MACHINE_DATA)})")
        if not _value_ok(number, value):
            raise ValueError(f"machine_data.{number}: {MACHINE_DATA[number][0]} must be "
                             f"{'a list of ' + str(len(MACHINE_DATA[number][1])) + ' numbers' if isinstance(MACHINE_DATA[number][1], list) else 'a number'}")
    return values


def machine_data(overrides: dict[str, Any] | None) -> dict[str, Any]:
    """MD number -> value: the commissioned values with the scenario's ``overrides``."""
    data = {number: (list(v) if isinstance(v, list) else v) for number, (_name, v) in MACHINE_DATA.items()}
    data.update(overrides or {})
    return data

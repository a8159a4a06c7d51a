"""Protection levels as in SINUMERIK (design.md §9.2) and the functions that need them.

Level 0 is the highest, 7 the lowest. Levels 1-3 come from a password (1 machine manufacturer,
2 service, 3 user), levels 4-7 from the keyswitch (position 3 -> level 4 ... position 0 -> level 7).
A function is allowed when the acting level is at least as high as the level the function needs,
i.e. ``level <= required``. The required level of each function is a GUD setting
``level_<function>`` (``app.gud.GudSettings``), so the plant can change the table; the defaults
follow Operate: looking, jogging and measuring without writing need nothing (7), writing zero
offsets and tool data a keyswitch position, probe data, calibration, settings and administration a
password.
"""

from __future__ import annotations

from dataclasses import dataclass

HIGHEST, LOWEST = 0, 7
PASSWORD_LEVELS = (1, 2, 3)
TOKEN_LEVELS = tuple(range(1, 8))        # an automation token carries any level but 0 (Siemens only)
KEYSWITCH_POSITIONS = (0, 1, 2, 3)
TRAINER_LEVEL = 1                         # stand-alone trainer: every function, as at level 1

LEVEL_NAMES = {0: "system", 1: "manufacturer", 2: "service", 3: "user",
               4: "keyswitch 3", 5: "keyswitch 2", 6: "keyswitch 1", 7: "keyswitch 0"}


def keyswitch_level(position: int) -> int:
    """Keyswitch position 0..3 -> protection level 7..4."""
    if position not in KEYSWITCH_POSITIONS:
        raise ValueError(f"keyswitch position must be 0..3, got {position!r}")
    return 7 - position


def describe_level(level: int) -> str:
    """"level 5 (keyswitch 2)", "level 3 (user password)"."""
    if level in PASSWORD_LEVELS:
        return f"level {level} ({LEVEL_NAMES[level]} password)"
    return f"level {level} ({LEVEL_NAMES.get(level, '?')})"


def how_to_reach(level: int) -> str:
    """What gives ``level``: a password of level 1..3 (or a higher one), or the keyswitch."""
    if level >= 4:
        return f"keyswitch position {7 - level} or higher, or a password"
    return f"a password of level {level}" + (" or higher" if level > 1 else "")


@dataclass(frozen=True)
class Function:
    key: str
    label: str
    default: int
    covers: str


# The table of functions (README "Access levels"). Every route that changes something names one
# (``app.access.needs``); reads need ``view``.
FUNCTIONS: dict[str, Function] = {f.key: f for f in (
    Function("view", "View screens and data", 7,
             "every screen, every GET of the API"),
    Function("jog", "Jog and position", 7,
             "jog, go to, feed override, Reset/stop, tool change, raw probe move, activate a zero offset, "
             "machine control panel, set-up support (activate, swivel)"),
    Function("measure", "Measure", 7,
             "measuring sessions, NC Start, Calculate with target measure_only, PLC interface bits"),
    Function("offsets", "Write zero offsets", 5,
             "zero-offset table, PUT /api/offsets, measuring into a zero offset, restoring an offset "
             "change, EV/MV memories"),
    Function("tools", "Write tool data", 5,
             "tool table, PUT/DELETE /api/tools, tool measuring into the tool data"),
    Function("probe_data", "Probe data", 3,
             "workpiece and tool probe records (screens, PUT /api/probes, /api/tool-probes)"),
    Function("calibration", "Probe calibration", 3,
             "calibrate the workpiece probe (length, radius) and the tool probe"),
    Function("settings", "Settings", 3,
             "the measuring settings (GUD), PLC mode; a write route that names no function"),
    Function("keyswitch", "Turn the keyswitch", 3,
             "turn the simulated keyswitch from the HMI (PUT /api/keyswitch)"),
    Function("scenario", "Load a scenario", 2,
             "POST /api/sim/scenario (reset_data wipes the stored data)"),
    Function("users", "User administration", 1,
             "users and API tokens (/api/users, /api/tokens), the access-level table (level_* settings)"),
)}

# a write route that declares no function needs this one (safe by default; tests/access checks
# that every write route declares one)
UNDECLARED_WRITE = "settings"


def setting_name(function: str) -> str:
    return f"level_{function}"


def required_level(gud, function: str) -> int:
    """The level ``function`` needs: the GUD setting, or the default when the settings lack it."""
    spec = FUNCTIONS[function]
    return int(getattr(gud, setting_name(function), spec.default))

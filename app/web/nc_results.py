"""What the NC program's results mean (``_OVR[n]``, ``_OVI[n]``): the meaning next to each index,
in the operator's language.

The result tables are the manual's, as the measuring cycles of this HMI write them
(app/nc/cycles: workpiece.py, calibration.py, sphere.py, kinematics.py, base.common_results;
measuring-math.md §3.2, §4.2, §7–§13). The cycle that wrote them is ``_OVI[2]``, its variant
``_OVI[3]``; an index the table does not name is shown with its index only.
"""

from __future__ import annotations

from app.i18n import N_, _

ABSCISSA, ORDINATE, APPLICATE = N_("abscissa"), N_("ordinate"), N_("applicate")
AOP = (ABSCISSA, ORDINATE, APPLICATE)
Table = dict[int, tuple[str, ...]]       # index -> (text, axis word, ...)

# _OVI: the same for every cycle (manual: result parameters of the measuring cycles)
OVI = {0: N_("D number / ZO number"), 2: N_("measuring cycle"), 3: N_("measuring variant"),
       4: N_("weighting factor k"), 5: N_("probe number"), 6: N_("mean value memory"),
       7: N_("empirical value memory"), 8: N_("tool number"), 9: N_("alarm number"),
       11: N_("correction written (1 = yes)")}

# _OVR[20], [27..31] of the workpiece cycles' tool-offset strategy (measuring-math §4.2)
_STRATEGY: Table = {20: (N_("compensation value"),), 27: (N_("zero offset range"),), 28: (N_("safe area"),),
             29: (N_("dimension difference"),), 30: (N_("empirical value"),), 31: (N_("mean value"),)}

# one meaning = (text,) or (text, axis word): "setpoint centre" + "abscissa"
_SIZE_AND_CENTRE: Table = {0: (N_("setpoint diameter / width"),), 1: (N_("setpoint centre"), ABSCISSA),
                    2: (N_("setpoint centre"), ORDINATE), 4: (N_("actual diameter / width"),),
                    5: (N_("actual centre"), ABSCISSA), 6: (N_("actual centre"), ORDINATE),
                    8: (N_("upper tolerance"),), 12: (N_("lower tolerance"),),
                    16: (N_("difference diameter / width"),), 17: (N_("difference centre"), ABSCISSA),
                    18: (N_("difference centre"), ORDINATE), **_STRATEGY}
_RECTANGLE: Table = {0: (N_("setpoint length"), ABSCISSA), 1: (N_("setpoint length"), ORDINATE),
              2: (N_("setpoint centre"), ABSCISSA), 3: (N_("setpoint centre"), ORDINATE),
              4: (N_("actual length"), ABSCISSA), 5: (N_("actual length"), ORDINATE),
              6: (N_("actual centre"), ABSCISSA), 7: (N_("actual centre"), ORDINATE),
              8: (N_("upper tolerance"), ABSCISSA), 9: (N_("upper tolerance"), ORDINATE),
              12: (N_("lower tolerance"), ABSCISSA), 13: (N_("lower tolerance"), ORDINATE),
              16: (N_("difference length"), ABSCISSA), 17: (N_("difference length"), ORDINATE),
              18: (N_("difference centre"), ABSCISSA), 19: (N_("difference centre"), ORDINATE), **_STRATEGY}
_POINT: Table = {0: (N_("setpoint"),), 1: (N_("setpoint position"), ABSCISSA), 2: (N_("setpoint position"), ORDINATE),
          3: (N_("setpoint position"), APPLICATE), 4: (N_("actual value"),), 8: (N_("upper tolerance"),),
          12: (N_("lower tolerance"),), 16: (N_("difference"),), **_STRATEGY}
_ANGLE: Table = {0: (N_("setpoint angle"),), 4: (N_("actual angle"),), 16: (N_("angle difference"),),
          20: (N_("angle correction"),), 28: (N_("safe area"),)}
_CORNER: Table = {4: (N_("angle of the edge (WCS)"),), 5: (N_("corner"), ABSCISSA), 6: (N_("corner"), ORDINATE),
           20: (N_("angle of the edge (MCS)"),), 21: (N_("corner (MCS)"), ABSCISSA),
           22: (N_("corner (MCS)"), ORDINATE)}
# trigger values per travel direction and their differences (app/nc/cycles/calibration TRIGGER_SLOTS)
_TRIGGERS: Table = {}
for _i, _axis in enumerate(AOP):
    for _j, _sign in enumerate(("−", "+")):
        _slot = 8 + 4 * _i + 2 * _j
        _TRIGGERS[_slot] = (N_("trigger value %(direction)s"), _axis, _sign)
        _TRIGGERS[_slot + 1] = (N_("difference trigger value %(direction)s"), _axis, _sign)
_PROBE_CALIBRATION: Table = {**_TRIGGERS, 4: (N_("effective ball diameter"),),
                      5: (N_("difference effective ball diameter"),), 6: (N_("centre"), ABSCISSA),
                      7: (N_("centre"), ORDINATE), 20: (N_("position deviation"), "X"),
                      21: (N_("position deviation"), "Y"), 27: (N_("zero offset range"),), 28: (N_("safe area"),)}
_PROBE_LENGTH: Table = {8: (N_("probe length"),), 9: (N_("difference probe length"),), 27: (N_("zero offset range"),),
                 28: (N_("safe area"),)}
_TOOL_PROBE: Table = {**_TRIGGERS, 27: (N_("zero offset range"),), 28: (N_("safe area"),)}
_TOOL: Table = {8: (N_("tool length"),), 9: (N_("difference tool length"),), 10: (N_("tool radius"),),
         11: (N_("difference tool radius"),), 27: (N_("zero offset range"),), 28: (N_("safe area"),),
         29: (N_("dimension difference"),)}
_SPHERES: Table = {0: (N_("setpoint diameter"),), 28: (N_("safe area"),)}
for _i, _slot in enumerate(range(1, 4)):
    _SPHERES[_slot] = (N_("setpoint centre"), AOP[_i])
for _k, (_d, _c, _dd, _cd) in enumerate(((4, 5, 8, 9), (12, 13, 16, 17), (20, 21, 24, 25)), start=1):
    _SPHERES[_d] = (N_("diameter sphere %(n)s"), "", str(_k))
    _SPHERES[_dd] = (N_("difference diameter sphere %(n)s"), "", str(_k))
    for _i in range(3):
        _SPHERES[_c + _i] = (N_("centre sphere %(n)s"), AOP[_i], str(_k))
        _SPHERES[_cd + _i] = (N_("difference centre sphere %(n)s"), AOP[_i], str(_k))
_KINEMATICS: Table = {9: (N_("axis offset"),), 10: (N_("direction error (µrad)"),),
                                           11: (N_("circle residual"),), 12: (N_("sphere diameter"),)}
for _i, _axis in enumerate("XYZ"):
    _KINEMATICS[_i] = (N_("point on the rotary axis"), _axis)
    _KINEMATICS[3 + _i] = (N_("direction of the rotary axis"), _axis)
    _KINEMATICS[6 + _i] = (N_("deviation of the point"), _axis)


def ovr_table(cycle: int, variant: int) -> Table:
    """The meanings of _OVR for the cycle ``_OVI[2]`` and its variant ``_OVI[3]``."""
    if cycle == 977:
        return _RECTANGLE if variant % 10 in (5, 6) else _SIZE_AND_CENTRE
    if cycle == 979:
        return _SIZE_AND_CENTRE
    if cycle == 978:
        return _POINT
    if cycle == 998:
        return _ANGLE
    if cycle == 961:
        return _CORNER
    if cycle == 976:
        return _PROBE_LENGTH if variant == 10000 else _PROBE_CALIBRATION
    if cycle == 971:
        return _TOOL_PROBE if variant in (0, 100000) else _TOOL
    if cycle == 997:
        return _SPHERES
    if cycle == 996:
        return _KINEMATICS
    return {}


def meaning_text(entry: tuple[str, ...]) -> str:
    """An entry in the screen's language: the text, then its axis word ("actual centre abscissa")."""
    text, axis, extra = (*entry, "", "")[:3]
    if "%(direction)s" in text:
        return _(text) % {"direction": extra + _(axis)}
    if "%(n)s" in text:
        return _(text) % {"n": extra} + (f" {_(axis)}" if axis else "")
    return _(text) + (f" {_(axis)}" if axis else "")


def results(values: dict) -> list[dict]:
    """The non-zero _OVR/_OVI elements of the last cycle, each with its meaning ('' when none)."""
    ovr, ovi = list(values.get("_OVR") or []), list(values.get("_OVI") or [])
    cycle = int(ovi[2]) if len(ovi) > 2 else 0
    variant = int(ovi[3]) if len(ovi) > 3 else 0
    table = ovr_table(cycle, variant)
    out = [{"name": f"_OVR[{i}]", "value": f"{v:.4f}", "meaning": meaning_text(table[i]) if i in table else ""}
           for i, v in enumerate(ovr) if v]
    out += [{"name": f"_OVI[{i}]", "value": str(v), "meaning": _(OVI[i]) if i in OVI else ""}
            for i, v in enumerate(ovi) if v]
    return out


def cycle_name(values: dict) -> str:
    """CYCLE977 etc. from ``_OVI[2]`` ('' when no cycle wrote results)."""
    ovi = list(values.get("_OVI") or [])
    return f"CYCLE{int(ovi[2])}" if len(ovi) > 2 and ovi[2] else ""

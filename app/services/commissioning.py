"""The start-up checks a commissioning engineer runs for the measuring cycles (manual ch. 9–10).

Each check names the manual's section, the machine datum (MD, §9.1/§9.3.1) or the cycle data
(GUD5/GUD6, §9.2; GUD7 "Measure in JOG", §9.3.2/§10.3) it reads, the value found in the NC, the
manual's rule and whether the value keeps it. The machine data come from the control
(``app.machine.protocol.MachineData``; a control without them: those checks are not run, ``ok``
None); the cycle data from the NC channel's variables (``app.services.nc``) and the GUD7 settings.

Like the readiness checklist (app.services.readiness) this module only reports. The rule is an
English catalogue text with its parameters (``rule`` + ``params``): the JSON API gives it
formatted in English, the screen in the operator's language.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from app.i18n import N_
from app.machine.machine_data import MACHINE_DATA
from app.machine.protocol import MachineData


@dataclass(frozen=True)
class CommissioningCheck:
    id: str
    group: str                  # "machine_data" | "cycle_data"
    section: str                # the manual's section, "§9.1.1"
    item: str                   # "MD 18130 MM_NUM_GUD_NAMES_CHAN", "_CVAL[1]"
    value: Any                  # what the NC holds
    rule: str                   # catalogue text (English), ``params`` fill it
    ok: bool | None             # None: not checked (the control gives no machine data)
    params: dict[str, Any] = field(default_factory=dict)
    alarm: int | None = None    # the cycle alarm a failure leads to, if the manual names one
    mask: bool = False          # a bit mask: shown in hex as the manual writes it (21H)

    def shown(self) -> str:
        """The value as the screen shows it: a mask in hex ("4045H"), a list with commas."""
        if self.value is None:
            return "–"
        if self.mask and isinstance(self.value, int | float):
            return f"{int(self.value):X}H"
        if isinstance(self.value, list):
            return ", ".join(f"{v:g}" if isinstance(v, float) else str(v) for v in self.value)
        return f"{self.value:g}" if isinstance(self.value, float) else str(self.value)

    def rule_text(self, translate=None) -> str:
        text = translate(self.rule) if translate else self.rule
        return text % self.params if self.params else text

    def to_api(self) -> dict[str, Any]:
        return {"id": self.id, "group": self.group, "section": self.section, "item": self.item,
                "value": self.value, "rule": self.rule_text(), "ok": self.ok, "alarm": self.alarm}


def _bits(mask: int) -> str:
    return ", ".join(str(b) for b in range(16) if mask >> b & 1)


# MD number -> (section, kind, argument): the manual's value "for the measuring cycles"
MD_RULES: dict[str, tuple[str, str, Any]] = {
    "18118": ("§9.1.1", "min", 7), "18120": ("§9.1.1", "min", 30), "18130": ("§9.1.1", "min", 130),
    "18150": ("§9.1.1", "min", 28), "28082": ("§9.1.1", "bits_set", 0x20), "18170": ("§9.1.1", "min", 80),
    "18180": ("§9.1.1", "min", 800), "28020": ("§9.1.1", "min", 200), "28040": ("§9.1.1", "min", 16),
    "13200": ("§9.1.2", "all_equal", 0), "10132": ("§9.1.2", "min", 3.0), "11420": ("§9.1.2", "min", 5),
    "11602": ("§9.3.1", "bits_set", 0x1), "11604": ("§9.3.1", "range", (1, 0x64)),
    "20050": ("§9.3.1", "assigned", 3), "20110": ("§9.3.1", "bits_set", 0x4045),
    "20112": ("§9.3.1", "bits_clear", 0x40), "20310": ("§9.3.1", "tool_management", 0x4001),
    "24006": ("§9.3.1", "bits_set", 0x1), "24007": ("§9.3.1", "bits_clear", 0x1),
}
MD_ALARMS = {"28082": 61016}

RULE_TEXTS = {
    "min": N_("at least %(min)s"),
    "bits_set": N_("bit %(bits)s = 1"),
    "bits_clear": N_("bit %(bits)s = 0"),
    "all_equal": N_("every input %(value)s (FALSE: not deflected = 0 V)"),
    "range": N_("from %(min)s to %(max)s"),
    "assigned": N_("%(count)s geometry axes assigned"),
    "tool_management": N_("with tool management (bit 0 = 1) also bit 14 = 1"),
}


def _number(value: Any) -> float:
    return float(value) if isinstance(value, int | float) and not isinstance(value, bool) else float("nan")


def _md_ok(kind: str, arg: Any, value: Any) -> tuple[bool, dict[str, Any]]:
    """(the value keeps the rule, the rule's parameters)."""
    if kind == "min":
        return _number(value) >= arg, {"min": arg}
    if kind in ("all_equal", "assigned"):
        items = list(value) if isinstance(value, list) else [value]
        if kind == "all_equal":
            return all(_number(v) == arg for v in items), {"value": arg}
        return sum(1 for v in items if _number(v) > 0) >= arg, {"count": arg}
    if kind == "range":
        return arg[0] <= _number(value) <= arg[1], {"min": arg[0], "max": arg[1]}
    word = int(_number(value)) if _number(value) == _number(value) else 0
    if kind == "bits_set":
        return word & arg == arg, {"bits": _bits(arg)}
    if kind == "bits_clear":
        return word & arg == 0, {"bits": _bits(arg)}
    return not word & 1 or word & arg == arg, {}          # tool management: bit 0 -> bit 14


def machine_data_checks(machine: Any) -> list[CommissioningCheck]:
    """§9.1.1, §9.1.2, §9.3.1: each machine datum against the manual's value for the measuring cycles."""
    values = machine.machine_data() if isinstance(machine, MachineData) else None
    out = []
    for number, (section, kind, arg) in MD_RULES.items():
        name = MACHINE_DATA[number][0]
        if values is None:
            ok, params, value = None, _md_ok(kind, arg, None)[1], None
        else:
            value = values.get(number)
            ok, params = _md_ok(kind, arg, value)
        out.append(CommissioningCheck(f"md{number}", "machine_data", section, f"MD {number} {name}", value,
                                      RULE_TEXTS[kind], ok, params, MD_ALARMS.get(number),
                                      mask=kind.startswith("bits") or kind == "tool_management"))
    return out


def _rows(value: Any) -> int:
    return len(value) if isinstance(value, list) else 0


def _cycle_data(read) -> list[CommissioningCheck]:
    """§9.2: the record counts _CVAL and _EVMVNUM against the arrays they size (61416), _SPEED."""
    cval, sizes = read("_CVAL"), read("_EVMVNUM")
    out = []
    for i, array in enumerate(("_TP", "_WP", "_KB", "_TPW")):
        rows = _rows(read(array))
        out.append(CommissioningCheck(f"cval{i}", "cycle_data", "§9.2", f"_CVAL[{i}]", cval[i],
                                      N_("= the records of %(array)s (%(rows)s)"), cval[i] == rows,
                                      {"array": array, "rows": rows}, 61416))
    for i, array in enumerate(("_EV", "_MV")):
        rows = _rows(read(array))
        out.append(CommissioningCheck(f"evmvnum{i}", "cycle_data", "§9.2", f"_EVMVNUM[{i}]", sizes[i],
                                      N_("= the records of %(array)s (%(rows)s)"), sizes[i] == rows,
                                      {"array": array, "rows": rows}))
    speed = read("_SPEED")
    out.append(CommissioningCheck("speed0", "cycle_data", "§9.2", "_SPEED[0]", speed[0],
                                  N_("from %(min)s to %(max)s"), 0 < speed[0] <= 100, {"min": 1, "max": 100}))
    out.append(CommissioningCheck("speed", "cycle_data", "§9.2", "_SPEED[1..3]", list(speed[1:4]),
                                  N_("greater than 0"), all(v > 0 for v in speed[1:4])))
    types = [int(row[8]) for row in read("_TP")]
    out.append(CommissioningCheck("tp_type", "cycle_data", "§9.2", "_TP[k,8]", types,
                                  N_("0 cube, 101 disc in XY, 201 in ZX, 301 in YZ"),
                                  all(t in (0, 101, 201, 301) for t in types)))
    return out


def _jog_data(settings, read) -> list[CommissioningCheck]:
    """§10.3: the probe numbers of "Measure in JOG" (GUD7 _JM_I[1], _JM_I[2]) have their records."""
    cval = read("_CVAL")
    rule = N_("from 1 to %(item)s = %(max)s")
    return [
        CommissioningCheck("jm_probe", "cycle_data", "§10.3", "_JM_I[1]", settings.probe_number, rule,
                           1 <= settings.probe_number <= cval[1], {"item": "_CVAL[1]", "max": cval[1]}, 61416),
        CommissioningCheck("jm_tool_probe", "cycle_data", "§10.3", "_JM_I[2]", settings.tool_probe_number, rule,
                           1 <= settings.tool_probe_number <= cval[0], {"item": "_CVAL[0]", "max": cval[0]}, 61416),
    ]


class CommissioningService:
    def __init__(self, services):
        self._services = services

    def checks(self) -> list[CommissioningCheck]:
        s = self._services
        out = machine_data_checks(s.machine.machine)
        if s.nc is not None:
            read = s.nc.variables.read
            out += [*_cycle_data(read), *_jog_data(s.settings.get(), read)]
        return out

    def report(self) -> dict[str, Any]:
        checks = self.checks()
        return {"ok": all(c.ok is not False for c in checks),
                "failed": sum(1 for c in checks if c.ok is False),
                "checks": [c.to_api() for c in checks]}

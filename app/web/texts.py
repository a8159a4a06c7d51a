"""Operator texts the screens make from data: alarm texts in the screen's language, channel states,
increments, and the messages of the services (English, the JSON API's) in the operator's words.

Alarms: the manual's Chinese text is ``engine.alarms`` ``text_zh``; German (and any other) comes
from the catalogue with the English text as its msgid (``scripts/i18n.py`` extracts every alarm
of the catalogue). Messages: the services raise English texts (the API's contract); the screens
translate them here by message catalogue: ``MESSAGES`` holds each message's pattern and its
catalogue text, whose ``%(field)s`` is the field's operator name (``field_label``), never a key.
"""

from __future__ import annotations

import re

from app.i18n import N_, _, format_fixed, language
from app.web import units
from engine import alarms as catalogue

PROGRAM_STATES = {"active": N_("active"), "interrupted": N_("interrupted"), "reset": N_("reset")}
VERDICTS = {"ok": N_("OK"), "rework": N_("rework"), "scrap": N_("scrap"), "not_decidable": N_("not decidable")}


def _definition(code, text: str | None):
    try:
        number = int(code)
    except (TypeError, ValueError):
        return None
    same = [a for a in catalogue.all_alarms() if a.number == number]
    for alarm in same:
        if text is not None and alarm.text == text:
            return alarm
    return catalogue.by_number(number) if text is None or not same else None


def alarm_text(alarm) -> str:
    """The text of an alarm (``{"code", "text"}`` or an AlarmDef) in the screen's language."""
    if isinstance(alarm, catalogue.AlarmDef):
        code, text = alarm.number, alarm.text
    else:
        code, text = alarm.get("code"), alarm.get("text")
    definition = _definition(code, text)
    if definition is None:
        return _(text) if text else ""
    if language() == "zh":
        return definition.text_zh
    return _(definition.text)


def alarm_remedy(alarm) -> str:
    code = alarm.number if isinstance(alarm, catalogue.AlarmDef) else alarm.get("code")
    text = alarm.text if isinstance(alarm, catalogue.AlarmDef) else alarm.get("text")
    definition = _definition(code, text) or _definition(code, None)
    return _(definition.remedy) if definition is not None else ""


def program_state_text(state: str) -> str:
    return _(PROGRAM_STATES.get(state, state))


def verdict_text(verdict: str) -> str:
    """A part's or characteristic's verdict in the operator's language (design.md §10.3)."""
    return _(VERDICTS.get(verdict, verdict))


def increment_text(increment: str, gud) -> str:
    """One INC step of the control panel in the screen's unit: 1 µm = INC 1 in mm, 0.0001 inch in
    inch (Operate: the increment counts in the unit's smallest displayed step)."""
    try:
        steps = int(increment)
    except ValueError:
        return increment
    if units.is_inch(gud):
        return f"{units.format_fixed(steps * 0.0001, 4)} inch"
    return f"{steps} µm"


# --- messages of the services, in the operator's words ---------------------------------------------

# (pattern of the English message, catalogue text); named groups fill the catalogue text; a group
# called "field" is a parameter key and becomes the field's operator name (``field_label``).
MESSAGES: list[tuple[re.Pattern, str]] = []


def message(pattern: str, text: str) -> None:
    MESSAGES.append((re.compile(pattern + r"\Z", re.S), text))


ALARM_IN_MESSAGE = re.compile(r"(?P<code>\d{5}) (?P<rest>.*)\Z", re.S)


def translate_message(text: str | None, field_label=None) -> str:
    """A service's English message as the operator reads it. ``field_label(key)`` gives the
    operator's name of a parameter key (the screen knows its fields)."""
    if not text:
        return ""
    text = str(text)
    for pattern, msgid in MESSAGES:
        match = pattern.match(text)
        if match:
            params = {}
            for name, value in match.groupdict().items():
                if value is None:
                    value = ""
                if name == "field" or name.startswith("field_"):
                    value = _label_of(value, field_label)
                elif name == "alarm":
                    value = translate_message(value, field_label)
                params[name] = value
            return _(msgid) % params
    alarm = ALARM_IN_MESSAGE.match(text)
    if alarm:
        code, rest = alarm.group("code"), alarm.group("rest")
        for definition in (a for a in catalogue.all_alarms() if a.number == int(code)):
            if rest == definition.text:
                return f"{code} {alarm_text(definition)}"
            if rest.startswith(definition.text):
                tail = rest[len(definition.text):]
                return f"{code} {alarm_text(definition)}{_tail(tail, field_label)}"
    return _(text)


def _tail(tail: str, field_label) -> str:
    """What a message adds after an alarm text (": press Reset first")."""
    if not tail:
        return ""
    if tail.startswith(": "):
        return ": " + translate_message(tail[2:], field_label)
    return translate_message(tail, field_label)


FIELD_NAMES = {
    # parameter keys of the JSON API -> operator names (the screens' field labels where they have one)
    "trans": N_("translation"), "rot": N_("rotation"), "fine": N_("fine offset"),
    "length": N_("length"), "radius": N_("radius"), "wear.length": N_("wear length"),
    "wear.radius": N_("wear radius"), "type": N_("tool type"), "name": N_("name"),
    "ball_diameter": N_("ball diameter"), "effective_diameter": N_("effective ball diameter"),
    "disc_diameter": N_("disc diameter"), "dz": N_("upper edge to tool lower edge"),
    "axes": N_("axes code"), "tool": N_("tool"), "skew": N_("skew"), "trigger": N_("trigger value"),
    "diameter": N_("diameter"), "setpoint": N_("setpoint"), "target": N_("zero offset"),
    "setpoint_angle": N_("setpoint angle"), "infeed": N_("infeed DZ"), "width": N_("width"),
    "probe_angle": N_("probing angle"), "offset_v": N_("offset V"), "points": N_("number of points"),
    "position": N_("corner position"), "axis": N_("axis"), "direction": N_("direction"),
}


def field_name(key: str) -> str:
    """An API key (``trans.Y``, ``wear.radius``, ``trigger.X+``) as the operator's name."""
    if key in FIELD_NAMES:
        return _(FIELD_NAMES[key])
    part, _sep, rest = key.partition(".")
    if part in ("trans", "rot", "fine") and rest:
        return f"{_(FIELD_NAMES[part])} {rest}"
    if part == "trigger" and rest:
        return _("trigger value %(direction)s", direction=rest)
    if part in FIELD_NAMES and rest:
        return f"{_(FIELD_NAMES[part])} {rest}"
    return key


def _label_of(key: str, field_label) -> str:
    if field_label is not None:
        label = field_label(key)
        if label:
            return label
    return field_name(key)


# the service messages (app/services, app/workflow, engine.params), most specific first
message(r"(?P<field>[\w.+\-\[\]]+): '(?P<value>.*)' is not a number", N_("%(field)s: enter a number"))
# the channel's mode group (app/services/nc.py, app/workflow/service.py)
message(r"Program (?P<program>\S+) runs in (?P<mode>MDA|AUTO): locked until the program ends "
        r"\(NC Stop holds it, Reset ends it\)",
        N_("Program %(program)s runs in %(mode)s: locked until the program ends (NC Stop holds it, Reset ends it)"))
message(r"The JOG measurement (?P<program>\S+) runs: a program starts when it has ended \(Reset ends it\)",
        N_("The JOG measurement %(program)s runs: a program starts when it has ended (Reset ends it)"))
message(r"(?P<field>[\w.+\-\[\]]+): must be a finite number", N_("%(field)s: enter a number"))
message(r"(?P<field>[\w.+\-\[\]]+) must be a number, got .*", N_("%(field)s: enter a number"))
message(r"(?P<field>[\w.+\-\[\]]+) must be a finite number, got .*", N_("%(field)s: enter a number"))
message(r"(?P<field>[\w.+\-\[\]]+) is required", N_("%(field)s: enter a value"))
message(r"(?P<field>[\w.+\-\[\]]+) must be > 0, got (?P<value>.*)",
        N_("%(field)s: enter a value greater than 0"))
message(r"(?P<field>[\w.+\-\[\]]+) must be >= 0, got (?P<value>.*)", N_("%(field)s: enter 0 or more"))
message(r"(?P<field>[\w.+\-\[\]]+) must lie within ±(?P<limit>[\d.e+]+), got .*",
        N_("%(field)s: enter a value within ±%(limit)s"))
message(r"(?P<field>[\w.+\-\[\]]+) must be one of (?P<choices>.*), got .*",
        N_("%(field)s: choose one of %(choices)s"))
message(r"(?P<field>[\w.+\-\[\]]+) must lie in \(-360, 360\), got .*",
        N_("%(field)s: enter an angle between -360° and 360°"))
message(r"(?P<field>[\w.+\-\[\]]+) is locked while a point is stored",
        N_("%(field)s cannot be changed while a point is stored"))
message(r"unknown zero offset '(?P<name>.*)'", N_("There is no zero offset %(name)s"))
message(r"a measurement is running; press Reset first", N_("A measurement is running: press Reset first"))
message(r"a measurement is running", N_("A measurement is running"))
message(r"a measurement is already running", N_("A measurement is already running"))
message(r"a measurement or Calculate is running", N_("A measurement or Calculate is running"))
message(r"the machine is moving", N_("The machine is moving"))
message(r"all points are stored: press Calculate or invalidate a point",
        N_("All points are stored: press Calculate or invalidate a point"))
message(r"Calculate needs all points stored; missing (?P<points>.*)",
        N_("Calculate needs all points stored; missing %(points)s"))
message(r"Calculate needs all points stored", N_("Calculate needs all points stored"))
message(r"this task computes on NC Start; there is no Calculate",
        N_("This function calculates on NC Start; there is no Calculate"))
message(r"(?P<field>[\w.+\-\[\]]+): unknown axis \(allowed: (?P<allowed>.*)\)",
        N_("%(field)s: this axis does not exist here (allowed: %(allowed)s)"))
message(r"the set-up support was already carried out or left",
        N_("The set-up support was already carried out or left"))
message(r"(?P<alarm>.*): press Reset first", N_("%(alarm)s: press Reset first"))
message(r"T(?P<t>\d+) is in the spindle; change the tool first",
        N_("T%(t)s is in the spindle: change the tool first"))
message(r"T(?P<t>\d+) is not in the tool table", N_("T%(t)s is not in the tool table"))
message(r"T(?P<t>\d+) exists already", N_("T%(t)s exists already"))
message(r"T: '(?P<value>.*)' is not a tool number", N_("T: enter a tool number"))
message(r"'(?P<value>.*)' is not a tool number", N_("Enter a tool number"))
message(r"'(?P<value>.*)' is not a whole number", N_("Enter a whole number"))
message(r"'(?P<value>.*)' is not a number", N_("Enter a number"))
message(r"required", N_("Enter a value"))
message(r"each digit must be 0 \(no\), 1 \(minus\), 2 \(plus\) or 3 \(both\)",
        N_("Each digit must be 0 (no), 1 (minus), 2 (plus) or 3 (both)"))
message(r"the tool axis \(hundreds digit\) must allow the minus direction",
        N_("The tool axis (hundreds digit) must allow the minus direction"))
message(r"must be negative: travel \+(?P<axis>\w) switches with the ball centre before the wall",
        N_("Must be negative: travelling +%(axis)s the probe switches with the ball centre before the wall"))
message(r"must be positive: travel −(?P<axis>\w) switches with the ball centre past the wall",
        N_("Must be positive: travelling −%(axis)s the probe switches with the ball centre past the wall"))
message(r"Input should be greater than (?P<limit>.*)", N_("Enter a value greater than %(limit)s"))
message(r"Input should be greater than or equal to (?P<limit>.*)", N_("Enter %(limit)s or more"))
message(r"Input should be less than or equal to (?P<limit>.*)", N_("Enter %(limit)s or less"))
message(r"Input should be less than (?P<limit>.*)", N_("Enter a value less than %(limit)s"))
message(r"Input should be a valid number.*", N_("Enter a number"))
message(r"Input should be a valid integer.*", N_("Enter a whole number"))
message(r"Input should be (?P<choices>'.*)", N_("Choose %(choices)s"))
message(r"Not saved: (?P<n>\d+) field\(s\) need correction", N_("Not saved: %(n)s field(s) need correction"))
message(r"Select an increment \(INC\) for a single jog step", N_("Select an increment (INC) for a single jog step"))
message(r"Feed override must be 0\.\.120 %", N_("Feed override must be 0..120 %%"))
message(r"Tilted part: orient plane measured (?P<tilt>[-\d.]+)° for (?P<target>\S+), which the control cannot hold "
        r"\(61321\): a measurement in the machine's plane is off by the tilt; align the part on the table",
        N_("Tilted part: orient plane measured %(tilt)s° for %(target)s, which the control cannot hold (61321): a "
           "measurement in the machine's plane is off by the tilt; align the part on the table"))
# probe trust (app.workflow.probe_trust): the tail after the alarm text
message(r"length (?P<axis>\w)-: calibrate the probe length on a known surface first",
        N_("length %(axis)s-: calibrate the probe length on a known surface first"))
message(r"radius: calibrate the probe in the ring gauge first", N_("radius: calibrate the probe in the ring gauge first"))
message(r"direction (?P<keys>.+): calibrate the probe in the ring gauge in this plane first",
        N_("direction %(keys)s: calibrate the probe in the ring gauge in this plane first"))


# --- states and names the screens show ---------------------------------------------------------------

NC_STATES = {"idle": N_("idle"), "ready": N_("ready"), "running": N_("running"), "stopped": N_("stopped"),
             "done": N_("done"), "alarm": N_("alarm"), "single_block": N_("single block"),
             "nc_stop": N_("NC Stop"), "reset": N_("reset"), "m0": N_("programmed stop M0"),
             "m30": N_("end of program")}
AUDIT_SOURCES = {"screen": N_("screen"), "api": N_("API"), "measurement": N_("measurement"),
                 "undo": N_("undo"), "scenario": N_("scenario"), "calibration": N_("calibration"),
                 "nc": N_("part program"), "setup_support": N_("set-up support")}
LOG_STATUS = {"ok": N_("ok"), "alarm": N_("alarm"), "aborted": N_("aborted"), "refused": N_("refused")}


def nc_state_text(state) -> str:
    return _(NC_STATES[state]) if state in NC_STATES else str(state or "").replace("_", " ")


def source_text(source) -> str:
    return _(AUDIT_SOURCES[source]) if source in AUDIT_SOURCES else str(source or "")


def log_status_text(status) -> str:
    return _(LOG_STATUS[status]) if status in LOG_STATUS else str(status or "")


# texts of the services that reach the screens as they are (their msgid is the English text)
SERVICE_TEXTS = (
    N_("You are compensating in an inactive WO!"), N_("The new WCS needs a new alignment!"),
    N_("Rotary axis must be positioned!"), N_("Press NC Start to activate!"),
    N_("Re-alignment of the probe is not possible on this machine (no swivel kinematics): "
       "measuring continues with the probe as it is"),
    N_("Activate compensated WO"), N_("Re-align probe"), N_("Retract before swivel"),
    N_("Position rotary axis"),
    N_("Retract along the tool axis to the limit before swivelling (manual toggle field 3: "
       "\u7a7a\u8fd0\u884c, dry run / traverse-free motion)"),
    N_("Left without activating: the compensation stays written in the WO"),
    N_("Measurement aborted by Reset"),
    N_("Measure only"),
    # app.workflow.finish_probe.UNDECIDED_FRAME
    N_("The ring passes cannot tell whether the pre-travel turns with the spindle: calibrated as turning with it"),
    N_("The ring passes cannot tell whether the pre-travel turns with the spindle: "
       "calibrated as fixed to the machine axes"),
)
message(r"(?P<wo>\S+) activated: it is the WO of the next measurement",
        N_("%(wo)s activated: it is the WO of the next measurement"))
message(r"Probe re-aligned: tool axis parallel to (?P<axis>\S+) of (?P<wo>\S+) \(head (?P<angles>.*)\)",
        N_("Probe re-aligned: tool axis parallel to %(axis)s of %(wo)s (head %(angles)s)"))
message(r"Position rotary axis (?P<axis>\S+)", N_("Position rotary axis %(axis)s"))
message(r"WCS rotated around (?P<axes>.*)", N_("WCS rotated around %(axes)s"))


# --- labels of the measuring fields (app/workflow/forms.py; plain ones are extracted from there) ------

LABELS: list[tuple[re.Pattern, str]] = [
    (re.compile(r"Setpoint (?P<axis>\w+)0 \((?P<of>.*)\)\Z"), N_("Setpoint %(axis)s0 (%(of)s)")),
    (re.compile(r"Length L \((?P<axis>\w+)\)\Z"), N_("Length L (%(axis)s)")),
    (re.compile(r"Width W \((?P<axis>\w+)\)\Z"), N_("Width W (%(axis)s)")),
    (re.compile(r"Calibration height (?P<axis>\w+)\Z"), N_("Calibration height %(axis)s")),
    (re.compile(r"Rotary axis (?P<axis>\w+)\Z"), N_("Rotary axis %(axis)s")),
    (re.compile(r"Basic frame (?P<n>\w+)\Z"), N_("Basic frame %(n)s")),
    # the lathe's values (app/workflow/forms.py lathe_form): radius or diameter, by the label's suffix
    (re.compile(r"(?P<label>.+) \(radius\)\Z"), N_("%(label)s (radius)")),
    (re.compile(r"(?P<label>.+) \(radius on X\)\Z"), N_("%(label)s (radius on X)")),
    (re.compile(r"(?P<label>.+) \(Ø on X\)\Z"), N_("%(label)s (Ø on X)")),
    (re.compile(r"(?P<label>.+) \(Ø\)\Z"), N_("%(label)s (Ø)")),
]
FIELD_TEXTS = (   # labels and choices that are built in code (variables, not FieldSpec arguments)
    N_("Setpoint (nominal size)"), N_("Upper tolerance"), N_("Lower tolerance"), N_("Zero offset range"),
    N_("Mean value range"), N_("Dimension difference"), N_("Safe area"), N_("Weighting factor k"),
    N_("Empirical / mean value memory"), N_("Direction"), N_("Direction P1"), N_("Direction P2"),
    N_("Axis"), N_("Coordinate rotation"), N_("Tool offset"), N_("Basic reference"), N_("none"),
    N_("P0"), N_("centre"),
    # the lathe's labels before their radius / diameter suffix (app/workflow/forms.py lathe_form)
    N_("Measuring path"), N_("Surface position"), N_("Setpoint"), N_("Diameter"), N_("Protection zone in X"),
)


def label_text(label) -> str:
    """A field's label or choice text (English in app/workflow/forms.py) in the screen's language."""
    text = str(label or "")
    for pattern, msgid in LABELS:
        match = pattern.match(text)
        if match:
            return _(msgid) % {k: _(v) for k, v in match.groupdict().items()}
    return _(text) if text else ""


# the message line of the measuring screens (app/web/task_screens.py) and the record screens
message(r"P(?P<n>\d+) stored; press Calculate", N_("P%(n)s stored; press Calculate"))
message(r"P(?P<n>\d+) stored", N_("P%(n)s stored"))
message(r"P(?P<n>\d+) invalid: measure it again with NC Start", N_("P%(n)s invalid: measure it again with NC Start"))
message(r"NC Start: measuring P(?P<n>\d+)", N_("NC Start: measuring P%(n)s"))
message(r"Measurement done: WO activated", N_("Measurement done: WO activated"))
message(r"Measurement done", N_("Measurement done"))
message(r"Calculated: WO activated", N_("Calculated: WO activated"))
message(r"Calculated", N_("Calculated"))

# a function the level may not do (app/access/deps.denied: disabled keys, locked NC Start)
message(r"needs level (?P<level>\d+): keyswitch position (?P<position>\d+) or higher, or a password",
        N_("needs level %(level)s: keyswitch position %(position)s or higher, or a password"))
message(r"needs level (?P<level>\d+): a password of level (?P<password>\d+) or higher",
        N_("needs level %(level)s: a password of level %(password)s or higher"))
message(r"needs level (?P<level>\d+): a password of level (?P<password>\d+)",
        N_("needs level %(level)s: a password of level %(password)s"))

# sign-in (app/access/service.py, app/access/throttle.py)
message(r"wrong user name or password", N_("wrong user name or password"))
message(r"too many failed sign-ins from this computer: try again in (?P<seconds>\d+) s",
        N_("too many failed sign-ins from this computer: try again in %(seconds)s s"))
message(r"too many sign-ins at once: try again in a moment", N_("too many sign-ins at once: try again in a moment"))
message(r"password: at least (?P<n>\d+) characters", N_("password: at least %(n)s characters"))


def result_value(key: str, value) -> str:
    """A value of those tables: 4 decimals with the language's decimal sign; yes/no translated."""
    if isinstance(value, bool):
        return _("yes") if value else _("no")
    if isinstance(value, int | float):
        return format_fixed(value, 4)
    return str(value)


# --- soft hyphens in key labels (issue 29 item 3) -----------------------------------------------------
# Chromium on Linux has no hyphenation dictionaries: a long German compound on a softkey breaks at
# these joints (a soft hyphen shows "-" only where the line breaks), not at any letter.
JOINTS = re.compile(r"(?<=\w{4})(?=(verschiebung|ansicht|liste|lungen|taster|speicher|kalibrier|messung|"
                    r"vorschub|programm|protokoll|korrektur|daten|werte|einrichten|ausrichten|abstand)\b)",
                    re.IGNORECASE)


def breakable(label) -> str:
    """``label`` with soft hyphens at the joints of its long words (12 letters or more)."""
    text = str(label)
    return re.sub(r"\w{12,}", lambda m: JOINTS.sub("\u00ad", m.group(0)), text)

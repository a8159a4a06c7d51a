"""The PLC screen's texts in the operator's language (issue 29 item 2): the DB19.DBB43 bit meanings
(app/services/plc.py) and the readiness checklist (app/services/readiness.py) are English data of
the services; here they are registered with the screens' message translation (``texts.message``),
and the checklist's fixed labels are put into the catalogue."""

from __future__ import annotations

from app.i18n import N_

from .texts import message

# the categories a check applies to (readiness.py: WORKPIECE, PROBE_CAL, TOOLPROBE_CAL, TOOL)
CATEGORIES = (N_("workpiece"), N_("probe calibration"), N_("tool probe calibration"), N_("tool measuring"))
LABELS = (N_("All three geometry axes exist"), N_("Machine axes referenced"), N_("No alarm pending"),
          N_("Switching tool probe installed"), N_("Workpiece probe is the active tool"),
          N_("Tool offset (D number) of the probe active"), N_("Feed override as during calibration"),
          N_("Working plane"), N_("No scale factor in the frames"), N_("A cutter is the active tool"),
          N_("Approximate tool length and radius entered"), N_("Tool probe effective diameter set"),
          N_("the simulated axes are referenced at power-on"), N_("no alarm"), N_("tool probe on the table"),
          N_("this machine has no tool probe"), N_("no tool in the spindle: load the 3D probe"),
          N_("no tool offset active"), N_("no probe in the spindle"), N_("no calibration override recorded"),
          N_("frames carry translation and rotation only"), N_("no tool in the spindle: load the tool to measure"),
          N_("no cutter in the spindle"), N_("length, radius"), N_("length"), N_("radius"),
          N_("length calibrated, diameter calibrated"), N_("length calibrated, diameter not calibrated"),
          N_("length not calibrated, diameter calibrated"), N_("length not calibrated, diameter not calibrated"))

message(r"PLC → HMI: request P(?P<n>\d) invalid, discard its measurement",
        N_("PLC → HMI: request P%(n)s invalid, discard its measurement"))
message(r"HMI → PLC: P(?P<n>\d) measured and stored", N_("HMI → PLC: P%(n)s measured and stored"))
message(r"geometry axes (?P<axes>.*)", N_("geometry axes %(axes)s"))
message(r"T(?P<t>\d+) is the 3D probe \(type (?P<type>\d+)\)", N_("T%(t)s is the 3D probe (type %(type)s)"))
message(r"T(?P<t>\d+) is type (?P<type>\S+), not a 3D probe \(type (?P<probe>\d+)\)",
        N_("T%(t)s is type %(type)s, not a 3D probe (type %(probe)s)"))
message(r"probe (?P<n>\S+) calibrated \(length and radius\) in (?P<plane>\S+)",
        N_("probe %(n)s calibrated (length and radius) in %(plane)s"))
message(r"not calibrated: (?P<alarm>.*); measuring is allowed, results carry pre-travel and eccentricity",
        N_("not calibrated: %(alarm)s; measuring is allowed, results carry pre-travel and eccentricity"))
message(r"now (?P<now>\S+) %, calibrated at (?P<cal>\S+) %", N_("now %(now)s %%, calibrated at %(cal)s %%"))
message(r"(?P<plane>G1[789]): infeed axis (?P<axis>\w)", N_("%(plane)s: infeed axis %(axis)s"))
message(r"T(?P<t>\d+) is the workpiece probe: load a cutter", N_("T%(t)s is the workpiece probe: load a cutter"))
message(r"Probe calibrated in the active plane (?P<plane>G\d+)", N_("Probe calibrated in the active plane %(plane)s"))
message(r"Tool probe (?P<n>\S+) calibrated \(length and diameter\)",
        N_("Tool probe %(n)s calibrated (length and diameter)"))
message(r"Tool probe (?P<n>\S+) calibrated", N_("Tool probe %(n)s calibrated"))
message(r"(?P<alarm>.*): press Reset", N_("%(alarm)s: press Reset"))

"""Words of the manual's listings (chapters 5 and 6) this control does not run, each with the
manual section it comes from and why: the NC refuses them with that text (alarm 12550 at the
word, before anything moves), never with a bare "unknown name" (issue 28 item 1).
"""

from __future__ import annotations

_LATHE = ("a word of the lathe (manual ch. 6): this machine is a milling machine; the NC runs it on a lathe "
          "(machine kind \"lathe\")")

#: the words of manual ch. 6 the NC runs on a lathe (app.nc.cycles.lathe, DIAMON/DIAMOF in the
#: interpreter) and refuses by name on the milling machine
LATHE_WORDS = frozenset({"DIAMON", "DIAMOF", "CYCLE982", "CYCLE973", "CYCLE974", "CYCLE994"})

OUT_OF_SCOPE: dict[str, tuple[str, str]] = {
    "DIAMON": ("§6", f"diameter programming is {_LATHE}"),
    "DIAMOF": ("§6", f"diameter programming off is {_LATHE}"),
    "CYCLE982": ("§6.2–6.3", f"tool measuring on the lathe is {_LATHE}"),
    "CYCLE973": ("§6.4", f"calibrating the workpiece probe on the lathe is {_LATHE}"),
    "CYCLE974": ("§6.5", f"1-point measuring on the lathe is {_LATHE}"),
    "CYCLE994": ("§6.6", f"2-point measuring on the lathe is {_LATHE}"),
    "CYCLE800": ("§5.7.2", "the swivel cycle CYCLE800 is no measuring cycle and this machine has no "
                           "swivel data: set the rotary table by positioning its axis"),
    "CYCLE119": ("§5.9.4", "CYCLE119 (frame from three measured points) is not part of this control"),
    "MVAR": ("§5.4.2", "MVAR is not a known variable: the listing's N61 prints MVAR for the cycle "
                         "parameter _MVAR (with the underscore)"),
    "$P_TOOLR": ("§5.2.4", "the active tool radius variable is not part of this control: program the "
                           "tool probe position as a number"),
    "_TPW": ("§5.2.2", "workpiece-related tool-probe data (_TPW) are not part of this control: the "
                       "tool probe is calibrated machine-related (_TP, CYCLE971 _MVAR=0)"),
    "$P_UIFR": ("§5.7.2", "the settable frames are written by the measuring cycles and the zero-offset "
                          "screen, not by frame assignments in a program"),
}


def refusal(word: str, lathe: bool = False) -> str | None:
    """The operator's text for a word of the manual this control refuses, or None (``lathe``: the
    machine is a lathe, which runs the words of ``LATHE_WORDS``)."""
    entry = OUT_OF_SCOPE.get(str(word).upper())
    if entry is None or lathe and str(word).upper() in LATHE_WORDS:
        return None
    section, why = entry
    return f"{word} (manual {section}): {why}"

"""Words of the manual's listings (chapters 5 and 6) this control does not run, each with the
manual section it comes from and why: the NC refuses them with that text (alarm 12550 at the
word, before anything moves), never with a bare "unknown name" (issue 28 item 1).
"""

from __future__ import annotations

_LATHE = ("a measuring cycle of the lathe (manual ch. 6) that this control's NC does not run (on the milling "
          "machine and on the lathe alike): measure on the lathe with the lathe tasks of the JOG screens")

OUT_OF_SCOPE: dict[str, tuple[str, str]] = {
    "DIAMON": ("§6", "diameter programming of the lathe (manual ch. 6) is not part of this control's NC: "
                     "programs give X as a radius coordinate, on the lathe too"),
    "DIAMOF": ("§6", "diameter programming off (lathe, manual ch. 6) is not part of this control's NC: "
                     "programs always give X as a radius coordinate, on the lathe too"),
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


def refusal(word: str) -> str | None:
    """The operator's text for a word of the manual this control refuses, or None."""
    entry = OUT_OF_SCOPE.get(str(word).upper())
    if entry is None:
        return None
    section, why = entry
    return f"{word} (manual {section}): {why}"

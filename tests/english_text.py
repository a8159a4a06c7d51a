"""What the operator reads on a rendered page, and the English sentences in it (issue 29 item 2).

Text nodes and the attributes an operator sees (title, aria-label, placeholder, alt) of the HTML as
the server rendered it, without scripts, styles and NC code (program text, code samples, keys). An
English sentence is a text run with two or more English words: words of letters with a lowercase
letter, other than units, key names and the control's own names, which the manual keeps in every
language (mm, inch, Ctrl, NC, G54, _OVR, CYCLE977, …).
"""

from __future__ import annotations

import re
from html.parser import HTMLParser

HIDDEN = {"script", "style", "code", "pre", "textarea", "kbd", "template"}
SEEN_ATTRIBUTES = ("title", "aria-label", "placeholder", "alt")
# units and key names (the manual keeps them in Latin letters); trademarks; the screen's own units
KEPT = {"mm", "min", "inch", "in", "deg", "rpm", "Ctrl", "Enter", "Tab", "Shift", "Esc", "Alt", "Del",
        "Backspace", "Ø", "OPC", "UA", "Chromium", "WebGL"}
WORD = re.compile(r"(?<![\w$])[A-Za-z]*[a-z][A-Za-z]*(?![\w(\[])")


class _Text(HTMLParser):
    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.hidden = 0
        self.runs: list[str] = []

    def handle_starttag(self, tag, attrs):
        if tag in HIDDEN:
            self.hidden += 1
        if self.hidden:
            return
        for name, value in attrs:
            if name in SEEN_ATTRIBUTES and value and value.strip():
                self.runs.append(value.strip())

    def handle_endtag(self, tag):
        if tag in HIDDEN and self.hidden:
            self.hidden -= 1

    def handle_data(self, data):
        if not self.hidden and data.strip():
            self.runs.append(" ".join(data.split()))


def shown_texts(html: str) -> list[str]:
    parser = _Text()
    parser.feed(html)
    return parser.runs


def english_words(text: str) -> list[str]:
    return [w for w in WORD.findall(text) if w not in KEPT and len(w) >= 2]


# English words that are no German words (German shares "in", "an", "so", "war", ...)
FUNCTION_WORDS = frozenset("""the and of to on at is are be by for with from not yet then this that its it or into
each press here there when which what has have was were will can must only than after before while above below
between first second no none any all out up down off how why where who you your set shows shown probe probed
measure measured measuring tool length diameter radius value values edge corner hole spigot pocket ring point
points offset zero enter type typed calibrated calibration program screen turn move drag wheel view data""".split())


def english_words_de(text: str) -> list[str]:
    return [w for w in WORD.findall(text) if w.lower() in FUNCTION_WORDS]


def english_sentences(html: str, lang: str = "zh") -> list[str]:
    """The text runs of ``html`` with two or more English words (each once, in page order)."""
    words = english_words_de if lang == "de" else english_words
    return list(dict.fromkeys(t for t in shown_texts(html) if len(words(t)) >= 2))

"""The help pictures of the measuring screens in Chinese and German (issue 28 item 7): every text of
the picture (labels, notes, caption) and the probe-data lines beside it are in the operator's
language, and the Chinese uses the manual's terms (seed 001_*.txt, the Chinese SW 6.3 manual; the
line where the term stands). The pictures are read from the rendered screens, as the operator sees
them, for every measuring function with a picture, in the edge functions' infeed variant too."""

from __future__ import annotations

import re

import pytest
from english_text import english_words, english_words_de, shown_texts

SCREENS = ("/measure/workpiece/edge/set", "/measure/workpiece/edge/align", "/measure/workpiece/edge/distance",
           "/measure/workpiece/corner/right", "/measure/workpiece/corner/any",
           "/measure/workpiece/pocket/rect", "/measure/workpiece/spigot/rect",
           *(f"/measure/workpiece/pocket/hole{k}" for k in range(1, 5)),
           *(f"/measure/workpiece/spigot/spigot{k}" for k in range(1, 5)),
           "/measure/workpiece/plane", "/measure/workpiece/calibrate/length", "/measure/workpiece/calibrate/radius",
           "/measure/tool/length", "/measure/tool/diameter", "/measure/tool/calibrate")

# (screen, the manual's Chinese term shown in its help box, seed 001 line)
MANUAL_TERMS = (
    ("/measure/workpiece/edge/set", "起始位置", 8882),              # figure label "起始位置" (start position)
    ("/measure/workpiece/calibrate/radius", "钻孔中心", 5107),      # "测量头大约定位在钻孔中心和校准深度处"
    ("/measure/workpiece/calibrate/radius", "校准深度", 5107),
    ("/measure/workpiece/pocket/hole1", "测量头大致定位在钻孔中心和测量深度上", 4685),
    ("/measure/workpiece/spigot/spigot1", "定位在轴颈上方的中心处", 5668),
    ("/measure/workpiece/calibrate/length", "校准高度", 8884),
    ("/measure/workpiece/calibrate/length", "测量头", 8543),
    ("/measure/tool/length", "圆盘", 7764),                          # the tool probe's disc "在 X/Y 上的圆盘"
)


def help_box(client, path: str, lang: str, **query) -> str:
    html = client.get(path, params={"lang": lang, **query}).text
    match = re.search(r'<figure class="help-picture".*?</figure>', html, re.S)
    assert match, f"{path}: no help picture"
    equipment = re.search(r'<dl class="equipment".*?</dl>', html, re.S)
    return match.group(0) + (equipment.group(0) if equipment else "")


GERMAN_TOO = {"radius"}            # English and German alike ("Radius noch nicht")


def english_in(html: str, lang: str) -> list[str]:
    """The texts with an English word: any word of Latin letters with a lowercase letter but the
    units and the control's names (zh), an English function word that is no German word (de)."""
    if lang == "de":
        return [t for t in shown_texts(html) if [w for w in english_words_de(t) if w.lower() not in GERMAN_TOO]]
    return [t for t in shown_texts(html) if english_words(t)]


@pytest.mark.parametrize("lang", ["zh", "de"])
def test_no_english_word_in_any_help_picture(client, lang):
    client.post("/api/machine/tool", json={"tool": 9})
    found = {}
    for path in SCREENS:
        for query in ({}, {"axis": "Z"}) if "/edge/" in path else ({},):
            english = english_in(help_box(client, path, lang, **query), lang)
            if english:
                found[f"{path} {query}"] = english
    assert not found, found


def test_english_is_english(client):
    """The detector finds the English a Chinese screen would show if a text were not translated."""
    assert english_in(help_box(client, "/measure/workpiece/edge/set", "en"), "zh")
    assert english_in(help_box(client, "/measure/workpiece/calibrate/length", "en"), "de")


@pytest.mark.parametrize(("path", "term", "line"), MANUAL_TERMS, ids=[f"{r[0]}:{r[1]}" for r in MANUAL_TERMS])
def test_the_chinese_help_uses_the_manuals_term(client, path, term, line):
    assert term in help_box(client, path, "zh"), f"seed 001 line {line}: {term}"


def test_the_german_help_picture_labels(client):
    box = help_box(client, "/measure/workpiece/edge/set", "de")
    assert ">Start<" in box
    box = help_box(client, "/measure/workpiece/calibrate/length", "de")
    assert ">Messtaster<" in box and "Kalibrierhöhe" in box

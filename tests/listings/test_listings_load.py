"""Every NC listing of the manual's chapters 5 and 6 (tests/listings/manual_listings.py, with the
seed's line numbers) is read by the NC as printed: either it loads (its words are implemented as
the 840D does them), or the NC refuses it naming the word and the manual section (alarm 12550,
app.nc.scope), never with a bare syntax error. Chapter 6 (the lathe: DIAMON/DIAMOF, CYCLE982,
CYCLE973, CYCLE974, CYCLE994) loads on a lathe and is refused by name on the milling machine. Adapted: ``循环`` → ``CYCLE`` (the translation of
the cycle names) and, in §5.9's listing, an expression the print wrapped over two lines and its
"..." for blocks left out.
Running them against the simulator's truth: test_listings_cycle976.py, test_listings_workpiece.py,
test_listings_lathe.py.
"""

from __future__ import annotations

import pytest
from manual_listings import ALL

from app.nc.cycles import CYCLE_NAMES, LATHE_CYCLE_NAMES, PROTOCOL_CYCLES
from app.nc.errors import NcSyntaxError
from app.nc.interpreter import Interpreter
from app.nc.variables import Variables

# what the NC refuses on the milling machine, by the listing's first seed line: the word it names
REFUSED = {
    8496: "_TPW",          # §5.2.4 workpiece-related tool-probe data
    11035: "MVAR",         # §5.4.2 the print's "N61 MVAR=1" (the parameter is _MVAR)
    14182: "CYCLE800",     # §5.7.2 the swivel cycle
    16332: "CYCLE119",     # §5.9.4
    **{first: word for word, firsts in {
        "DIAMOF": (16812, 17138, 17856, 18606, 20537),
        "CYCLE982": (19596, 20039),
        "DIAMON": (20714, 21058, 21272, 21502, 22051, 22159),
    }.items() for first in firsts},
}
# the print's own marks, not NC: an expression wrapped over two lines, "..." for blocks left out,
# §6.3.6's comment whose "；" the print lost (seed line 20040: "N10 T3 D1 G94  车刀T3当前有效，")
PRINT_MARKS = {16181: (("600, \n\n100,", "600, 100,"), ("\n  ...  \n", "\n")),
               20039: (("G94  车刀", "G94  ；车刀"),)}


def as_read(listing) -> str:
    text = listing.text.replace("循环", "CYCLE")
    for printed, read in PRINT_MARKS.get(listing.lines[0], ()):
        assert printed in text
        text = text.replace(printed, read)
    return text


class Axes:
    """What loading reads of the machine: its axes (a rotary table C for §5.7's listing), the
    active offset and the tool in the spindle."""

    axes = ("X", "Y", "Z", "C")

    def active_offset(self) -> str:
        return "G500"

    def tool_state(self) -> tuple[int | None, int]:
        return None, 0


class LatheAxes(Axes):
    """A lathe (X radius, Z; DIAMON after Reset) for loading."""

    axes = ("X", "Z")
    is_lathe = True
    diameter_programming = True


def load(text: str, machine: Axes | None = None) -> None:
    machine = machine or Axes()
    cycles = {name: (lambda ctx: None) for name in (*CYCLE_NAMES, *LATHE_CYCLE_NAMES, *PROTOCOL_CYCLES)}
    interp = Interpreter(machine, Variables(axes=machine.axes), cycles=cycles)    # type: ignore[arg-type]
    interp.load(text)


@pytest.mark.parametrize("listing", ALL, ids=lambda item: f"{item.lines[0]}-{item.name.strip()}")
def test_listing_loads_or_is_refused_by_name(listing):
    word = REFUSED.get(listing.lines[0])
    if word is None:
        load(as_read(listing))
        return
    with pytest.raises(NcSyntaxError) as refused:
        load(as_read(listing))
    assert refused.value.message.startswith(f"{word} (manual §"), refused.value.message
    assert refused.value.alarm.number == 12550


def test_the_store_holds_every_listing_of_chapters_5_and_6():
    assert len(ALL) == 36
    assert [item.lines for item in ALL] == sorted(item.lines for item in ALL)
    assert all(item.section.startswith(("§5", "§6")) for item in ALL)


def test_the_chinese_cycle_name_is_refused_as_printed():
    with pytest.raises(NcSyntaxError) as refused:
        load("N70 循环977 ;启动测量循环")
    assert "循" in refused.value.message


def test_the_fullwidth_semicolon_of_chapter_6_starts_a_comment():
    load("N10 G0 X10 ；车刀T3当前有效\nN20 M2 ；程序结束")


CHAPTER_6 = [item for item in ALL if item.section.startswith("§6")]


@pytest.mark.parametrize("listing", CHAPTER_6, ids=lambda item: f"{item.lines[0]}-{item.name.strip()}")
def test_on_the_lathe_every_chapter_6_listing_loads_as_printed(listing):
    """The lathe runs DIAMON/DIAMOF and CYCLE982/973/974/994 (app.nc.cycles.lathe): each listing of
    chapter 6 loads unchanged but for 循环 (none of chapter 6's listings has it in its code)."""
    load(as_read(listing), LatheAxes())


def test_on_the_lathe_the_other_refused_words_stay_refused():
    with pytest.raises(NcSyntaxError) as refused:
        load("N10 CYCLE800", LatheAxes())
    assert refused.value.message.startswith("CYCLE800 (manual §5.7.2)")


@pytest.mark.parametrize("first", [16812, 19596, 21272, 22051])
def test_on_the_milling_machine_a_chapter_6_listing_is_refused_by_name_and_nothing_moves(client, first):
    """On the milling machine (the demo scenario) the NC names the lathe's word and the section,
    with alarm 12550, through the API (422, never a bare syntax error), before anything moves."""
    machine = client.get("/api/machine").json()
    assert machine.get("kind", "mill") != "lathe"
    listing = next(item for item in ALL if item.lines[0] == first)
    answer = client.post("/api/nc/run", json={"mda": as_read(listing)})
    assert answer.status_code == 422, answer.text
    error = answer.json()["error"]
    assert error["code"] == "nc_syntax" and error["alarm"]["code"] == 12550
    assert error["message"].startswith(f"{REFUSED[first]} (manual §6"), error["message"]
    assert "milling machine" in error["message"]
    assert client.get("/api/machine").json()["mcs"] == machine["mcs"]

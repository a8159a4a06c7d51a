"""The machine control panel state of one browser tab (sent by the tab, held by no server object)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from fastapi import Request


@dataclass(frozen=True)
class PanelState:
    """The machine control panel of one browser tab (axis, increment, displayed coordinates).

    Each tab keeps its own (static/hmi.js, sessionStorage) and sends it with every request in
    ``X-Panel-*`` headers; the server holds none, so two tabs never share a selection and a jog
    always moves the axis its tab shows (design.md §9.1)."""

    axis: str = "X"
    increment: str = "1000"
    coords: str = "WCS"
    feed: str = ""            # jog feed, mm/min ("" = the machine's own jog feed, SD 41110 JOG_SET_VELO)
    rapid: bool = False       # the RAPID key: jog at rapid traverse times the rapid override
    rov: str = "25"           # rapid override, percent
    mode: str = ""            # the mode the tab's screen selects (JOG/MDA/AUTO; "" = the page's own)
    INCREMENTS: ClassVar[dict[str, float | None]] = {"1": 0.001, "10": 0.01, "100": 0.1, "1000": 1.0, "cont": None}
    FEEDS: ClassVar[tuple[str, ...]] = ("", "100", "250", "500", "1000", "2000", "5000")
    RAPID_OVERRIDES: ClassVar[tuple[str, ...]] = ("1", "5", "25", "50", "100")
    MODES: ClassVar[tuple[str, ...]] = ("JOG", "MDA", "AUTO")

    @classmethod
    def of(cls, request: Request, axes) -> PanelState:
        headers = request.headers
        axis = headers.get("X-Panel-Axis", cls.axis)
        increment = headers.get("X-Panel-Increment", cls.increment)
        coords = headers.get("X-Panel-Coords", cls.coords)
        feed = headers.get("X-Panel-Feed", cls.feed)
        rov = headers.get("X-Panel-Rov", cls.rov)
        mode = headers.get("X-Panel-Mode", cls.mode)
        return cls(axis=axis if axis in axes else cls.axis,
                   increment=increment if increment in cls.INCREMENTS else cls.increment,
                   coords=coords if coords in ("WCS", "MCS") else cls.coords,
                   feed=feed if feed in cls.FEEDS else cls.feed,
                   rapid=headers.get("X-Panel-Rapid") == "on",
                   rov=rov if rov in cls.RAPID_OVERRIDES else cls.rov,
                   mode=mode if mode in cls.MODES else cls.mode)

    def jog_feed(self, rapid_traverse: float, rapid: bool | None = None) -> float | None:
        """mm/min of a jog: the chosen jog feed, or with RAPID the rapid traverse times the rapid
        override (the feed override acts on both, as on the machine's every motion); None: the
        machine's own jog feed."""
        if self.rapid if rapid is None else rapid:
            return float(rapid_traverse) * float(self.rov) / 100.0
        return float(self.feed) if self.feed else None

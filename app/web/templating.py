"""Jinja2 + jinja2-fragments: full page on a normal GET, only the screen blocks on an htmx request.

A screen template extends ``base.html`` and fills ``content`` and ``vkeys``; ``render_screen``
returns the blocks ``screen``, ``vsoftkeys`` and ``hsoftkeys`` (the last two swap out of band).
"""

from __future__ import annotations

from pathlib import Path

import jinja2_fragments
from fastapi import Request
from fastapi.responses import HTMLResponse
from jinja2_fragments.fastapi import Jinja2Blocks

from app.gud import GudSettings

TEMPLATES_DIR = Path(__file__).resolve().parents[2] / "templates"
SCREEN_BLOCKS = ["screen", "vsoftkeys", "hsoftkeys"]

# Horizontal softkeys F1..F8 (design.md §7); None = an empty key.
HORIZONTAL_SOFTKEYS: list[tuple[str, str, str] | None] = [
    ("measure_workpiece", "Measure workpiece", "/measure/workpiece"),
    ("measure_tool", "Measure tool", "/measure/tool"),
    ("offsets", "Zero offset", "/offsets"),
    ("tools", "Tool list", "/tools"),
    ("machine_view", "Machine view", "/machine-view"),
    ("settings", "Settings", "/settings"),
    ("log", "Log", "/log"),
    ("jog", "JOG", "/jog"),
]

INCH = 25.4


def fmt_length(value: float | None, gud: GudSettings, rotary: bool = False) -> str:
    """Display a stored mm value: 3 decimals in mm, 4 in inch; rotary axes in degrees."""
    if value is None:
        return ""
    if rotary:
        return f"{value:.3f}"
    if gud.inch_display:
        return f"{value / INCH:.4f}"
    return f"{value:.3f}"


def fixed(value, decimals: int = 4) -> str:
    """Fixed-point display without a "-0.0000" for values that round to zero."""
    text = f"{float(value):.{decimals}f}"
    return text[1:] if text.startswith("-") and float(text) == 0.0 else text


def vkeys(keys: list, back: dict) -> list:
    """Vertical softkeys S-F1.. with ``back`` on S-F8 (the way out of a screen); None = an empty key."""
    return [*keys, *[None] * (7 - len(keys)), back]


# result keys in degrees (4 decimals); the others are mm (3 decimals), design.md §4
ANGLE_KEYS = frozenset({"angle", "alpha", "beta", "angle_2", "corner_angle", "setpoint_angle"})


def fmt_result(key: str, value) -> str:
    """A measuring result value: yes/no, degrees with 4 decimals, mm with 3, else as text."""
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int | float):
        return fixed(value, 4 if key in ANGLE_KEYS else 3)
    return str(value)


templates = Jinja2Blocks(directory=str(TEMPLATES_DIR))
templates.env.globals["HORIZONTAL_SOFTKEYS"] = HORIZONTAL_SOFTKEYS
templates.env.filters["mm"] = fmt_length
templates.env.filters["fixed"] = fixed
# macros as a global module, so blocks rendered on their own (htmx partials) can call them
templates.env.globals["ui"] = templates.env.get_template("macros.html").module


def is_htmx(request: Request) -> bool:
    return request.headers.get("HX-Request") == "true" and "HX-History-Restore-Request" not in request.headers


def base_context(request: Request) -> dict:
    services = request.app.state.services
    machine = services.machine
    return {
        "status": machine.status(),
        "panel": machine.panel,
        "axes": machine.axes,
        "rotary_axes": machine.rotary_axes,
        "gud": services.settings.get(),
    }


def _owner(template: str, block: str) -> str:
    """The template that defines ``block``: the screen's own, else the layout's default."""
    return template if block in templates.get_template(template).blocks else "base.html"


def render_screen(request: Request, template: str, context: dict | None = None, status_code: int = 200):
    """Full page on a normal GET; on an htmx request the blocks screen + vsoftkeys + hsoftkeys."""
    if not is_htmx(request):
        ctx = {"request": request, **base_context(request), **(context or {})}
        return templates.TemplateResponse(request, template, ctx, status_code=status_code)
    return render_blocks(request, template, SCREEN_BLOCKS, context, status_code)


def render_blocks(request: Request, template: str, blocks: list[str], context: dict | None = None,
                  status_code: int = 200, headers: dict | None = None):
    """The named blocks, each from the template that defines it, one after the other."""
    ctx = {"request": request, **base_context(request), **(context or {})}
    html = "".join(jinja2_fragments.render_block(templates.env, _owner(template, block), block, ctx)
                   for block in blocks)
    return HTMLResponse(html, status_code=status_code, headers=headers)


def render_block(request: Request, template: str, block: str, context: dict | None = None,
                 status_code: int = 200, headers: dict | None = None):
    return render_blocks(request, template, [block], context, status_code, headers)

"""The JOG basic screen."""

from __future__ import annotations

from fastapi import APIRouter, Request
from fastapi.responses import RedirectResponse

from .templating import render_screen

router = APIRouter()


@router.get("/")
def root():
    return RedirectResponse("/jog", status_code=303)


@router.get("/jog")
def jog_screen(request: Request):
    return render_screen(request, "jog.html", {"screen": "jog"})

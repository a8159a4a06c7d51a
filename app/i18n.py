"""Operator languages EN/DE/ZH (design.md §9.9): the message catalogues and the current language.

Texts are English in the code and translated where an operator reads them, by GNU gettext
catalogues (``app/locale/<lang>/LC_MESSAGES/messages.po``, Babel). The language of a request is
a ContextVar set by ``app.web.language.LanguageMiddleware``; the JSON API stays English.

- ``_("text")`` / ``gettext``: translated now (screens, per request); named parameters fill
  ``%(name)s`` after translation: ``_("P%(n)s stored", n=2)``.
- ``N_("text")``: marks a text of a module-level table for extraction; translate it where it is
  shown with ``_(value)``.
- ``Text("text", **params)``: a str that is English to the code (comparisons, JSON) and the
  translation wherever it is printed (``str()``, f-strings, Jinja output).

The catalogues are compiled in memory from the .po files on first use (fuzzy entries left out), so
a fresh clone needs no build step; ``scripts/i18n.py`` extracts, updates, checks and compiles them.
"""

from __future__ import annotations

import gettext as _gettext
import io
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from functools import cache
from pathlib import Path

LANGUAGES: dict[str, str] = {"en": "English", "de": "Deutsch", "zh": "中文"}
DEFAULT_LANGUAGE = "en"
LOCALE_DIR = Path(__file__).resolve().parent / "locale"
DOMAIN = "messages"

_language: ContextVar[str] = ContextVar("hmi_language", default=DEFAULT_LANGUAGE)


def language() -> str:
    """The language of the current request (``en`` outside one)."""
    return _language.get()


def set_language(lang: str):
    """Make ``lang`` current; returns the token for ``reset_language``."""
    return _language.set(lang if lang in LANGUAGES else DEFAULT_LANGUAGE)


def reset_language(token) -> None:
    _language.reset(token)


@contextmanager
def using(lang: str) -> Iterator[None]:
    """``with using("de"): ...``: translate in ``lang`` (tests, background work)."""
    token = set_language(lang)
    try:
        yield
    finally:
        reset_language(token)


def po_path(lang: str) -> Path:
    return LOCALE_DIR / lang / "LC_MESSAGES" / f"{DOMAIN}.po"


@cache
def translations(lang: str) -> _gettext.NullTranslations:
    """The catalogue of ``lang``, compiled in memory from its .po (fuzzy entries are not used)."""
    path = po_path(lang)
    if lang == DEFAULT_LANGUAGE or not path.exists():
        return _gettext.NullTranslations()
    from babel.messages.mofile import write_mo
    from babel.messages.pofile import read_po

    with path.open("rb") as fp:
        catalog = read_po(fp, locale=lang)
    buffer = io.BytesIO()
    write_mo(buffer, catalog, use_fuzzy=False)
    buffer.seek(0)
    return _gettext.GNUTranslations(buffer)


def gettext(message: str, **params) -> str:
    """``message`` in the current language, ``%(name)s`` filled from ``params``."""
    if isinstance(message, Text):
        return str(message)
    text = translations(language()).gettext(message) if message else message
    return text % params if params else text


def ngettext(singular: str, plural: str, n: int, **params) -> str:
    text = translations(language()).ngettext(singular, plural, n)
    return text % {"num": n, **params}


_ = gettext


def N_(message: str) -> str:
    """Marks ``message`` for the catalogue; it is translated where it is shown."""
    return message


class Text(str):
    """English to the code and the JSON API; the translation wherever it is printed."""

    msgid: str
    params: dict

    def __new__(cls, msgid: str, **params):
        obj = super().__new__(cls, msgid % params if params else msgid)
        obj.msgid = msgid
        obj.params = params
        return obj

    def __str__(self) -> str:
        return gettext(self.msgid, **self.params)

    def __format__(self, spec: str) -> str:
        return format(str(self), spec)

    def __html__(self) -> str:
        from markupsafe import escape

        return str(escape(str(self)))


# --- numbers and dates (Babel's locale data) ------------------------------------------------------

@cache
def decimal_symbol(lang: str) -> str:
    from babel.numbers import get_decimal_symbol

    return get_decimal_symbol(_babel_locale(lang))


def _babel_locale(lang: str) -> str:
    return {"en": "en_GB", "de": "de_DE", "zh": "zh_Hans_CN"}.get(lang, "en_GB")


def format_fixed(value: float, decimals: int) -> str:
    """``value`` with ``decimals`` decimals, the locale's decimal sign, no grouping (a CNC display:
    Operate shows no thousands separator), never "-0.000"."""
    text = f"{float(value):.{decimals}f}"
    if text.startswith("-") and float(text) == 0.0:
        text = text[1:]
    sign = decimal_symbol(language())
    return text if sign == "." else text.replace(".", sign)


def format_number(value: float) -> str:
    """A number as short as it is exact (``%g``) with the locale's decimal sign."""
    text = f"{float(value):g}"
    sign = decimal_symbol(language())
    return text if sign == "." else text.replace(".", sign)


def format_datetime(value, with_seconds: bool = True) -> str:
    """A date and time in the current language (Babel), e.g. 14.03.2025, 09:41:07."""
    from babel.dates import format_datetime as babel_format

    if value is None or value == "":
        return ""
    if isinstance(value, str):
        from datetime import datetime

        try:
            value = datetime.fromisoformat(value.replace("Z", "+00:00"))
        except ValueError:
            return value
    from babel.dates import LOCALTZ

    if value.tzinfo is None:          # the database holds UTC
        from datetime import UTC

        value = value.replace(tzinfo=UTC)
    pattern = "medium" if with_seconds else "short"
    return babel_format(value, pattern, tzinfo=LOCALTZ, locale=_babel_locale(language()))

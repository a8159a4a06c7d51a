"""The GUD measuring settings: stored in the db, validated by ``app.gud.GudSettings``."""

from __future__ import annotations

import threading
from typing import NoReturn

from pydantic import ValidationError

from app.errors import InvalidInput
from app.gud import GudSettings, legacy_units
from db import Database


def raise_invalid(error: ValidationError, prefix: str = "") -> NoReturn:
    """First pydantic error -> InvalidInput naming the field (``prefix`` + location)."""
    first = error.errors()[0]
    field = prefix + ".".join(str(p) for p in first["loc"])
    message = first["msg"].removeprefix("Value error, ")
    raise InvalidInput(f"{field}: {message}" if field else message, field=field or None) from None


def validation_errors(error: ValidationError) -> dict[str, str]:
    """All pydantic errors as {field: message}, for forms that mark every bad field."""
    out: dict[str, str] = {}
    for item in error.errors():
        field = ".".join(str(p) for p in item["loc"])
        out.setdefault(field, item["msg"].removeprefix("Value error, "))
    return out


class SettingsService:
    def __init__(self, db: Database):
        self._db = db
        self._lock = threading.Lock()
        # (write count, settings): read again once any process wrote (Database.generation)
        self._cached: tuple[int, GudSettings] | None = None

    def get(self) -> GudSettings:
        """Stored values over the defaults; unknown or stale stored keys are ignored."""
        cached = self._cached                   # no lock while the write count says it is current
        if cached is not None and cached[0] == self._db.generation:
            return cached[1]
        with self._lock:
            return self.get_unlocked()

    def validate(self, values: dict) -> GudSettings:
        """Current settings with ``values`` applied; InvalidInput names the first bad field."""
        if not isinstance(values, dict):
            raise InvalidInput("settings must be an object")
        merged = {**self.get().model_dump(), **legacy_units(values, self.get().model_dump())}
        try:
            settings = GudSettings.model_validate(merged)
        except ValidationError as error:
            raise_invalid(error)
        self._check_wo(settings)
        return settings

    def check(self, values: dict) -> tuple[GudSettings | None, dict[str, str]]:
        """Like ``validate`` but collects every bad field (for the settings form)."""
        merged = {**self.get().model_dump(), **legacy_units(values, self.get().model_dump())}
        try:
            settings = GudSettings.model_validate(merged)
        except ValidationError as error:
            return None, validation_errors(error)
        try:
            self._check_wo(settings)
        except InvalidInput as error:
            return None, {error.field or "": error.message}
        return settings, {}

    def put(self, values: dict, source: str = "api") -> GudSettings:
        """Audited (kind "settings"): the keys that changed, before and after. The stored values
        are read, merged and written in one writing unit: a concurrent change of other keys (this
        or another HMI process) is kept (design.md §10.5)."""
        self.validate(values)                      # a bad value: refused before anything is locked
        with self._lock:
            with self._db.unit() as unit:
                old = _lenient(unit.get_settings()).model_dump()
                settings = self._merged(old, values)
                new = settings.model_dump()
                changed = sorted(k for k in new if new[k] != old.get(k))
                unit.put_settings(new)
                if changed:
                    unit.add_audit("settings", "settings", {k: old.get(k) for k in changed},
                                   {k: new[k] for k in changed}, source)
            self._cached = None
        return settings

    def _merged(self, current: dict, values: dict) -> GudSettings:
        merged = {**current, **legacy_units(values, current)}
        try:
            settings = GudSettings.model_validate(merged)
        except ValidationError as error:
            raise_invalid(error)
        self._check_wo(settings)
        return settings

    def get_unlocked(self) -> GudSettings:
        generation = self._db.generation           # before the read: a later write reads again
        if self._cached is None or self._cached[0] != generation:
            with self._db.unit(readonly=True) as unit:
                self._cached = (generation, _lenient(unit.get_settings()))
        return self._cached[1]

    def changes_levels(self, values) -> bool:
        """``values`` change the access-level table (a ``level_*`` setting)."""
        if not isinstance(values, dict):
            return False
        current = self.get()
        return any(key.startswith("level_") and key in GudSettings.model_fields and value != getattr(current, key)
                   for key, value in values.items())

    def reset_to_defaults(self) -> GudSettings:
        """The measuring settings' defaults; the access-level table (``level_*``) stays as it is:
        it is the plant's access configuration, not measuring data."""
        current = self.get()
        defaults = {k: v for k, v in GudSettings().model_dump().items() if not k.startswith("level_")}
        return self.put({**current.model_dump(), **defaults}, source="scenario")

    def _check_wo(self, settings: GudSettings) -> None:
        if settings.measuring_wo in ("G500", "active"):
            return
        with self._db.unit(readonly=True) as unit:
            names = unit.offset_names()
        if settings.measuring_wo not in names:
            raise InvalidInput(f"measuring_wo: {settings.measuring_wo} is not a configured zero offset",
                               field="measuring_wo")


def _lenient(stored: dict) -> GudSettings:
    """The stored values over the defaults; a stored key this version does not know, or whose value
    it refuses (a database of an older or newer HMI), is left out and its default stands."""
    defaults = GudSettings().model_dump()
    stored = legacy_units(stored)           # a database of wave 1: inch_display without units
    known = {key: value for key, value in stored.items() if key in GudSettings.model_fields}
    try:                                    # the usual case: they were stored together, validated
        return GudSettings.model_validate({**defaults, **known})
    except ValidationError:
        pass
    values = {}
    for key, value in known.items():
        try:
            GudSettings.model_validate({**defaults, key: value})
        except ValidationError:
            continue
        values[key] = value
    return GudSettings.model_validate({**defaults, **values})

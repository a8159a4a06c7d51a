"""Stored GUD settings are read over the defaults (app/services/settings.py): what an older or newer
HMI left in the database (an unknown key, a value this version refuses) is left out and its default
stands; every other stored value is kept."""

from __future__ import annotations

from app.gud import GudSettings


def _store(app, values: dict) -> None:
    with app.state.services.db.unit() as unit:
        unit.put_settings(values)


def test_stored_values_over_the_defaults(app, client):
    _store(app, {"measuring_feed": 150.0, "fast_feed": 1200.0})
    got = client.get("/api/settings").json()
    assert (got["measuring_feed"], got["fast_feed"]) == (150.0, 1200.0)


def test_a_refused_or_unknown_stored_value_falls_back_to_its_default_only(app, client):
    default = GudSettings()
    _store(app, {"measuring_feed": -5.0,            # this version refuses it (gt 0)
                 "fast_feed": 1200.0, "rapid_return": True,
                 "a_setting_of_a_newer_hmi": 3})
    got = client.get("/api/settings").json()
    assert got["measuring_feed"] == default.measuring_feed
    assert (got["fast_feed"], got["rapid_return"]) == (1200.0, True)
    assert "a_setting_of_a_newer_hmi" not in got

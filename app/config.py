"""Process settings (pydantic-settings, env prefix ``HMI_``), distinct from the GUD measuring settings."""

from __future__ import annotations

from pathlib import Path

from pydantic import Field
from pydantic_settings import BaseSettings, SettingsConfigDict


class Settings(BaseSettings):
    model_config = SettingsConfigDict(env_prefix="HMI_", extra="ignore")

    host: str = "127.0.0.1"
    port: int = Field(default=8000, ge=1, le=65535)
    db_path: Path = Path("data/hmi.db")
    scenario_path: Path | None = None          # None = the built-in demo scenario
    time_scale: float | None = Field(default=None, ge=0)  # overrides the scenario's machine.time_scale

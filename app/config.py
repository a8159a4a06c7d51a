"""Process settings (pydantic-settings, env prefix ``HMI_``), distinct from the GUD measuring settings."""

from __future__ import annotations

from pathlib import Path

from pydantic import Field
from pydantic_settings import BaseSettings, SettingsConfigDict

from db.database import MACHINE_NAME, default_machine_name


class Settings(BaseSettings):
    model_config = SettingsConfigDict(env_prefix="HMI_", extra="ignore")

    host: str = "127.0.0.1"
    port: int = Field(default=8000, ge=1, le=65535)
    db_path: Path = Path("data/hmi.db")
    # design.md §10.5: a postgresql:// URL (HMI_DB_URL, or --db URL) puts the HMI on a plant's shared
    # PostgreSQL database instead of the SQLite file; machine_name names this HMI's rows there
    db_url: str | None = None
    machine_name: str = Field(default_factory=default_machine_name, pattern=f"^{MACHINE_NAME.pattern}$")
    scenario_path: Path | None = None          # None = the built-in demo scenario
    time_scale: float | None = Field(default=None, ge=0)  # overrides the scenario's machine.time_scale
    machine: str = "sim"                       # the controller, a name of app.machine.registry (design.md §9.6)
    # design.md §10.7: the machine's own LinuxCNC INI (run headless, or attached to when it runs);
    # None = the product's generated configuration with the simulated probe
    linuxcnc_ini: Path | None = None
    # Host names the HMI answers to besides the loopback names (DNS rebinding guard, design.md §9.2);
    # HMI_TRUSTED_HOSTS='["hmi.plant.local", "10.0.0.5"]' or --trusted-host NAME (repeatable)
    trusted_hosts: list[str] = Field(default_factory=list)
    session_hours: float = Field(default=8.0, gt=0, le=24 * 30)   # a sign-in lasts one shift by default
    # design.md §9.7: also serve OPC UA (opc.tcp://host:PORT) in this process; None = off.
    # opcua_umati adds the umati MachineTool instance (loaded in the background after the start)
    opcua_port: int | None = Field(default=None, ge=1, le=65535)
    opcua_umati: bool = False
    mtconnect_port: int | None = Field(default=None, ge=1, le=65535)   # an MTConnect SHDR adapter; None = off

    @property
    def database(self) -> str | Path:
        """What ``db.Database`` opens: the URL when one is given, else the SQLite file."""
        return self.db_url or self.db_path

"""``python -m app [--host 127.0.0.1] [--port 8000] [--db PATH] [--scenario PATH]`` (design.md §4)."""

from __future__ import annotations

import argparse
from pathlib import Path

from app.config import Settings


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="python -m app", description="Measure-in-JOG HMI (simulated machine)")
    parser.add_argument("--host", default=None, help="bind address (default 127.0.0.1)")
    parser.add_argument("--port", type=int, default=None, help="TCP port (default 8000)")
    parser.add_argument("--db", type=Path, default=None, help="SQLite file (default data/hmi.db)")
    parser.add_argument("--scenario", type=Path, default=None, help="scenario JSON (default: built-in demo)")
    parser.add_argument("--time-scale", type=float, default=None,
                        help="override the scenario's machine.time_scale (0 = no waiting)")
    return parser.parse_args(argv)


def settings_from_args(args: argparse.Namespace) -> Settings:
    """Command-line values over ``HMI_*`` environment values over the defaults."""
    given = {"host": args.host, "port": args.port, "db_path": args.db,
             "scenario_path": args.scenario, "time_scale": args.time_scale}
    return Settings(**{k: v for k, v in given.items() if v is not None})


def main(argv: list[str] | None = None) -> None:
    import uvicorn

    from app.main import create_app

    settings = settings_from_args(parse_args(argv))
    uvicorn.run(create_app(settings), host=settings.host, port=settings.port, log_level="info")


if __name__ == "__main__":
    main()

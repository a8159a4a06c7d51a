"""``python -m app [--host 127.0.0.1] [--port 8000] [--db PATH|URL] [--machine-name NAME] [--scenario PATH] [--machine sim]
[--opcua PORT [--opcua-umati]] [--mtconnect PORT]`` (design.md §4, §9.6, §9.7) serves the HMI, with
``--opcua`` also OPC UA, with ``--mtconnect`` an MTConnect SHDR adapter (docs/opcua.md);
the access subcommands (design.md §9.2) work on the database:

    python -m app [--db PATH] user add NAME --level L      (password on stdin; switches sign-in on)
    python -m app [--db PATH] user list | user delete NAME | user passwd NAME
    python -m app [--db PATH] token add NAME --level L     (prints the new token once)
    python -m app [--db PATH] token list | token delete NAME
    python -m app [--db PATH] keyswitch [POSITION]          (show or turn the simulated keyswitch)
    python -m app [--db PATH] opcua trust add|list|remove CERT  (the OPC UA client certificates trusted)
    python -m app [--db PATH] [--scenario PATH] commissioning [--json]  (the start-up checks of manual ch. 9-10)

Without users the HMI is the stand-alone trainer and binds only to loopback: a ``--host`` other than
loopback is refused until a user exists.
"""

from __future__ import annotations

import argparse
import getpass
import logging
import sys
import threading
from pathlib import Path

from app.config import Settings
from app.machine import registry
from db import StorageUnavailable

log = logging.getLogger(__name__)


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="python -m app", description="Measure-in-JOG HMI (the simulated machine by default)")
    parser.add_argument("--host", default=None, help="bind address (default 127.0.0.1; another needs a user)")
    parser.add_argument("--port", type=int, default=None, help="TCP port (default 8000)")
    parser.add_argument("--db", default=None, metavar="PATH|URL",
                        help="SQLite file (default data/hmi.db) or a plant's PostgreSQL database, "
                             "postgresql+psycopg://USER@HOST/DBNAME (design.md §10.5; also HMI_DB_URL)")
    parser.add_argument("--machine-name", default=None, metavar="NAME",
                        help="this HMI's name on a shared database (default: the host name)")
    parser.add_argument("--scenario", type=Path, default=None, help="scenario JSON (default: built-in demo)")
    parser.add_argument("--time-scale", type=float, default=None,
                        help="override the scenario's machine.time_scale (0 = no waiting)")
    parser.add_argument("--machine", choices=registry.names(), default=None,
                        help=f"the controller behind the HMI (default {registry.DEFAULT})")
    parser.add_argument("--linuxcnc-ini", type=Path, default=None, metavar="PATH",
                        help="with --machine linuxcnc (implied): the machine's own LinuxCNC INI, run headless or "
                             "attached to when it runs already (design.md §10.7)")
    parser.add_argument("--trusted-host", action="append", default=None, metavar="NAME",
                        help="a Host name the HMI answers to besides the loopback names (repeatable)")
    parser.add_argument("--opcua", type=int, default=None, metavar="PORT",
                        help="also serve OPC UA at opc.tcp://HOST:PORT (design.md §9.7)")
    parser.add_argument("--opcua-umati", action="store_true", default=None,
                        help="with --opcua: add the umati MachineTool instance (loaded in the background)")
    parser.add_argument("--mtconnect", type=int, default=None, metavar="PORT",
                        help="also serve an MTConnect SHDR adapter at HOST:PORT for an MTConnect agent")
    commands = parser.add_subparsers(dest="command", metavar="{user,token,keyswitch,opcua,commissioning}",
                                     help="access administration (without one: serve the HMI)")
    user = commands.add_parser("user", help="users who sign in with a password (levels 1-3)")
    user_cmd = user.add_subparsers(dest="action", required=True)
    add = user_cmd.add_parser("add", help="create a user; the password is read from stdin")
    add.add_argument("name")
    add.add_argument("--level", type=int, required=True, choices=(1, 2, 3),
                     help="1 manufacturer, 2 service, 3 user")
    user_cmd.add_parser("list", help="the users and their levels")
    delete = user_cmd.add_parser("delete", help="remove a user (their sessions end)")
    delete.add_argument("name")
    passwd = user_cmd.add_parser("passwd", help="set a new password (from stdin)")
    passwd.add_argument("name")
    token = commands.add_parser("token", help="API tokens for automation (Authorization: Bearer)")
    token_cmd = token.add_subparsers(dest="action", required=True)
    tadd = token_cmd.add_parser("add", help="create a token and print it once")
    tadd.add_argument("name")
    tadd.add_argument("--level", type=int, required=True, choices=range(1, 8), metavar="{1..7}")
    token_cmd.add_parser("list", help="the tokens and their levels (never the secret)")
    tdel = token_cmd.add_parser("delete", help="revoke a token")
    tdel.add_argument("name")
    key = commands.add_parser("keyswitch", help="show or turn the simulated keyswitch (0..3 = level 7..4)")
    key.add_argument("position", nargs="?", type=int, choices=(0, 1, 2, 3))
    opcua = commands.add_parser("opcua", help="the OPC UA trust list of client certificates")
    opcua_cmd = opcua.add_subparsers(dest="action", required=True)
    trust = opcua_cmd.add_parser("trust", help="trust add CERT | trust list | trust remove THUMBPRINT|FILE")
    trust.add_argument("trust_action", choices=("add", "list", "remove"))
    trust.add_argument("cert", nargs="?", help="add: a certificate file (DER or PEM); remove: thumbprint or file")
    commissioning = commands.add_parser(
        "commissioning", help="the start-up checks of the measuring cycles (manual ch. 9-10); exit 1 when one fails")
    commissioning.add_argument("--json", action="store_true", help="print GET /api/commissioning/checks' answer")
    return parser.parse_args(argv)


def run_commissioning_command(args: argparse.Namespace, settings: Settings) -> int:
    """``commissioning``: each check of app.services.commissioning on the machine of ``--scenario``
    and the database's settings; one line per check, or the API's JSON; 1 when one fails."""
    import json

    from app.main import build_services
    from app.services.commissioning import CommissioningService
    from app.services.scenarios import read_scenario

    services = build_services(settings, read_scenario(settings))
    try:
        report = CommissioningService(services).report()
    finally:
        if services.nc is not None:
            services.nc.close()
        services.machine.close()
        services.db.close()
    if args.json:
        print(json.dumps(report, ensure_ascii=False, indent=1))
    else:
        for check in report["checks"]:
            state = {True: "ok  ", False: "FAIL", None: "--  "}[check["ok"]]
            print(f"{state} {check['section']:<7} {check['item']:<36} {check['value']!s:<14} {check['rule']}")
        print(f"{len(report['checks']) - report['failed']} of {len(report['checks'])} checks passed")
    return 0 if report["ok"] else 1


def run_trust_command(args: argparse.Namespace, settings: Settings) -> int:
    """``opcua trust add|list|remove`` (design.md §10.8): the folder beside the database."""
    from app.opcua.trust import TrustList

    trust = TrustList(settings.db_path.parent)
    if args.trust_action == "list":
        for entry in trust.entries():
            print(f"{entry['thumbprint']}  {entry['subject']}  ({entry['file']})")
        rejected = sorted(p.name for p in trust.rejected.glob("*.der")) if trust.rejected.is_dir() else []
        for name in rejected:
            print(f"rejected: {trust.rejected / name}")
        return 0
    if not args.cert:
        print(f"python -m app: opcua trust {args.trust_action} needs a certificate", file=sys.stderr)
        return 2
    if args.trust_action == "add":
        try:
            entry = trust.add(Path(args.cert))
        except (OSError, ValueError) as exc:
            print(f"python -m app: {args.cert} is no readable certificate ({exc})", file=sys.stderr)
            return 1
        print(f"trusted {entry['thumbprint']}  {entry['subject']}")
        return 0
    gone = trust.remove(args.cert)
    if not gone:
        print(f"python -m app: no trusted certificate {args.cert}", file=sys.stderr)
        return 1
    print("removed " + ", ".join(gone))
    return 0


def settings_from_args(args: argparse.Namespace) -> Settings:
    """Command-line values over ``HMI_*`` environment values over the defaults."""
    db_url = args.db if args.db is not None and "://" in args.db else None
    db_path = Path(args.db) if args.db is not None and db_url is None else None
    given = {"host": args.host, "port": args.port, "db_path": db_path, "db_url": db_url,
             "machine_name": getattr(args, "machine_name", None),
             "scenario_path": args.scenario, "time_scale": args.time_scale, "machine": args.machine,
             "linuxcnc_ini": getattr(args, "linuxcnc_ini", None),
             "trusted_hosts": getattr(args, "trusted_host", None), "opcua_port": getattr(args, "opcua", None),
             "opcua_umati": getattr(args, "opcua_umati", None), "mtconnect_port": getattr(args, "mtconnect", None)}
    if given["linuxcnc_ini"] is not None:
        if args.machine not in (None, "linuxcnc"):
            raise SystemExit(f"python -m app: --linuxcnc-ini runs LinuxCNC; it does not go with --machine {args.machine}")
        given["machine"] = "linuxcnc"
    return Settings(**{k: v for k, v in given.items() if v is not None})


def read_password(stdin=None) -> str:
    """The password from stdin: one line when piped, asked twice on a terminal."""
    stdin = stdin or sys.stdin
    if stdin.isatty():
        first = getpass.getpass("Password: ")
        if getpass.getpass("Repeat: ") != first:
            sys.exit("python -m app: the passwords differ")
        return first
    return stdin.readline().rstrip("\r\n")


def run_access_command(args: argparse.Namespace, settings: Settings) -> int:
    """``user``/``token``/``keyswitch``; 0 on success. The audit names "cli"."""
    from app.access.levels import describe_level, keyswitch_level
    from app.access.service import AccessError, AccessService
    from db import Actor, Database, acting_as

    with Database(settings.database, machine=settings.machine_name) as db, acting_as(Actor("cli", 0)):
        access = AccessService(db, settings.session_hours)
        try:
            if args.command == "user":
                if args.action == "add":
                    user = access.add_user(args.name, args.level, read_password())
                    print(f"user {user['name']} added with {describe_level(user['level'])}; sign-in is on")
                elif args.action == "passwd":
                    access.set_password(args.name, read_password())
                    print(f"password of {args.name} changed")
                elif args.action == "delete":
                    access.delete_user(args.name)
                    left = access.list_users()
                    print(f"user {args.name} deleted" + ("" if left else "; no user left: trainer mode (loopback only)"))
                else:
                    for user in access.list_users():
                        print(f"{user['name']}\tlevel {user['level']}\t{user['created']}")
            elif args.command == "token":
                if args.action == "add":
                    secret, record = access.add_token(args.name, args.level)
                    print(secret)
                    print(f"token {record['name']} ({describe_level(record['level'])}): shown only now; "
                          "send it as 'Authorization: Bearer <token>'", file=sys.stderr)
                elif args.action == "delete":
                    access.delete_token(args.name)
                    print(f"token {args.name} revoked")
                else:
                    for record in access.list_tokens():
                        print(f"{record['name']}\tlevel {record['level']}\t{record['created']}")
            elif args.position is None:
                position = access.keyswitch()
                print(f"keyswitch position {position} = level {keyswitch_level(position)}")
            else:
                state = access.set_keyswitch(args.position, source="cli")
                print(f"keyswitch turned to position {state['position']} = level {state['level']}")
        except AccessError as exc:
            print(f"python -m app: {exc}", file=sys.stderr)
            return 1
    return 0


def refuse_open_trainer(settings: Settings) -> str | None:
    """The message that stops a non-loopback ``--host`` while no user exists, else None."""
    from app.access.middleware import is_loopback_host
    from db import Database

    if is_loopback_host(settings.host):
        return None
    with Database(settings.database, machine=settings.machine_name) as db, db.unit(readonly=True) as unit:
        if unit.users_exist():
            return None
    return (f"--host {settings.host} would serve the network, but no user is configured: without users the "
            "HMI is the stand-alone trainer (every function allowed) and serves only this computer. "
            f"Create a user first: python -m app --db {settings.database} user add NAME --level 1")


def endpoint_problem(settings: Settings) -> str | None:
    """A port of the OPC UA endpoint or the MTConnect adapter that cannot be served, as one line
    (before uvicorn starts)."""
    chosen = [(flag, port) for flag, port in (("--opcua", settings.opcua_port),
                                              ("--mtconnect", settings.mtconnect_port)) if port is not None]
    for flag, port in chosen:
        if port == settings.port:
            return f"{flag} {port} is the HTTP port; choose another"
    if len(chosen) == 2 and chosen[0][1] == chosen[1][1]:
        return f"--opcua and --mtconnect both ask for port {chosen[0][1]}; choose two"
    if settings.opcua_port is not None:
        from app.opcua import port_problem

        problem = port_problem(settings.host, settings.opcua_port)
        if problem:
            return problem
    if settings.mtconnect_port is not None:
        from app.mtconnect import port_problem as shdr_port_problem

        return shdr_port_problem(settings.host, settings.mtconnect_port)
    return None


def endpoint_lines(settings: Settings) -> list[str]:
    """Where the shop-floor endpoints listen (docs/opcua.md), one line each."""
    host = f"[{settings.host}]" if ":" in settings.host else settings.host
    lines = []
    if settings.opcua_port is not None:
        umati = " with the umati MachineTool instance (loading)" if settings.opcua_umati else ""
        lines.append(f"OPC UA at opc.tcp://{host}:{settings.opcua_port}{umati}, namespace urn:jog-measure-hmi")
    if settings.mtconnect_port is not None:
        lines.append(f"MTConnect SHDR adapter at {host}:{settings.mtconnect_port}")
    return lines


def main(argv: list[str] | None = None) -> None:
    args = parse_args(argv)
    try:
        settings = settings_from_args(args)
        if args.command == "opcua":
            sys.exit(run_trust_command(args, settings))
        if args.command == "commissioning":
            sys.exit(run_commissioning_command(args, settings))
        if args.command:
            sys.exit(run_access_command(args, settings))
        refusal = refuse_open_trainer(settings)
    except StorageUnavailable as exc:
        sys.exit(f"python -m app: {exc}")
    if refusal:
        sys.exit(f"python -m app: {refusal}")

    import uvicorn

    from app.main import create_app, trusted_hosts

    try:
        app = create_app(settings)
    except (registry.UnknownMachine, StorageUnavailable) as exc:   # a bad HMI_MACHINE; a database
        sys.exit(f"python -m app: {exc}")                          # that cannot be opened or written
    problem = endpoint_problem(settings)
    if problem:
        sys.exit(f"python -m app: {problem}")
    for line in endpoint_lines(settings):
        print(f"python -m app: {line}", file=sys.stderr)
    if settings.host in ("0.0.0.0", "::"):
        print(f"python -m app: serving the network; browsers must use one of the trusted host names "
              f"{', '.join(trusted_hosts(settings))} (add the machine's name with --trusted-host)", file=sys.stderr)
    server = StoppingServer(uvicorn.Config(app, host=settings.host, port=settings.port, log_level="info",
                                           access_log=False),
                            stop_motion=app.state.services.machine.reset)
    server.run()


def _stopping_server_class():
    import uvicorn

    class _StoppingServer(uvicorn.Server):
        """uvicorn's server that stops motion at SIGTERM/SIGINT (issue 34 §4): a graceful shutdown
        waits for running requests, and a measurement's request would run to its end (48 s seen);
        the channel's Reset (design.md §10.1) ends it within LinuxCNC's or the simulator's braking."""

        def __init__(self, config, stop_motion) -> None:
            super().__init__(config)
            self._stop_motion = stop_motion

        def handle_exit(self, sig, frame) -> None:
            if not self.should_exit:
                threading.Thread(target=self._reset, name="stop-motion", daemon=True).start()
            super().handle_exit(sig, frame)

        def _reset(self) -> None:
            try:
                self._stop_motion()
            except Exception:   # noqa: BLE001 - the HMI stops anyway; why the Reset failed is logged
                log.exception("Reset before stopping the HMI")

    return _StoppingServer


def StoppingServer(config, stop_motion):   # noqa: N802 - a class made when uvicorn is imported
    return _stopping_server_class()(config, stop_motion)


if __name__ == "__main__":
    main()

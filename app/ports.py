"""Whether a TCP port of a shop-floor endpoint (OPC UA, MTConnect) can be served, asked before the
start so that a taken port is a one-line error and not a traceback."""

from __future__ import annotations

import errno
import socket


def port_problem(host: str, port: int, what: str, flag: str) -> str | None:
    """Why ``host:port`` cannot be served (in use, not allowed), else None; ``what`` names the
    endpoint ("OPC UA") and ``flag`` the option that chooses the port ("--opcua")."""
    try:
        infos = socket.getaddrinfo(host or None, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE)
    except socket.gaierror as exc:
        return f"{what}: the address {host!r} cannot be resolved ({exc.strerror})"
    for family, kind, proto, _name, address in infos:
        with socket.socket(family, kind, proto) as probe:
            probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)   # as asyncio's server does
            try:
                probe.bind(address)
            except OSError as exc:
                reason = ("is in use by another program" if exc.errno == errno.EADDRINUSE
                          else f"cannot be opened ({exc.strerror})")
                return f"{what} port {port} on {host} {reason}; choose another with {flag} PORT"
    return None

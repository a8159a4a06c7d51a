"""Who is connected: the OPC UA user name token is checked against the HMI's users (design.md
jog-measuring §9.2: the same argon2 hashes, sign-in bounds and levels as ``POST /api/session``); an anonymous session
reads only. Nobody is ever asyncua's ``Admin`` (which could add and delete nodes)."""

from __future__ import annotations

import logging
from contextvars import ContextVar
from dataclasses import dataclass

from asyncua import ua
from asyncua.crypto.permission_rules import USER_TYPES, PermissionRuleset, User, UserRole
from asyncua.server.internal_session import InternalSession
from asyncua.server.user_managers import UserManager

from app.access.service import AccessService, SignInRefused
from app.access.throttle import OPCUA

log = logging.getLogger(__name__)


@dataclass
class HmiUser(User):
    """A signed-in HMI user; the level is read again at every write (it may have changed)."""

    level: int | None = None


class HmiUserManager(UserManager):
    def __init__(self, access: AccessService):
        self._access = access

    def get_user(self, iserver, username: str | None = None, password: str | None = None,
                 certificate=None) -> User | None:
        """None refuses the session (asyncua answers BadUserAccessDenied)."""
        if username is None:
            return User(role=UserRole.Anonymous)
        try:
            identity = self._access.verify_password(username, password or "", (OPCUA, _peer.get()))
        except SignInRefused as exc:
            log.warning("OPC UA sign-in of %r refused: %s", username, exc.message)
            return None
        return HmiUser(role=UserRole.User, name=identity.name, level=identity.level)


# the client address of the session being activated (asyncua's get_user is not told it)
_peer: ContextVar[str] = ContextVar("opcua_peer", default="")


class _PeerSession(InternalSession):
    def activate_session(self, params, peer_certificate):
        peer = self.name[0] if isinstance(self.name, tuple) and self.name else str(self.name)
        token = _peer.set(peer)
        try:
            return super().activate_session(params, peer_certificate)
        finally:
            _peer.reset(token)


def count_sign_ins_per_client(iserver) -> None:
    """Sessions that tell ``HmiUserManager`` their client's address, so failed OPC UA sign-ins are
    throttled per client (app/access/throttle.py), apart from HTTP's."""

    def create_session(name, user: User = User(role=UserRole.Anonymous), external: bool = False):
        return _PeerSession(iserver, iserver.aspace, iserver.subscription_service, name, user=user,
                            external=external)

    iserver.create_session = create_session


class HmiRuleset(PermissionRuleset):
    """Which requests a session may send: anonymous and users the same (read, browse, subscribe,
    call, write; what a write may change is checked per node), nobody the node management ones."""

    def __init__(self):
        self._allowed = {ua.NodeId(ua.Int32(action)) for action in USER_TYPES}

    def check_validity(self, user, action_type_id, body) -> bool:
        return action_type_id in self._allowed

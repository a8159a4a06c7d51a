"""Writes of zero-offset nodes go through the HMI's own path: the level check of the function
"offsets" (``check_actor``, the level the settings name), ``OffsetService.put`` (validation, the
NC's copy, the active frame) and its audit row, which names the user ("user:anna", source
"opcua"). Anonymous sessions and users below the level get ``BadUserAccessDenied``; nothing is
written then. Every other node keeps asyncua's check (read-only nodes refuse every client write).
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Awaitable, Callable

from asyncua import ua
from asyncua.crypto.permission_rules import User, UserRole
from asyncua.server.address_space import AttributeService

from app.access.checks import check_actor
from app.access.errors import AccessDenied
from app.access.levels import required_level
from app.access.service import AccessService
from app.errors import ConflictError, HmiError, InvalidInput, NotFoundError
from app.services import Services
from db import StorageUnavailable, acting_as

from .users import HmiUser

log = logging.getLogger(__name__)
Target = tuple[str, str, str]                      # (offset name, frame component, axis)
Written = Callable[[str, dict], Awaitable[None]]   # shows the stored frame on its nodes
SOURCE = "opcua"

NUMBER_TYPES = {ua.VariantType.Double, ua.VariantType.Float, ua.VariantType.Int16, ua.VariantType.Int32,
                ua.VariantType.Int64, ua.VariantType.UInt16, ua.VariantType.UInt32, ua.VariantType.UInt64,
                ua.VariantType.SByte, ua.VariantType.Byte}


def status(code: int) -> ua.StatusCode:
    return ua.StatusCode(ua.UInt32(code))


def status_of(exc: Exception) -> ua.StatusCode:
    """The service's refusal as an OPC UA status (the reason goes to the log)."""
    if isinstance(exc, AccessDenied):
        return status(ua.StatusCodes.BadUserAccessDenied)
    if isinstance(exc, InvalidInput):
        return status(ua.StatusCodes.BadOutOfRange)
    if isinstance(exc, NotFoundError):
        return status(ua.StatusCodes.BadNodeIdUnknown)
    if isinstance(exc, ConflictError):       # an alarm: the NC cannot hold the frame (LinuxCNC)
        return status(ua.StatusCodes.BadInvalidState)
    if isinstance(exc, StorageUnavailable):
        return status(ua.StatusCodes.BadResourceUnavailable)
    return status(ua.StatusCodes.BadInternalError)


class GuardedAttributeService(AttributeService):
    """asyncua's attribute service with the zero-offset nodes routed to the offsets service."""

    def __init__(self, aspace, services: Services, access: AccessService,
                 targets: dict[ua.NodeId, Target], written: Written):
        super().__init__(aspace)
        self._services = services
        self._access = access
        self._targets = targets
        self._written = written

    async def write(self, params: ua.WriteParameters, user: User = User(role=UserRole.Admin)) -> list[ua.StatusCode]:
        results = []
        for item in params.NodesToWrite:
            target = self._targets.get(item.NodeId)
            if target is None or user.role == UserRole.Admin:     # the server's own writes
                results += await super().write(ua.WriteParameters(NodesToWrite=[item]), user)
            else:
                results.append(await self._write_offset(item, target, user))
        return results

    async def _write_offset(self, item: ua.WriteValue, target: Target, user: User) -> ua.StatusCode:
        if not isinstance(user, HmiUser) or not user.name:
            return status(ua.StatusCodes.BadUserAccessDenied)
        if item.AttributeId != ua.AttributeIds.Value or item.IndexRange:
            return status(ua.StatusCodes.BadUserAccessDenied if item.AttributeId != ua.AttributeIds.Value
                          else ua.StatusCodes.BadIndexRangeInvalid)
        variant = item.Value.Value if item.Value is not None else None
        if variant is None or variant.VariantType not in NUMBER_TYPES or variant.is_array:
            return status(ua.StatusCodes.BadTypeMismatch)
        # the number as sent (an int of any size, a float, NaN): the offsets service checks it with
        # the JSON API's validator (app/checks.py: finite, within the range) -> BadOutOfRange
        value = variant.Value
        name, part, axis = target
        try:
            after = await asyncio.to_thread(self._put, user.name, name, part, axis, value)
        except HmiError as exc:
            log.warning("OPC UA write of %s %s.%s by %s refused: %s", name, part, axis, user.name, exc.message)
            return status_of(exc)
        except StorageUnavailable as exc:
            log.error("OPC UA write of %s: %s", name, exc)
            return status_of(exc)
        await self._written(name, after)
        return status(ua.StatusCodes.Good)

    def _put(self, user: str, name: str, part: str, axis: str, value: int | float) -> dict:
        """In a worker thread, as the user (the audit row names them)."""
        identity = self._access.user_identity(user)
        if identity is None:                       # deleted since the session began
            raise AccessDenied("offsets", required_level(self._services.settings.get(), "offsets"), None,
                               f"user:{user}")
        with acting_as(identity.actor):
            check_actor(self._services.settings, ["offsets"])
            return self._services.offsets.put(name, {part: {axis: value}}, source=SOURCE)

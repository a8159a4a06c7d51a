"""Request body size limit (design.md §9.1): bodies over 1 MiB are answered 413 before they are read.

A pure ASGI middleware: it refuses by Content-Length at once and counts the bytes of a streamed
body, so a large upload never reaches the JSON parser (or the memory).
"""

from __future__ import annotations

import json

MAX_BODY = 1024 * 1024


class BodyTooLarge(Exception):
    pass


def _too_large_body() -> bytes:
    return json.dumps({"error": {"code": "body_too_large",
                                 "message": f"request body larger than {MAX_BODY} bytes"}}).encode()


class BodySizeLimit:
    def __init__(self, app, max_body: int = MAX_BODY):
        self.app = app
        self.max_body = max_body

    async def __call__(self, scope, receive, send):
        if scope["type"] != "http":
            return await self.app(scope, receive, send)
        length = dict(scope.get("headers") or []).get(b"content-length")
        if length is not None and (not length.isdigit() or int(length) > self.max_body):
            return await self._refuse(send)
        seen = 0
        started = False

        async def counted_receive():
            nonlocal seen
            message = await receive()
            if message["type"] == "http.request":
                seen += len(message.get("body", b""))
                if seen > self.max_body:
                    raise BodyTooLarge
            return message

        async def tracking_send(message):
            nonlocal started
            if message["type"] == "http.response.start":
                started = True
            await send(message)

        try:
            await self.app(scope, counted_receive, tracking_send)
        except BodyTooLarge:
            if not started:
                await self._refuse(send)

    @staticmethod
    async def _refuse(send) -> None:
        body = _too_large_body()
        await send({"type": "http.response.start", "status": 413,
                    "headers": [(b"content-type", b"application/json"),
                                (b"content-length", str(len(body)).encode())]})
        await send({"type": "http.response.body", "body": body})

"""Refuses oversized request bodies before they are read, and uploads whose size is not declared."""

from __future__ import annotations

from starlette.requests import Request
from starlette.types import ASGIApp, Receive, Scope, Send

from api.errors import LengthRequired, ServiceError, UploadTooLarge
from api.handlers import error_response

MULTIPART_OVERHEAD_BYTES = 64 * 1024
UPLOAD_PATHS = frozenset({"/submissions", "/ui/submissions"})


class BodyLimitMiddleware:
    """ASGI middleware: 413 for a Content-Length over the limit, 411 for an upload without one.

    Args:
        app: The wrapped application.
        max_upload_bytes: GYMGRADE_MAX_UPLOAD_BYTES; bodies may exceed it by the multipart framing.
    """

    def __init__(self, app: ASGIApp, max_upload_bytes: int) -> None:
        self.app = app
        self.max_body_bytes = max_upload_bytes + MULTIPART_OVERHEAD_BYTES
        self.max_upload_bytes = max_upload_bytes

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        """Check the declared body size, then hand over to the application."""
        if scope["type"] == "http" and scope["method"] in {"POST", "PUT", "PATCH"}:
            error = self._refusal(scope)
            if error is not None:
                response = error_response(Request(scope), error)
                await response(scope, receive, send)
                return
        await self.app(scope, receive, send)

    def _refusal(self, scope: Scope) -> ServiceError | None:
        declared = dict(scope["headers"]).get(b"content-length")
        if declared is None:
            if scope["path"] in UPLOAD_PATHS:
                return LengthRequired("uploads must declare their size in a Content-Length header")
            return None
        if not declared.isdigit() or int(declared) > self.max_body_bytes:
            return UploadTooLarge(
                f"the request body is larger than the limit of {self.max_upload_bytes} bytes for a file; "
                "upload only your opengym.py source"
            )
        return None

"""The one place where domain errors become HTTP responses (JSON for the API, a page for the web UI)."""

from __future__ import annotations

from fastapi import FastAPI, Request
from fastapi.responses import JSONResponse, Response

from api.errors import (
    InstructorOnly,
    InvalidStudentName,
    InvalidUpload,
    LengthRequired,
    NotAuthenticated,
    RateLimited,
    ServiceError,
    StudentExists,
    StudentNotFound,
    StudentOnly,
    SubmissionNotFound,
    UploadTooLarge,
)
from api.web import PAGE_HEADERS, templates

HTTP_STATUS: dict[type[ServiceError], int] = {
    NotAuthenticated: 401,
    InstructorOnly: 403,
    StudentOnly: 403,
    SubmissionNotFound: 404,
    StudentNotFound: 404,
    StudentExists: 409,
    LengthRequired: 411,
    UploadTooLarge: 413,
    InvalidStudentName: 422,
    InvalidUpload: 422,
    RateLimited: 429,
}
UI_PREFIX = "/ui"


def status_of(error: ServiceError) -> int:
    """The HTTP status of a domain error (its nearest mapped class)."""
    for cls in type(error).__mro__:
        if cls in HTTP_STATUS:
            return HTTP_STATUS[cls]
    return 400


def error_response(request: Request, error: ServiceError) -> Response:
    """Render a domain error: ``{"detail": message}`` for the API, the error page for the web UI.

    Args:
        request: The failed request (its path chooses JSON or HTML).
        error: The domain error; its message is shown as is.

    Returns:
        The response with the mapped status and, where HTTP asks for them, WWW-Authenticate or Retry-After.
    """
    status = status_of(error)
    headers: dict[str, str] = {}
    if isinstance(error, NotAuthenticated):
        headers["WWW-Authenticate"] = "Bearer"
    if isinstance(error, RateLimited):
        headers["Retry-After"] = str(error.retry_after_seconds)
    path = request.scope.get("path", "")
    if path == "/" or path.startswith(UI_PREFIX):
        return templates.TemplateResponse(
            request,
            "error.html",
            {"message": str(error), "status": status},
            status_code=status,
            headers={**headers, **PAGE_HEADERS},
        )
    return JSONResponse({"detail": str(error)}, status_code=status, headers=headers)


def install_error_handlers(app: FastAPI) -> None:
    """Route every ServiceError raised by an endpoint through :func:`error_response`."""

    async def handle(request: Request, error: Exception) -> Response:
        if not isinstance(error, ServiceError):
            raise error
        return error_response(request, error)

    app.add_exception_handler(ServiceError, handle)

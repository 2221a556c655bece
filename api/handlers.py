"""The one place where errors become HTTP responses (JSON for the API, a page for the web UI) and documented.

Every non-2xx response of the API is an :class:`api.schemas.ErrorBody`: the domain errors of
:mod:`api.errors`, and the framework's own refusals (a body that does not parse, a request that breaks the
schema, an unknown path or method, a crash), which are first turned into domain errors here.
"""

from __future__ import annotations

from typing import Any

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse, Response
from starlette.exceptions import HTTPException
from starlette.routing import Match, Mount

from api.errors import (
    CourseExists,
    CourseNotFound,
    GradingInProgress,
    InstructorOnly,
    InternalError,
    InvalidRequest,
    InvalidStudentName,
    InvalidUpload,
    LaunchRefused,
    LengthRequired,
    LinkNotFound,
    LtiRequestInvalid,
    MalformedBody,
    MethodNotAllowed,
    NoLatePolicy,
    NotAuthenticated,
    NothingGradedYet,
    OperatorOnly,
    PathNotFound,
    PlatformExists,
    PlatformUnreachable,
    RateLimited,
    ServiceError,
    StaffNotFound,
    StudentExists,
    StudentNotFound,
    StudentOnly,
    SubmissionNotFound,
    UploadTooLarge,
)
from api.schemas import ErrorBody, FieldProblem
from api.web import PAGE_HEADERS, page_headers, templates

HTTP_STATUS: dict[type[ServiceError], int] = {
    MalformedBody: 400,
    LtiRequestInvalid: 400,
    NotAuthenticated: 401,
    InstructorOnly: 403,
    OperatorOnly: 403,
    StudentOnly: 403,
    LaunchRefused: 403,
    PathNotFound: 404,
    SubmissionNotFound: 404,
    StudentNotFound: 404,
    CourseNotFound: 404,
    StaffNotFound: 404,
    LinkNotFound: 404,
    MethodNotAllowed: 405,
    StudentExists: 409,
    CourseExists: 409,
    GradingInProgress: 409,
    NothingGradedYet: 409,
    NoLatePolicy: 409,
    PlatformExists: 409,
    LengthRequired: 411,
    UploadTooLarge: 413,
    InvalidRequest: 422,
    InvalidStudentName: 422,
    InvalidUpload: 422,
    RateLimited: 429,
    InternalError: 500,
    PlatformUnreachable: 502,
}
ERROR_HEADERS: dict[type[ServiceError], dict[str, dict[str, Any]]] = {
    NotAuthenticated: {
        "WWW-Authenticate": {
            "description": "Always `Bearer`: authenticate with `Authorization: Bearer <token>`.",
            "required": True,
            "schema": {"type": "string", "const": "Bearer"},
        }
    },
    RateLimited: {
        "Retry-After": {
            "description": "Seconds until the next upload is accepted.",
            "required": True,
            "schema": {"type": "integer", "minimum": 1, "maximum": 60},
        }
    },
    MethodNotAllowed: {
        "Allow": {
            "description": "The methods the resource supports.",
            "required": True,
            "schema": {"type": "string"},
        }
    },
}
UI_PREFIX = "/ui"
PAGE_PATHS = ("/lti/login", "/lti/launch")
"""Paths a browser reaches from the LMS: their errors are pages too, which any LMS's iframe may show."""
HTTP_METHODS = ("DELETE", "GET", "HEAD", "OPTIONS", "PATCH", "POST", "PUT")
MAX_SHOWN_INPUT_CHARS = 60


def status_of(error: ServiceError) -> int:
    """The HTTP status of a domain error (its nearest mapped class)."""
    for cls in type(error).__mro__:
        if cls in HTTP_STATUS:
            return HTTP_STATUS[cls]
    return 400


def _headers_of(error: ServiceError) -> dict[str, str]:
    if isinstance(error, NotAuthenticated):
        return {"WWW-Authenticate": "Bearer"}
    if isinstance(error, RateLimited):
        return {"Retry-After": str(error.retry_after_seconds)}
    if isinstance(error, MethodNotAllowed):
        return {"Allow": ", ".join(error.allowed)}
    return {}


def error_body(error: ServiceError) -> ErrorBody:
    """The JSON body of an error response."""
    problems = None
    if isinstance(error, InvalidRequest):
        problems = [
            FieldProblem(location=location, message=message, type=kind)
            for location, message, kind in error.problems
        ]
    return ErrorBody(detail=str(error), problems=problems)


def error_response(request: Request, error: ServiceError) -> Response:
    """Render an error: an :class:`ErrorBody` for the API, the error page for the web UI.

    Args:
        request: The failed request (its path chooses JSON or HTML).
        error: The domain error; its message is shown as is.

    Returns:
        The response with the mapped status and, where HTTP asks for them, WWW-Authenticate, Retry-After
        or Allow.
    """
    status = status_of(error)
    headers = _headers_of(error)
    path = request.scope.get("path", "")
    if path == "/" or path.startswith(UI_PREFIX) or path in PAGE_PATHS:
        return templates.TemplateResponse(
            request,
            "error.html",
            {"message": str(error), "status": status},
            status_code=status,
            headers={**headers, **(page_headers("*") if path in PAGE_PATHS else PAGE_HEADERS)},
        )
    return JSONResponse(
        error_body(error).model_dump(mode="json", exclude_none=True), status_code=status, headers=headers
    )


def error_responses(*errors: type[ServiceError]) -> dict[int | str, dict[str, Any]]:
    """The OpenAPI ``responses`` of an operation that can fail with ``errors``.

    Each status gets the :class:`ErrorBody` model, a description made of its errors' docstrings and the
    headers those errors send.

    Args:
        errors: Every domain error the operation (its dependencies and middleware included) can end in.

    Returns:
        A mapping for the ``responses`` argument of a route decorator.
    """
    documented: dict[int | str, dict[str, Any]] = {}
    for error in errors:
        entry = documented.setdefault(HTTP_STATUS[error], {"model": ErrorBody, "description": ""})
        reason = (error.__doc__ or error.__name__).strip().splitlines()[0].replace("Raised when", "When", 1)
        entry["description"] = f"{entry['description']} {reason}".strip()
        if error in ERROR_HEADERS:
            entry.setdefault("headers", {}).update(ERROR_HEADERS[error])
    return dict(sorted(documented.items(), key=lambda item: str(item[0])))


def _shown(value: Any) -> str:
    text = repr(value)
    if len(text) <= MAX_SHOWN_INPUT_CHARS:
        return text
    return text[: MAX_SHOWN_INPUT_CHARS - 3] + "..."


def _from_validation(error: RequestValidationError) -> ServiceError:
    problems: list[tuple[list[str | int], str, str]] = []
    for item in error.errors():
        location = [part if isinstance(part, int) else str(part) for part in item.get("loc", ())]
        message = str(item.get("msg", "invalid"))
        kind = str(item.get("type", "invalid"))
        if kind == "json_invalid":
            reason = item.get("ctx", {}).get("error", message)
            return MalformedBody(
                f"the request body is not valid JSON ({reason} at character {location[-1]}); "
                "send the JSON object this operation documents"
            )
        if kind != "missing" and "input" in item:
            message = f"{message}, found {_shown(item['input'])}"
        problems.append((location, message, kind))
    listed = "; ".join(
        ".".join(str(part) for part in location) + ": " + message for location, message, _ in problems
    )
    return InvalidRequest(f"the request does not match this operation's schema: {listed}", problems)


def allowed_methods(request: Request) -> list[str]:
    """The methods some route of the application accepts at the request's path (static files aside)."""
    routes = [route for route in request.app.router.routes if not isinstance(route, Mount)]
    return [
        method
        for method in HTTP_METHODS
        if any(route.matches({**request.scope, "method": method})[0] is Match.FULL for route in routes)
    ]


def _from_http_exception(request: Request, error: HTTPException) -> ServiceError | None:
    path = request.url.path
    if error.status_code == 400:
        return MalformedBody(
            f"the request body could not be parsed ({error.detail}); "
            "send multipart/form-data for uploads and JSON for everything else, as this operation documents"
        )
    if error.status_code == 404:
        return PathNotFound(f"nothing is at {path}; the API's operations are listed at /docs")
    if error.status_code == 405:
        allowed = allowed_methods(request) or [
            method.strip() for method in (error.headers or {}).get("Allow", "GET, HEAD").split(",")
        ]
        return MethodNotAllowed(
            f"{request.method} is not supported at {path}; use {', '.join(allowed)}", allowed=allowed
        )
    return None


def install_error_handlers(app: FastAPI) -> None:
    """Route every error of the application through :func:`error_response`."""

    async def handle_service_error(request: Request, error: Exception) -> Response:
        if not isinstance(error, ServiceError):
            raise error
        return error_response(request, error)

    async def handle_validation_error(request: Request, error: Exception) -> Response:
        if not isinstance(error, RequestValidationError):
            raise error
        return error_response(request, _from_validation(error))

    async def handle_http_exception(request: Request, error: Exception) -> Response:
        if not isinstance(error, HTTPException):
            raise error
        mapped = _from_http_exception(request, error)
        if mapped is not None:
            return error_response(request, mapped)
        return JSONResponse(
            ErrorBody(detail=str(error.detail)).model_dump(mode="json", exclude_none=True),
            status_code=error.status_code,
            headers=error.headers,
        )

    async def handle_crash(request: Request, _error: Exception) -> Response:
        return error_response(
            request,
            InternalError(
                "the service failed on this request and logged why; "
                "try again, and tell the instructor if it keeps failing"
            ),
        )

    app.add_exception_handler(ServiceError, handle_service_error)
    app.add_exception_handler(RequestValidationError, handle_validation_error)
    app.add_exception_handler(HTTPException, handle_http_exception)
    app.add_exception_handler(Exception, handle_crash)

"""Wires the FastAPI application: settings, start-up, routers, error handlers, body limits."""

from __future__ import annotations

from collections.abc import AsyncIterator
from contextlib import asynccontextmanager
from typing import Any

from fastapi import APIRouter, Depends, FastAPI
from fastapi.routing import APIRoute
from fastapi.staticfiles import StaticFiles

from api.context import ServiceContext
from api.deps import ASSIGNMENT_PREFIX, COURSE_PREFIX, in_assignment, in_course
from api.handlers import install_error_handlers
from api.limits import BodyLimitMiddleware
from api.lti.sessions import redact_access_log
from api.routes import (
    course_pages,
    courses,
    extensions,
    gradebook,
    health,
    lti,
    lti_scoped,
    overrides,
    students,
    submissions,
    ui,
)
from api.settings import Settings, load_settings
from api.web import STATIC_DIR

DESCRIPTION = (
    "Students upload `opengym.py` and get their grade; "
    "the operator creates courses and their staff; "
    "a course's staff create students, see every submission of their course's assignments and export each assignment's gradebook. "  # noqa: E501
    "The routes without a `/courses/{course}` prefix are the embedded default course's and assignment's. "
    "Authenticate with `Authorization: Bearer <token>`."
)


def create_app(settings: Settings | None = None, *, run_workers: bool = True) -> FastAPI:
    """Build the application.

    Args:
        settings: Service settings; read from the environment when None (refusing unsafe values).
        run_workers: Start GYMGRADE_WORKERS grading workers in this process (False: leave grading to
            ``gymgrade worker`` or to the caller).

    Returns:
        The application; the database is connected and migrated when it starts.
    """
    settings = settings or load_settings()

    @asynccontextmanager
    async def lifespan(app: FastAPI) -> AsyncIterator[None]:
        redact_access_log()
        context = ServiceContext.open(settings, pool_size=settings.workers if run_workers else 0)
        app.state.context = context
        try:
            yield
        finally:
            context.close()

    app = FastAPI(title="gymgrade", version="0.1.0", description=DESCRIPTION, lifespan=lifespan)
    app.add_middleware(BodyLimitMiddleware, max_upload_bytes=settings.max_upload_bytes)
    install_error_handlers(app)
    for module in (students, submissions, gradebook, overrides, extensions, health, ui, course_pages, lti):
        app.include_router(module.router)
    app.include_router(ui.assignment_router)
    app.include_router(courses.router)
    app.include_router(courses.course_router)
    app.include_router(lti_scoped.router)
    app.include_router(_mounted_again(students.router, COURSE_PREFIX, in_course, "_of_course"))
    for module in (submissions, gradebook, overrides, extensions):
        app.include_router(_mounted_again(module.router, ASSIGNMENT_PREFIX, in_assignment, SCOPED_SUFFIX))
    app.mount("/ui/static", StaticFiles(directory=STATIC_DIR), name="static")

    def openapi() -> dict[str, Any]:
        if app.openapi_schema is None:
            schema = FastAPI.openapi(app)
            _link_scoped_operations(schema)
            submissions.document_upload_rules(schema, settings.max_upload_bytes)
        return app.openapi_schema or {}

    app.openapi = openapi  # type: ignore[method-assign]  # FastAPI's documented way to extend the schema
    return app


SCOPED_SUFFIX = "_of_assignment"
"""Added to the fixed operation ids of the routes mounted again under an assignment's prefix."""


def _mounted_again(router: APIRouter, prefix: str, declares: Any, suffix: str) -> APIRouter:
    """The routes of ``router`` again under ``prefix`` (whose path parameters ``declares`` states), each with
    its own name and, where the original has a fixed one, operation id (``suffix`` added)."""
    again = APIRouter(prefix=prefix, dependencies=[Depends(declares)])
    for route in router.routes:
        if not isinstance(route, APIRoute):
            raise TypeError(f"only API routes are mounted again under {prefix}; found {route!r}")
        again.add_api_route(
            route.path,
            route.endpoint,
            methods=sorted(route.methods or ()),
            response_model=route.response_model,
            status_code=route.status_code,
            tags=route.tags,
            dependencies=route.dependencies,
            summary=route.summary,
            description=route.description,
            response_description=route.response_description,
            responses=route.responses,
            operation_id=route.operation_id + suffix if route.operation_id else None,
            response_class=route.response_class,
            name=route.name + suffix,
            include_in_schema=route.include_in_schema,
        )
    return again


def _link_scoped_operations(schema: dict[str, Any]) -> None:
    """Point the links of the assignment-prefixed operations at their own prefixed operations, in place."""
    for path, item in schema["paths"].items():
        if not path.startswith(ASSIGNMENT_PREFIX):
            continue
        for operation in item.values():
            for response in operation.get("responses", {}).values():
                links = response.get("links")
                if not links:
                    continue
                response["links"] = {
                    name: {
                        **link,
                        "operationId": link["operationId"] + SCOPED_SUFFIX,
                        "parameters": {
                            **link.get("parameters", {}),
                            "course": "$request.path.course",
                            "assignment": "$request.path.assignment",
                        },
                    }
                    for name, link in links.items()
                }

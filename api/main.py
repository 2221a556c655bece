"""Wires the FastAPI application: settings, start-up, routers, error handlers, body limits."""

from __future__ import annotations

from collections.abc import AsyncIterator
from contextlib import asynccontextmanager
from typing import Any

from fastapi import FastAPI
from fastapi.staticfiles import StaticFiles

from api.context import ServiceContext
from api.handlers import install_error_handlers
from api.limits import BodyLimitMiddleware
from api.lti.sessions import redact_access_log
from api.routes import gradebook, health, lti, overrides, students, submissions, ui
from api.settings import Settings, load_settings
from api.web import STATIC_DIR

DESCRIPTION = (
    "Students upload `opengym.py` and get their grade; "
    "the instructor creates students, sees every submission and exports the gradebook. "
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
    for module in (students, submissions, gradebook, overrides, health, ui, lti):
        app.include_router(module.router)
    app.mount("/ui/static", StaticFiles(directory=STATIC_DIR), name="static")

    def openapi() -> dict[str, Any]:
        if app.openapi_schema is None:
            submissions.document_upload_rules(FastAPI.openapi(app), settings.max_upload_bytes)
        return app.openapi_schema or {}

    app.openapi = openapi  # type: ignore[method-assign]  # FastAPI's documented way to extend the schema
    return app

"""GET /gradebook.csv: every student's latest or best grade."""

from __future__ import annotations

from fastapi import APIRouter
from fastapi.responses import Response

from api.deps import InstructorDep, SessionDep, SettingsDep
from api.errors import InstructorOnly, NotAuthenticated
from api.gradebook import gradebook_csv
from api.handlers import error_responses

router = APIRouter(tags=["gradebook"])


@router.get(
    "/gradebook.csv",
    response_class=Response,
    responses={
        200: {"content": {"text/csv": {}}, "description": "One row per student, one column per problem."},
        **error_responses(NotAuthenticated, InstructorOnly),
    },
)
def get_gradebook(session: SessionDep, settings: SettingsDep, _instructor: InstructorDep) -> Response:
    """The gradebook as CSV: each student's latest or best graded submission (GYMGRADE_GRADEBOOK_POLICY)."""
    return Response(
        gradebook_csv(session, settings.gradebook_policy),
        media_type="text/csv; charset=utf-8",
        headers={"Content-Disposition": 'attachment; filename="gradebook.csv"'},
    )

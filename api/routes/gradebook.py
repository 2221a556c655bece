"""GET /gradebook.csv: every student's latest or best grade."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Query
from fastapi.responses import Response

from api.deps import AssignmentDep, InstructorDep, SessionDep
from api.errors import CourseNotFound, InstructorOnly, InvalidRequest, NotAuthenticated
from api.gradebook import GRADEBOOK_FORMATS, gradebook_export
from api.handlers import error_responses
from grader.classroom.gradebooks import Assignment as GradebookNames

router = APIRouter(tags=["gradebook"])


@router.get(
    "/gradebook.csv",
    response_class=Response,
    responses={
        200: {"content": {"text/csv": {}}, "description": "One row per student, one column per problem."},
        **error_responses(NotAuthenticated, CourseNotFound, InstructorOnly, InvalidRequest),
    },
)
def get_gradebook(
    session: SessionDep,
    assignment: AssignmentDep,
    _instructor: InstructorDep,
    format: Annotated[str, Query(pattern=f"^({'|'.join(GRADEBOOK_FORMATS)})$")] = "gymgrade",
    assignment_title: str | None = None,
    assignment_id: Annotated[str, Query(pattern=r"^\d*$")] = "",
) -> Response:
    """The gradebook as CSV: each student's latest or best graded submission (GYMGRADE_GRADEBOOK_POLICY),
    in gymgrade's columns or an LMS's import format (``canvas`` needs ``assignment_id``); the assignment's
    title is the graded lab's (`OpenGym AI lab`) unless given."""
    if format == "canvas" and not assignment_id:
        message = (
            "format=canvas needs assignment_id (the number in the assignment's Canvas URL .../assignments/ID)"
        )
        raise InvalidRequest(message, [(["query", "assignment_id"], message, "missing")])
    return Response(
        gradebook_export(
            session,
            assignment,
            format,
            GradebookNames(assignment_title or _lab_title(assignment.edition, assignment.lab), assignment_id),
        ),
        media_type="text/csv; charset=utf-8",
        headers={"Content-Disposition": 'attachment; filename="gradebook.csv"'},
    )


def _lab_title(edition: str | None, lab: str | None) -> str:
    from grader.lab.editions.choice import service_edition  # the packs import the checks: only when asked

    return service_edition(edition, lab).lab.assignment_title

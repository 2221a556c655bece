"""One assignment's LTI side, under /courses/{course}/assignments/{assignment}/lti: the resource links that
open it, a roster import through one of them, and its scores' publishing to the LMS. The course's staff (an
instructor or a TA) and the operator reach them; staff of another course find nothing, a student is refused.
The same without a prefix (``api.routes.lti``) are the default course's, and the operator's of every course.
"""

from __future__ import annotations

from fastapi import APIRouter, Depends

from api.deps import ASSIGNMENT_PREFIX, AssignmentDep, ContextDep, InstructorDep, SessionDep, in_assignment
from api.errors import (
    CourseNotFound,
    InstructorOnly,
    InvalidRequest,
    LinkNotFound,
    LtiRequestInvalid,
    NotAuthenticated,
    PlatformUnreachable,
)
from api.handlers import error_responses
from api.lti.people import links_of
from api.lti.publisher import publishing_status
from api.lti.roster import import_roster
from api.models import LtiLink
from api.schemas import LtiLinkView, LtiScoreView, RosterImported
from api.students import MAX_ID

router = APIRouter(tags=["lti"], prefix=ASSIGNMENT_PREFIX + "/lti", dependencies=[Depends(in_assignment)])


@router.get(
    "/links",
    response_model=list[LtiLinkView],
    responses=error_responses(NotAuthenticated, CourseNotFound, InstructorOnly, InvalidRequest),
)
def get_assignment_links(
    session: SessionDep, assignment: AssignmentDep, _staff: InstructorDep
) -> list[LtiLinkView]:
    """The resource links of the LMS that open this assignment (made by their first launch), oldest first."""
    return [
        LtiLinkView.model_validate(link) for link in links_of(session, assignment.course_id, assignment.id)
    ]


@router.post(
    "/links/{link_id}/roster",
    response_model=RosterImported,
    responses=error_responses(
        NotAuthenticated,
        CourseNotFound,
        InstructorOnly,
        LinkNotFound,
        LtiRequestInvalid,
        PlatformUnreachable,
        InvalidRequest,
    ),
)
def post_assignment_roster(
    link_id: int,
    session: SessionDep,
    context: ContextDep,
    assignment: AssignmentDep,
    _staff: InstructorDep,
) -> RosterImported:
    """Import the roster of the link's LMS course (Names and Role Provisioning) into this course: each learner
    gets an enrolment (a gradebook row) and becomes a member of the link."""
    link = session.get(LtiLink, link_id) if 1 <= link_id <= MAX_ID else None
    if link is None or link.assignment_id != assignment.id:
        raise LinkNotFound(
            f"no LTI link {link_id} opens this assignment; list its links with GET .../lti/links"
        )
    found = import_roster(session, link, context.access_tokens)
    return RosterImported(learners=found.learners, staff=found.staff, skipped=found.skipped)


@router.get(
    "/scores",
    response_model=list[LtiScoreView],
    responses=error_responses(NotAuthenticated, CourseNotFound, InstructorOnly, InvalidRequest),
)
def get_assignment_scores(
    session: SessionDep, assignment: AssignmentDep, _staff: InstructorDep
) -> list[LtiScoreView]:
    """Each student's score publishing to the LMS for this assignment: the kept (final: overrides and late
    penalty applied) score, the one the LMS holds, the state, the attempts, the last error."""
    rows = publishing_status(session, assignment.course_id, assignment.id)
    return [LtiScoreView.model_validate(row) for row in rows]

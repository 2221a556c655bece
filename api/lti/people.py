"""Courses of LMS contexts, platform users, links and members.

A course is one context of one deployment of a platform, made by the first launch from it (the first context
ever launched from takes the embedded default course, so a single-course service stays what it was). A link
is keyed by (platform, deployment, resource link id) and opens its own assignment of its context's course
(the default course's first link, the default assignment; every other new link, a new assignment configured
as the default one). A platform user is one person of a platform; in each course they are one enrolment
(student row, made on first sight by a launch or a roster import) or one staff row (instructor or TA, as the
launch's roles say), so a learner in two courses is two enrolments whose scores never mix, and a role counts
in its launch's context only."""

from __future__ import annotations

import secrets
from typing import Any

from sqlalchemy import select
from sqlalchemy.orm import Session

from api.auth import StaffRole
from api.courses import DEFAULT_ASSIGNMENT_ID, DEFAULT_COURSE_ID
from api.lti import claims as names
from api.lti.claims import Role
from api.models import Assignment, Course, LtiLink, LtiMember, LtiPlatform, LtiUser, Staff, Student
from api.security import token_digest
from api.students import MAX_NAME_CHARS, name_taken, normalise_name, printable


def display_name(claims: dict[str, Any], sub: str) -> str:
    """A person's name from the OpenID claims (name, given + family, email), else one made of ``sub``."""
    name = str(claims.get("name") or "").strip()
    if not name:
        name = " ".join(str(claims.get(part) or "").strip() for part in ("given_name", "family_name")).strip()
    if not name:
        name = str(claims.get("email") or "").strip()
    return name or f"lti {sub}"


def _free_name(session: Session, course_id: int, wanted: str, sub: str) -> str:
    try:
        base = normalise_name(wanted.strip()[:MAX_NAME_CHARS])
    except Exception:
        base = normalise_name(f"lti {sub[:80]}")
    for candidate in (base, f"{base} ({sub})", f"{base} ({secrets.token_hex(4)})"):
        candidate = candidate[:MAX_NAME_CHARS].strip()
        if not name_taken(session, course_id, candidate):
            return candidate
    raise RuntimeError("no free student name")  # three distinct names all taken: not reachable in practice


def ensure_user(session: Session, platform: LtiPlatform, sub: str, name: str) -> LtiUser:
    """The platform user keyed by (platform, sub).

    Nothing is committed: the caller commits with the rest of its change.
    """
    user = session.scalars(
        select(LtiUser).where(LtiUser.platform_id == platform.id, LtiUser.sub == sub)
    ).first()
    if user is None:
        user = LtiUser(platform_id=platform.id, sub=sub, name=name[:255])
        session.add(user)
    session.flush()
    return user


def enrolment_of(session: Session, course_id: int, user: LtiUser) -> Student | None:
    """The user's enrolment in the course, None when they have none."""
    query = select(Student).where(Student.course_id == course_id, Student.lti_user_id == user.id)
    return session.scalars(query).first()


def ensure_enrolment(session: Session, course_id: int, user: LtiUser, role: Role) -> Student | None:
    """A learner's enrolment in the course (made on first sight, without a usable token); None for staff.

    Nothing is committed: the caller commits with the rest of its change.
    """
    if role is not Role.LEARNER:
        return None
    student = enrolment_of(session, course_id, user)
    if student is None:
        student = Student(
            course_id=course_id,
            name=_free_name(session, course_id, user.name, user.sub),
            token_sha256=token_digest("lti-" + secrets.token_urlsafe(32)),
            lti_user_id=user.id,
        )
        session.add(student)
        session.flush()
    return student


def ensure_course(
    session: Session, platform: LtiPlatform, deployment_id: str, claims: dict[str, Any]
) -> Course:
    """The course of the launch's context: found by (platform, deployment, context id), else the unclaimed
    default course, else a new course titled after the context. Nothing is committed."""
    context = claims.get(names.CONTEXT) or {}
    context_id = context_id_of(claims)
    course = course_of_context(session, platform.id, deployment_id, context_id)
    if course is not None:
        return course
    default = session.get_one(Course, DEFAULT_COURSE_ID)
    if default.lti_context_id is None:
        course = default
    else:
        title = printable(str(context.get("title") or context.get("label") or context_id), "LMS course")
        course = Course(slug=f"lti-{secrets.token_hex(6)}", title=title)
        session.add(course)
    course.lti_platform_id, course.lti_deployment_id, course.lti_context_id = (
        platform.id,
        deployment_id,
        context_id,
    )
    session.flush()
    return course


def context_id_of(claims: dict[str, Any]) -> str:
    """The id of a launch's context (its course in the LMS), as courses keep it."""
    context = claims.get(names.CONTEXT) or {}
    return str(context.get("id") or "")[:255]


def course_of_context(
    session: Session, platform_id: int, deployment_id: str, context_id: str
) -> Course | None:
    """The course of an LMS context, None before its first launch (nothing is written)."""
    return session.scalars(
        select(Course).where(
            Course.lti_platform_id == platform_id,
            Course.lti_deployment_id == deployment_id,
            Course.lti_context_id == context_id,
        )
    ).first()


LINKED_ASSIGNMENT = "assignment"
"""The custom parameter of a deep link naming the course's assignment it opens (its slug)."""


def named_assignment(session: Session, course_id: int | None, custom: object) -> Assignment | None:
    """The assignment of course ``course_id`` a link's custom parameters name (``LINKED_ASSIGNMENT``, as the
    lab picker writes it), None when they name none or one the course does not have."""
    slug = custom.get(LINKED_ASSIGNMENT) if isinstance(custom, dict) else None
    if course_id is None or not isinstance(slug, str):
        return None
    return session.scalars(
        select(Assignment).where(Assignment.course_id == course_id, Assignment.slug == slug)
    ).first()


def _assignment_for_new_link(session: Session, course: Course, title: str, custom: object) -> int:
    """The assignment a new link of the course opens: the course's assignment its custom parameters name (a
    deep link picked it), else the default assignment for the default course's first link, else a new one
    configured as the default assignment (the service's lab, edition and policies)."""
    named = named_assignment(session, course.id, custom)
    if named is not None:
        return named.id
    if course.id == DEFAULT_COURSE_ID:
        linked = session.scalars(
            select(LtiLink.id).where(LtiLink.assignment_id == DEFAULT_ASSIGNMENT_ID)
        ).first()
        if linked is None:
            return DEFAULT_ASSIGNMENT_ID
    default = session.get_one(Assignment, DEFAULT_ASSIGNMENT_ID)
    columns = ("lab", "edition", "config_toml", "seed_policy", "seed", "release_seeds", "due_date")
    assignment = Assignment(
        course_id=course.id,
        slug=f"lti-{secrets.token_hex(6)}",
        title=printable(title, "LMS assignment"),
        gradebook_policy=default.gradebook_policy,
        late_policy=default.late_policy,
        **{column: getattr(default, column) for column in columns},
    )
    session.add(assignment)
    session.flush()
    return assignment.id


def ensure_staff(session: Session, course_id: int, user: LtiUser, teaching_assistant: bool) -> Staff:
    """The user as the course's staff, with the role the launch's roles give (a TA, or an instructor)."""
    role = (StaffRole.TA if teaching_assistant else StaffRole.INSTRUCTOR).value
    staff = session.scalars(
        select(Staff).where(Staff.course_id == course_id, Staff.lti_user_id == user.id)
    ).first()
    if staff is None:
        staff = Staff(course_id=course_id, lti_user_id=user.id, name=user.name[:100], role=role)
        session.add(staff)
    staff.role = role
    session.flush()
    return staff


def ensure_link(
    session: Session, platform: LtiPlatform, deployment_id: str, claims: dict[str, Any]
) -> LtiLink:
    """The resource link a launch names, keyed by (platform, deployment, link id), its service URLs and
    custom parameters brought up to date; a new link opens a new assignment of its context's course."""
    resource = claims.get(names.RESOURCE_LINK) or {}
    context = claims.get(names.CONTEXT) or {}
    ags = claims.get(names.AGS_ENDPOINT) or {}
    nrps = claims.get(names.NRPS) or {}
    link_id = str(resource.get("id"))
    link = existing_link(session, platform, deployment_id, claims)
    if link is None:
        course = ensure_course(session, platform, deployment_id, claims)
        title = str(resource.get("title") or context.get("title") or "")
        link = LtiLink(
            platform_id=platform.id,
            deployment_id=deployment_id,
            resource_link_id=link_id,
            assignment_id=_assignment_for_new_link(session, course, title, claims.get(names.CUSTOM)),
            lineitem_url=None,
        )
        session.add(link)
    link.context_id = str(context.get("id") or "")
    link.title = str(resource.get("title") or context.get("title") or "")[:255]
    link.lineitems_url = ags.get("lineitems") or link.lineitems_url
    link.lineitem_url = ags.get("lineitem") or link.lineitem_url
    link.ags_scopes = [str(scope) for scope in ags.get("scope") or []]
    link.memberships_url = nrps.get("context_memberships_url") or link.memberships_url
    custom = claims.get(names.CUSTOM)
    link.custom = {str(k): str(v) for k, v in custom.items()} if isinstance(custom, dict) else {}
    session.flush()
    return link


def existing_link(
    session: Session, platform: LtiPlatform, deployment_id: str, claims: dict[str, Any]
) -> LtiLink | None:
    """The resource link a launch names, if a launch made it before (nothing is written)."""
    resource = claims.get(names.RESOURCE_LINK) or {}
    return session.scalars(
        select(LtiLink).where(
            LtiLink.platform_id == platform.id,
            LtiLink.deployment_id == deployment_id,
            LtiLink.resource_link_id == str(resource.get("id")),
        )
    ).first()


def course_of(session: Session, link: LtiLink) -> int:
    """The id of the course whose assignment the link opens."""
    return session.get_one(Assignment, link.assignment_id).course_id


def links_of(session: Session, course_id: int | None, assignment_id: int | None = None) -> list[LtiLink]:
    """The resource links opening the assignment ``assignment_id`` (None: any) of course ``course_id`` (None:
    any course), oldest first."""
    query = select(LtiLink).join(Assignment, Assignment.id == LtiLink.assignment_id).order_by(LtiLink.id)
    if course_id is not None:
        query = query.where(Assignment.course_id == course_id)
    if assignment_id is not None:
        query = query.where(LtiLink.assignment_id == assignment_id)
    return list(session.scalars(query))


def ensure_member(session: Session, link: LtiLink, user: LtiUser) -> LtiMember:
    """The user as a member of the link (their enrolment's scores in the link's assignment go to the
    link's line item)."""
    member = session.scalars(
        select(LtiMember).where(LtiMember.link_id == link.id, LtiMember.user_id == user.id)
    ).first()
    if member is None:
        member = LtiMember(link_id=link.id, user_id=user.id)
        session.add(member)
        session.flush()
    return member

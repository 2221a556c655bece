"""Platform users, links and members: a learner's student row is made on first sight (launch or roster)."""

from __future__ import annotations

import secrets
from typing import Any

from sqlalchemy import select
from sqlalchemy.orm import Session

from api.lti import claims as names
from api.lti.claims import Role
from api.models import LtiLink, LtiMember, LtiPlatform, LtiUser, Student
from api.security import token_digest
from api.students import MAX_NAME_CHARS, normalise_name


def display_name(claims: dict[str, Any], sub: str) -> str:
    """A person's name from the OpenID claims (name, given + family, email), else one made of ``sub``."""
    name = str(claims.get("name") or "").strip()
    if not name:
        name = " ".join(str(claims.get(part) or "").strip() for part in ("given_name", "family_name")).strip()
    if not name:
        name = str(claims.get("email") or "").strip()
    return name or f"lti {sub}"


def _free_name(session: Session, wanted: str, sub: str) -> str:
    try:
        base = normalise_name(wanted.strip()[:MAX_NAME_CHARS])
    except Exception:
        base = normalise_name(f"lti {sub[:80]}")
    for candidate in (base, f"{base} ({sub})", f"{base} ({secrets.token_hex(4)})"):
        candidate = candidate[:MAX_NAME_CHARS].strip()
        if session.scalars(select(Student.id).where(Student.name == candidate)).first() is None:
            return candidate
    raise RuntimeError("no free student name")  # three distinct names all taken: not reachable in practice


def ensure_user(session: Session, platform: LtiPlatform, sub: str, name: str, role: Role) -> LtiUser:
    """The platform user keyed by (platform, sub); a learner gets a student row (without a usable token).

    Nothing is committed: the caller commits with the rest of its change.
    """
    user = session.scalars(
        select(LtiUser).where(LtiUser.platform_id == platform.id, LtiUser.sub == sub)
    ).first()
    if user is None:
        user = LtiUser(platform_id=platform.id, sub=sub, name=name[:255])
        session.add(user)
    if role is Role.LEARNER and user.student_id is None:
        student = Student(
            name=_free_name(session, name, sub), token_sha256=token_digest("lti-" + secrets.token_urlsafe(32))
        )
        session.add(student)
        session.flush()
        user.student_id = student.id
    session.flush()
    return user


def ensure_link(
    session: Session, platform: LtiPlatform, deployment_id: str, claims: dict[str, Any]
) -> LtiLink:
    """The resource link a launch names, its service URLs and custom parameters brought up to date."""
    resource = claims.get(names.RESOURCE_LINK) or {}
    context = claims.get(names.CONTEXT) or {}
    ags = claims.get(names.AGS_ENDPOINT) or {}
    nrps = claims.get(names.NRPS) or {}
    link_id = str(resource.get("id"))
    link = session.scalars(
        select(LtiLink).where(LtiLink.platform_id == platform.id, LtiLink.resource_link_id == link_id)
    ).first()
    if link is None:
        link = LtiLink(platform_id=platform.id, resource_link_id=link_id, lineitem_url=None)
        session.add(link)
    link.deployment_id = deployment_id
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


def ensure_member(session: Session, link: LtiLink, user: LtiUser) -> LtiMember:
    """The user as a member of the link (scores of the user's student go to the link's line item)."""
    member = session.scalars(
        select(LtiMember).where(LtiMember.link_id == link.id, LtiMember.user_id == user.id)
    ).first()
    if member is None:
        member = LtiMember(link_id=link.id, user_id=user.id)
        session.add(member)
        session.flush()
    return member

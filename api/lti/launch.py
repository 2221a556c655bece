"""OIDC third-party login initiation and the launch, with every check LTI 1.3 (Core, Security) asks for.

The state is a short-lived JWT the tool signs (``purpose`` "lti-state", the nonce, the platform, and the
digest of the browser's secret, ``bind``: api/lti/binding.py), posted back by the platform with the
id_token; the launch is accepted only from the browser holding the secret (a cookie, or the platform's
storage). The nonce is stored when a launch is accepted: a second launch with it is refused. Every check
runs before anything is written; a refused launch stores nothing.
"""

from __future__ import annotations

import secrets
import time
from dataclasses import dataclass
from datetime import UTC, datetime, timedelta
from typing import Any
from urllib.parse import urlencode, urlsplit

from joserfc import jwt
from joserfc.errors import ExpiredTokenError, JoseError
from joserfc.jws import extract_compact
from sqlalchemy import delete
from sqlalchemy.exc import IntegrityError
from sqlalchemy.orm import Session

from api.errors import LaunchRefused, LtiRequestInvalid
from api.lti import claims as names
from api.lti.binding import matches
from api.lti.claims import Role, is_teaching_assistant, role_of
from api.lti.keys import ALGORITHM, published_keys, sign
from api.lti.people import (
    course_of,
    display_name,
    ensure_course,
    ensure_enrolment,
    ensure_link,
    ensure_member,
    ensure_staff,
    ensure_user,
)
from api.lti.platforms import PlatformKeys, find_platform
from api.lti.sessions import SESSION_PREFIX
from api.models import LtiLink, LtiNonce, LtiPlatform, LtiSession, LtiUser, utcnow
from api.security import token_digest

STATE_SECONDS = 600
"""How long a login may take between initiation and launch."""
LEEWAY_SECONDS = 60
"""Clock difference tolerated between the platform and the tool (exp, iat, nbf)."""
STATE_PURPOSE = "lti-state"
FRAME_ORIGINS_CHARS = 500
"""The longest frame-ancestors list a session keeps (its column's size)."""


@dataclass(frozen=True)
class Login:
    """Where a login initiation sends the browser, the state it made, and the platform's auth URL."""

    url: str
    state: str
    auth_url: str


def login_redirect(session: Session, params: dict[str, str], launch_url: str, *, bind: str) -> Login:
    """Answer an OIDC third-party login initiation: the platform's authorisation URL to redirect to.

    Args:
        session: A database session (the signing key is made on first use).
        params: The initiation's parameters (query or form): iss, login_hint, target_link_uri, and
            lti_message_hint, client_id, lti_deployment_id when the platform sends them.
        launch_url: The tool's launch URL (the redirect_uri it registered): target_link_uri must be it
            (a query aside).
        bind: The digest of the browser's secret, carried by the state.

    Raises:
        LtiRequestInvalid: A required parameter is missing, or target_link_uri is not the launch URL.
        LaunchRefused: The issuer (and client id) is not registered.
    """
    missing = [name for name in ("iss", "login_hint", "target_link_uri") if not params.get(name)]
    if missing:
        raise LtiRequestInvalid(
            f"an LTI login initiation needs {', '.join(missing)}; found only {', '.join(sorted(params)) or 'nothing'}"  # noqa: E501
        )
    target = params["target_link_uri"]
    if _without_query(target) != launch_url:
        raise LtiRequestInvalid(
            f"target_link_uri {target!r} is not this tool's launch URL (expected {launch_url}); "
            "check the tool's launch URL in the LMS"
        )
    platform = find_platform(session, params["iss"], params.get("client_id"))
    deployment = params.get("lti_deployment_id")
    if deployment and deployment not in platform.deployment_ids:
        raise LaunchRefused(_unknown_deployment(deployment, platform))
    nonce = secrets.token_urlsafe(24)
    now = int(time.time())
    state = sign(
        session,
        {
            "purpose": STATE_PURPOSE,
            "platform": platform.id,
            "nonce": nonce,
            "bind": bind,
            "store": params.get("lti_storage_target") or None,
            "target": target,
            "iat": now,
            "exp": now + STATE_SECONDS,
        },
    )
    query = {
        "scope": "openid",
        "response_type": "id_token",
        "response_mode": "form_post",
        "prompt": "none",
        "client_id": platform.client_id,
        "redirect_uri": launch_url,
        "login_hint": params["login_hint"],
        "state": state,
        "nonce": nonce,
    }
    if params.get("lti_message_hint"):
        query["lti_message_hint"] = params["lti_message_hint"]
    separator = "&" if urlsplit(platform.auth_url).query else "?"
    return Login(platform.auth_url + separator + urlencode(query), state, platform.auth_url)


@dataclass(frozen=True)
class Launch:
    """An accepted launch: its platform, the verified claims, and the service's role for the user."""

    platform: LtiPlatform
    claims: dict[str, Any]
    role: Role
    message_type: str
    deployment_id: str


def verify_launch(
    session: Session,
    keys: PlatformKeys,
    id_token: str,
    state: str,
    *,
    grace_seconds: float,
    browser_secret: str | None,
) -> Launch:
    """Check a launch (the form post of id_token and state, from the browser holding ``browser_secret``)
    without writing anything.

    Raises:
        LaunchRefused: Any check failed; the message names it, what was expected and what was found.
    """
    if not id_token or not state:
        raise LaunchRefused(
            "an LTI launch posts id_token and state; found " + ("no state" if id_token else "no id_token")
        )
    state_claims = tool_state(session, state, grace_seconds)
    if not matches(browser_secret, state_claims.get("bind")):
        raise LaunchRefused(
            "this launch did not come from the browser its login started in (the state is bound to that browser by a cookie or the LMS's storage, and this one has neither): "  # noqa: E501
            "a launch replayed from another browser is refused; open the assignment in the LMS again"
        )
    platform = session.get(LtiPlatform, state_claims.get("platform"))
    if platform is None:
        raise LaunchRefused("the launch's state names a platform that is no longer registered")
    try:
        header = extract_compact(id_token.encode("ascii")).protected
    except (JoseError, ValueError, UnicodeError):
        raise LaunchRefused("the id_token is not a compact JWS (header.payload.signature)") from None
    if header.get("alg") != ALGORITHM:
        raise LaunchRefused(
            f"the id_token is signed with {header.get('alg')!r}; LTI 1.3 requires {ALGORITHM}"
        )
    key_set = keys.key_set(platform.jwks_url, header.get("kid"))
    try:
        token = jwt.decode(id_token, key_set, algorithms=[ALGORITHM])
    except JoseError as error:
        raise LaunchRefused(
            f"the id_token's signature does not verify against the platform's keys at {platform.jwks_url} (key id {header.get('kid')!r}: {error.error}); "  # noqa: E501
            f"it was not signed by {platform.issuer}"
        ) from None
    claims = dict(token.claims)
    _check_times(claims)
    _check_claims(claims, platform, state_claims["nonce"])
    if claims.get(names.TARGET_LINK_URI) != state_claims.get("target"):
        raise LaunchRefused(
            f"the id_token's target_link_uri is {claims.get(names.TARGET_LINK_URI)!r}; "
            f"expected {state_claims.get('target')!r}, the one its login was started for"
        )
    role = role_of(claims.get(names.ROLES) or [])
    if role is None:
        raise LaunchRefused(
            f"the launch's roles {claims.get(names.ROLES)!r} include neither a learner nor an instructor or teaching assistant role of the course"  # noqa: E501
        )
    message_type = claims[names.MESSAGE_TYPE]
    if message_type == names.DEEP_LINKING_REQUEST and role is not Role.STAFF:
        raise LaunchRefused("only the course's instructors add the tool to the course (deep linking)")
    return Launch(platform, claims, role, message_type, str(claims[names.DEPLOYMENT_ID]))


def tool_state(session: Session, state: str, grace_seconds: float) -> dict[str, Any]:
    """The claims of a state this tool issued, unexpired (raises LaunchRefused)."""
    try:
        token = jwt.decode(state, published_keys(session, grace_seconds), algorithms=[ALGORITHM])
        jwt.JWTClaimsRegistry(exp={"essential": True}, nonce={"essential": True}).validate(token.claims)
    except ExpiredTokenError:
        raise LaunchRefused(
            "the launch's state has expired: more than 10 minutes passed since the login started; "
            "open the assignment in the LMS again"
        ) from None
    except (JoseError, ValueError, UnicodeError):
        raise LaunchRefused(
            "the launch's state was not issued by this tool (or was altered); open the assignment in the LMS again"  # noqa: E501
        ) from None
    if token.claims.get("purpose") != STATE_PURPOSE:
        raise LaunchRefused("the launch's state is a token this tool issued for something else")
    return dict(token.claims)


def _check_times(claims: dict[str, Any]) -> None:
    registry = jwt.JWTClaimsRegistry(leeway=LEEWAY_SECONDS, exp={"essential": True}, iat={"essential": True})
    try:
        registry.validate(claims)
    except ExpiredTokenError:
        raise LaunchRefused(
            f"the id_token expired at {_when(claims.get('exp'))} (now {_when(time.time())}); "
            "open the assignment in the LMS again"
        ) from None
    except JoseError as error:
        raise LaunchRefused(
            f"the id_token's times are not valid ({error.error}: {error.description})"
        ) from None


def _check_claims(claims: dict[str, Any], platform: LtiPlatform, nonce: str) -> None:
    if claims.get("iss") != platform.issuer:
        raise LaunchRefused(f"the id_token's issuer is {claims.get('iss')!r}; expected {platform.issuer!r}")
    audience = claims.get("aud")
    audiences = [audience] if isinstance(audience, str) else list(audience or [])
    if platform.client_id not in audiences:
        raise LaunchRefused(
            f"the id_token is addressed to {audiences!r}; "
            f"expected this tool's client id {platform.client_id!r}"
        )
    if (len(audiences) > 1 or "azp" in claims) and claims.get("azp") != platform.client_id:
        raise LaunchRefused(
            f"the id_token's azp (authorised party) is {claims.get('azp')!r}; expected this tool's client id {platform.client_id!r}"  # noqa: E501
        )
    if claims.get("nonce") != nonce:
        raise LaunchRefused("the id_token's nonce is not the one this login started with")
    deployment = claims.get(names.DEPLOYMENT_ID)
    if deployment not in platform.deployment_ids:
        raise LaunchRefused(_unknown_deployment(str(deployment), platform))
    if claims.get(names.VERSION) != names.LTI_VERSION:
        raise LaunchRefused(f"the launch's LTI version is {claims.get(names.VERSION)!r}; expected '1.3.0'")
    message_type = claims.get(names.MESSAGE_TYPE)
    if message_type not in names.MESSAGE_TYPES:
        raise LaunchRefused(
            f"the launch's message type is {message_type!r}; expected one of {', '.join(names.MESSAGE_TYPES)}"
        )
    if not isinstance(claims.get("sub"), str) or not claims["sub"]:
        raise LaunchRefused("the launch names no user (sub); anonymous launches are not accepted")
    if message_type == names.RESOURCE_LINK_REQUEST and not (claims.get(names.RESOURCE_LINK) or {}).get("id"):
        raise LaunchRefused("the resource link launch names no resource link (its id is required)")
    if not isinstance(claims.get(names.ROLES), list):
        raise LaunchRefused("the launch carries no roles claim (a list, possibly empty, is required)")


def _unknown_deployment(deployment: str, platform: LtiPlatform) -> str:
    # The registered ids are not listed: whoever sees this page is not signed in.
    return (
        f"deployment {deployment!r} of {platform.issuer} is not registered with this tool; "
        "the instructor adds it (POST /lti/platforms/{id}/deployments)"
    )


def _when(seconds: object) -> str:
    try:
        return datetime.fromtimestamp(float(seconds), UTC).isoformat(timespec="seconds")  # type: ignore[arg-type]
    except (TypeError, ValueError, OverflowError):
        return repr(seconds)


def frame_origins(launch: Launch) -> str:
    """The origins allowed to frame the tool's pages after this launch (CSP frame-ancestors): the LMS's
    return URL's (the page embedding the tool: Canvas's issuer is not the school's host), the issuer's and
    those registered with the platform (browsers check every ancestor: Open edX's learning MFE frames
    the LMS page that frames the tool)."""
    presentation = launch.claims.get(names.LAUNCH_PRESENTATION) or {}
    registered = launch.platform.frame_ancestors or []  # None on a platform row not flushed yet
    urls = [str(presentation.get("return_url") or ""), launch.platform.issuer, *registered]
    origins = dict.fromkeys(_origin(url) for url in urls if urlsplit(url).scheme in ("http", "https"))
    kept: list[str] = []
    for origin in origins:  # whole origins only: a cut one would be another source
        if len(" ".join([*kept, origin])) > FRAME_ORIGINS_CHARS:
            break
        kept.append(origin)
    return " ".join(kept)


def _origin(url: str) -> str:
    parts = urlsplit(url)
    return f"{parts.scheme}://{parts.netloc}"


def _without_query(url: str) -> str:
    parts = urlsplit(url)
    return f"{parts.scheme}://{parts.netloc}{parts.path}"


@dataclass(frozen=True)
class Landing:
    """Where an accepted launch lands: the session token made for the browser, its user and link."""

    token: str
    user: LtiUser
    link: LtiLink | None


def accept_launch(
    session: Session, launch: Launch, *, session_seconds: float, browser_digest: str | None
) -> Landing:
    """Store what an accepted launch brings (the nonce, the user and student, the link, a session bound to
    the browser's cookie of digest ``browser_digest``, or to nothing but its link when None), at once.

    Raises:
        LaunchRefused: The nonce was used before (a replay); nothing is stored.
    """
    now = utcnow()
    session.execute(delete(LtiNonce).where(LtiNonce.expires_at < now))
    session.execute(delete(LtiSession).where(LtiSession.expires_at < now))
    expires = datetime.fromtimestamp(float(launch.claims["exp"]) + LEEWAY_SECONDS, UTC).replace(tzinfo=None)
    session.add(
        LtiNonce(
            nonce=f"{launch.platform.id}:{launch.claims['nonce']}",
            platform_id=launch.platform.id,
            expires_at=max(expires, now),
        )
    )
    try:
        session.flush()
    except IntegrityError:
        session.rollback()
        raise LaunchRefused(
            "this launch was used already (its nonce was seen before): a replayed launch is refused; "
            "open the assignment in the LMS again"
        ) from None
    sub = launch.claims["sub"]
    user = ensure_user(session, launch.platform, sub, display_name(launch.claims, sub))
    link = None
    if launch.message_type == names.RESOURCE_LINK_REQUEST:
        link = ensure_link(session, launch.platform, launch.deployment_id, launch.claims)
        course_id = course_of(session, link)
    else:
        course_id = ensure_course(session, launch.platform, launch.deployment_id, launch.claims).id
    # The launch's roles count in its own context's course only: staff there, or an enrolment there.
    if launch.role is Role.STAFF:
        ensure_staff(session, course_id, user, is_teaching_assistant(launch.claims.get(names.ROLES) or []))
    elif link is not None and ensure_enrolment(session, course_id, user, launch.role) is not None:
        ensure_member(session, link, user)
    token = SESSION_PREFIX + secrets.token_urlsafe(32)
    session.add(
        LtiSession(
            token_sha256=token_digest(token),
            user_id=user.id,
            course_id=course_id,
            link_id=link.id if link is not None else None,
            frame_origin=frame_origins(launch),
            browser_sha256=browser_digest,
            expires_at=now + timedelta(seconds=session_seconds),
        )
    )
    session.commit()
    return Landing(token, user, link)

"""The LTI 1.3 tool's routes: keys, registration, login and launch, deep linking, roster and scores.

Browser-facing routes (login, launch, register, the lab picker) are reached from the LMS; the platform,
registration and key routes are the operator's; the links, rosters and scores are the default course's
staff's (and the operator's). All of them are JSON with a bearer token. None is part of the OpenAPI schema
of the grading API.
"""

from __future__ import annotations

from typing import Annotated, Any
from urllib.parse import urlencode, urlsplit

from fastapi import APIRouter, Form, Request
from fastapi.responses import JSONResponse, RedirectResponse, Response
from pydantic import BaseModel, Field
from sqlalchemy import select
from starlette.concurrency import run_in_threadpool

from api.deps import ContextDep, CourseDep, InstructorDep, OperatorDep, SessionDep, SettingsDep
from api.errors import LtiRequestInvalid
from api.lti import claims as names
from api.lti.deep_linking import (
    check_link_edition,
    choices,
    deep_linking_response,
    graded_edition,
    picker_token,
)
from api.lti.keys import public_jwks, rotate
from api.lti.launch import accept_launch, frame_origins, login_redirect, verify_launch
from api.lti.people import course_of
from api.lti.platforms import PlatformRegistration, add_deployment, register_platform
from api.lti.publisher import publishing_status
from api.lti.registration import ToolUrls, check_ticket, register_dynamically, registration_ticket
from api.lti.roster import import_roster
from api.lti.sessions import SESSION_PARAMETER
from api.models import Assignment, LtiLink, LtiPlatform
from api.settings import Settings
from api.web import page_headers, templates

router = APIRouter(include_in_schema=False)


def tool_urls(request: Request, settings: Settings) -> ToolUrls:
    """The tool's URLs: from GYMGRADE_PUBLIC_URL, else from the request's own address."""
    return ToolUrls((settings.public_url or str(request.base_url)).rstrip("/"))


@router.get("/lti/jwks")
def jwks(session: SessionDep, settings: SettingsDep) -> JSONResponse:
    """The tool's public keys (current and, for the grace period, retired)."""
    return JSONResponse(
        public_jwks(session, settings.lti_key_grace_seconds), headers={"Cache-Control": "max-age=300"}
    )


@router.api_route("/lti/login", methods=["GET", "POST"])
async def login(request: Request, context: ContextDep) -> Response:
    """OIDC third-party login initiation: redirect to the platform's authorisation endpoint."""
    params = dict(request.query_params)
    if request.method == "POST":
        params.update({key: str(value) for key, value in (await request.form()).items()})
    urls = tool_urls(request, context.settings)

    def redirect() -> str:  # the database (and the first key's generation) off the event loop
        with context.sessions() as session:
            return login_redirect(session, params, urls.launch, urls.origin)

    target = await run_in_threadpool(redirect)
    return RedirectResponse(target, status_code=302 if request.method == "GET" else 303)


@router.post("/lti/launch")
def launch(
    request: Request,
    session: SessionDep,
    context: ContextDep,
    id_token: Annotated[str, Form()] = "",
    state: Annotated[str, Form()] = "",
) -> Response:
    """The launch: verify everything, then land signed in (the upload page, or the lab picker)."""
    settings = context.settings
    checked = verify_launch(
        session, context.platform_keys, id_token, state, grace_seconds=settings.lti_key_grace_seconds
    )
    if checked.message_type == names.DEEP_LINKING_REQUEST:
        token = picker_token(session, checked)
        accept_launch(session, checked, session_seconds=settings.lti_session_seconds)
        return templates.TemplateResponse(
            request,
            "lti_picker.html",
            {
                "choices": choices(),
                "graded": graded_edition(settings.edition, settings.lab),
                "picker": token,
                "session_query": "",
            },
            headers=page_headers(frame_origins(checked)),
        )
    custom = checked.claims.get(names.CUSTOM)
    graded = graded_edition(settings.edition, settings.lab)
    check_link_edition(custom if isinstance(custom, dict) else {}, graded)
    landing = accept_launch(session, checked, session_seconds=settings.lti_session_seconds)
    return RedirectResponse("/?" + urlencode({SESSION_PARAMETER: landing.token}), status_code=303)


@router.post("/lti/deep-link")
def deep_link(
    request: Request,
    session: SessionDep,
    settings: SettingsDep,
    picker: Annotated[str, Form()] = "",
    edition: Annotated[str, Form()] = "",
) -> Response:
    """The instructor's pick: the signed LtiDeepLinkingResponse, posted back to the LMS by the browser."""
    urls = tool_urls(request, settings)
    return_url, response_jwt = deep_linking_response(
        session,
        picker,
        edition,
        urls.launch,
        graded=graded_edition(settings.edition, settings.lab),
        grace_seconds=settings.lti_key_grace_seconds,
    )
    target = urlsplit(return_url)
    headers = page_headers(f"{target.scheme}://{target.netloc}")
    headers["Content-Security-Policy"] = headers["Content-Security-Policy"].replace(
        "form-action 'self'", f"form-action {target.scheme}://{target.netloc}"
    )
    return templates.TemplateResponse(
        request,
        "lti_post.html",
        {"action": return_url, "jwt": response_jwt, "session_query": ""},
        headers=headers,
    )


@router.get("/lti/register")
def dynamic_registration(
    request: Request,
    session: SessionDep,
    settings: SettingsDep,
    openid_configuration: str = "",
    registration_token: str | None = None,
    ticket: str = "",
) -> Response:
    """LTI Dynamic Registration, opened by the platform with the instructor's registration URL."""
    check_ticket(session, ticket, settings.lti_key_grace_seconds)
    if not openid_configuration:
        raise LtiRequestInvalid("the platform opens this URL with openid_configuration; found none")
    platform = register_dynamically(
        session, tool_urls(request, settings), openid_configuration, registration_token
    )
    return templates.TemplateResponse(
        request,
        "lti_registered.html",
        {"platform": platform, "session_query": ""},
        headers=page_headers("*"),
    )


class RegistrationUrl(BaseModel):
    """A URL the LMS administrator gives the LMS for dynamic registration (valid 7 days)."""

    url: str


@router.post("/lti/registrations", status_code=201)
def new_registration(
    request: Request, session: SessionDep, settings: SettingsDep, _operator: OperatorDep
) -> RegistrationUrl:
    """A dynamic registration URL carrying a ticket the tool signed."""
    base = tool_urls(request, settings).base
    return RegistrationUrl(url=f"{base}/lti/register?" + urlencode({"ticket": registration_ticket(session)}))


class PlatformIn(BaseModel):
    """A platform registered by hand, as the LMS's tool registration page shows it."""

    issuer: str = Field(min_length=1, max_length=500)
    client_id: str = Field(min_length=1, max_length=255)
    deployment_ids: list[str] = Field(min_length=1)
    jwks_url: str = Field(min_length=1, max_length=1000)
    auth_url: str = Field(min_length=1, max_length=1000)
    token_url: str = Field(min_length=1, max_length=1000)


def _platform_view(row: LtiPlatform) -> dict[str, Any]:
    return {
        "id": row.id,
        "issuer": row.issuer,
        "client_id": row.client_id,
        "deployment_ids": row.deployment_ids,
        "jwks_url": row.jwks_url,
        "auth_url": row.auth_url,
        "token_url": row.token_url,
    }


@router.post("/lti/platforms", status_code=201)
def post_platform(body: PlatformIn, session: SessionDep, _operator: OperatorDep) -> dict[str, Any]:
    """Register a platform by hand."""
    row = register_platform(
        session,
        PlatformRegistration(
            body.issuer,
            body.client_id,
            tuple(body.deployment_ids),
            body.jwks_url,
            body.auth_url,
            body.token_url,
        ),
    )
    return _platform_view(row)


class DeploymentIn(BaseModel):
    """One more deployment of a registered platform (the LMS shows its id when the tool is deployed)."""

    deployment_id: str = Field(min_length=1, max_length=255)


@router.post("/lti/platforms/{platform_id}/deployments")
def post_deployment(
    platform_id: int, body: DeploymentIn, session: SessionDep, _operator: OperatorDep
) -> dict[str, Any]:
    """Accept launches from one more deployment of a platform."""
    platform = session.get(LtiPlatform, platform_id)
    if platform is None:
        raise LtiRequestInvalid(f"no platform has id {platform_id}; list them with GET /lti/platforms")
    add_deployment(session, platform, body.deployment_id)
    return _platform_view(platform)


@router.get("/lti/platforms")
def get_platforms(session: SessionDep, _operator: OperatorDep) -> list[dict[str, Any]]:
    """The registered platforms."""
    return [_platform_view(row) for row in session.scalars(select(LtiPlatform).order_by(LtiPlatform.id))]


@router.get("/lti/tool")
def tool_configuration(request: Request, settings: SettingsDep, _operator: OperatorDep) -> dict[str, str]:
    """The URLs an administrator enters in the LMS when registering the tool by hand."""
    urls = tool_urls(request, settings)
    return {
        "login_url": urls.login,
        "launch_url": urls.launch,
        "jwks_url": urls.jwks,
        "redirect_uri": urls.launch,
    }


@router.post("/lti/keys/rotate")
def rotate_keys(session: SessionDep, _operator: OperatorDep) -> dict[str, str]:
    """Make a new signing key; the old ones stay published for GYMGRADE_LTI_KEY_GRACE_SECONDS."""
    return {"kid": rotate(session)}


@router.get("/lti/links")
def get_links(session: SessionDep, instructor: InstructorDep, course: CourseDep) -> list[dict[str, Any]]:
    """The resource links students launched from, of the course's assignments (the operator's: all)."""
    query = select(LtiLink).join(Assignment, Assignment.id == LtiLink.assignment_id).order_by(LtiLink.id)
    if not instructor.is_operator:
        query = query.where(Assignment.course_id == course.id)
    return [
        {
            "id": link.id,
            "platform_id": link.platform_id,
            "context_id": link.context_id,
            "resource_link_id": link.resource_link_id,
            "title": link.title,
            "lineitem_url": link.lineitem_url,
            "custom": link.custom,
        }
        for link in session.scalars(query)
    ]


@router.post("/lti/links/{link_id}/roster")
def post_roster(
    link_id: int, session: SessionDep, context: ContextDep, instructor: InstructorDep, course: CourseDep
) -> dict[str, int]:
    """Import the link's course roster (Names and Role Provisioning): a link of the course's only (the
    operator's: any)."""
    link = session.get(LtiLink, link_id)
    if link is None or not (instructor.is_operator or course_of(session, link) == course.id):
        raise LtiRequestInvalid(f"no LTI link has id {link_id}; list them with GET /lti/links")
    found = import_roster(session, link, context.access_tokens)
    return {"learners": found.learners, "staff": found.staff, "skipped": found.skipped}


@router.get("/lti/publisher")
def get_publisher(context: ContextDep, _operator: OperatorDep) -> dict[str, Any]:
    """This server's publishing thread: running, its period, the rounds it finished, the last one's end."""
    if context.publisher is None:
        return {"running": False, "period_seconds": None, "rounds": 0, "last_round_at": None}
    return context.publisher.progress()


@router.get("/lti/scores")
def get_scores(session: SessionDep, instructor: InstructorDep, course: CourseDep) -> list[dict[str, Any]]:
    """Each student's score publishing to the LMS: kept score, the one the LMS holds, state, last error (the
    course's; the operator's: every course's)."""
    return publishing_status(session, None if instructor.is_operator else course.id)

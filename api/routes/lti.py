"""The LTI 1.3 tool's routes: keys, registration, login and launch, deep linking, roster and scores.

Browser-facing routes (login, launch, register, the lab picker) are reached from the LMS; the platform,
registration and key routes are the operator's; the links, rosters and scores here are the default course's
staff's (and the operator's, of every course); one assignment's are ``api.routes.lti_scoped``'s. All of them
are JSON with a bearer token. None is part of the OpenAPI schema of the grading API.
"""

from __future__ import annotations

from typing import Annotated, Any
from urllib.parse import urlencode, urlsplit

from fastapi import APIRouter, Form, Request
from fastapi.responses import JSONResponse, RedirectResponse, Response
from pydantic import BaseModel, Field
from sqlalchemy import select
from sqlalchemy.orm import Session
from starlette.concurrency import run_in_threadpool

from api.deps import ContextDep, CourseDep, InstructorDep, OperatorDep, SessionDep, SettingsDep
from api.errors import LtiRequestInvalid
from api.lti import claims as names
from api.lti.binding import (
    LAUNCH_PATH,
    LOGIN_COOKIE_PREFIX,
    SESSION_COOKIE,
    STORAGE_KEY_PREFIX,
    digest,
    new_secret,
    set_cookie,
    state_name,
)
from api.lti.deep_linking import (
    assignments_offered,
    check_link_edition,
    choices,
    deep_linking_response,
    graded_edition,
    picker_token,
)
from api.lti.keys import public_jwks, rotate
from api.lti.launch import (
    STATE_SECONDS,
    Launch,
    Login,
    accept_launch,
    frame_origins,
    login_redirect,
    tool_state,
    verify_launch,
)
from api.lti.people import (
    context_id_of,
    course_of,
    course_of_context,
    existing_link,
    links_of,
    named_assignment,
)
from api.lti.platforms import PlatformRegistration, add_deployment, checked_origins, register_platform
from api.lti.publisher import publishing_status
from api.lti.registration import ToolUrls, check_ticket, register_dynamically, registration_ticket
from api.lti.roster import import_roster
from api.lti.sessions import SESSION_PARAMETER
from api.models import Assignment, LtiLink, LtiPlatform
from api.schemas import LtiLinkView
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
    """OIDC third-party login initiation: bind the login to the browser (a cookie, and the platform's
    storage when it offers one), then on to the platform's authorisation endpoint."""
    params = dict(request.query_params)
    if request.method == "POST":
        params.update({key: str(value) for key, value in (await request.form()).items()})
    urls = tool_urls(request, context.settings)
    secret, bind = new_secret()

    def redirect() -> Login:  # the database (and the first key's generation) off the event loop
        with context.sessions() as session:
            return login_redirect(session, params, urls.launch, bind=bind)

    started = await run_in_threadpool(redirect)
    name = state_name(started.state)
    storage = params.get("lti_storage_target")
    response: Response
    if storage:
        # A page without anything to click, framed by the LMS whichever page of it frames the tool.
        response = templates.TemplateResponse(
            request,
            "lti_storage.html",
            {
                "action": "put",
                "target": storage,
                "origin": _origin(started.auth_url),
                "key": STORAGE_KEY_PREFIX + name,
                "value": secret,
                "next": started.url,
                "session_query": "",
            },
            headers=page_headers("*"),
        )
    else:
        response = RedirectResponse(started.url, status_code=302 if request.method == "GET" else 303)
    set_cookie(response, LOGIN_COOKIE_PREFIX + name, secret, max_age=STATE_SECONDS, path=LAUNCH_PATH)
    return response


def _origin(url: str) -> str:
    parts = urlsplit(url)
    return f"{parts.scheme}://{parts.netloc}"


@router.post("/lti/launch")
def launch(
    request: Request,
    session: SessionDep,
    context: ContextDep,
    id_token: Annotated[str, Form()] = "",
    state: Annotated[str, Form()] = "",
    storage_answer: Annotated[str | None, Form()] = None,
) -> Response:
    """The launch: verify everything (in the browser the login began in), then land signed in (the upload
    page, or the lab picker)."""
    settings = context.settings
    name = state_name(state)
    from_cookie = request.cookies.get(LOGIN_COOKIE_PREFIX + name)
    if from_cookie is None and storage_answer is None and state:
        stored = _from_platform_storage(request, session, settings, id_token, state)
        if stored is not None:
            return stored
    checked = verify_launch(
        session,
        context.platform_keys,
        id_token,
        state,
        grace_seconds=settings.lti_key_grace_seconds,
        browser_secret=from_cookie or storage_answer,
    )
    # A browser that sent the login's cookie keeps cookies: its session is bound to its browser cookie (the
    # one it has, which its other sessions are bound to, else a new one).
    browser_secret: str | None = None
    browser_digest: str | None = None
    if from_cookie is not None:
        browser_secret = request.cookies.get(SESSION_COOKIE) or new_secret()[0]
        browser_digest = digest(browser_secret)
    response: Response
    if checked.message_type == names.DEEP_LINKING_REQUEST:
        token = picker_token(session, checked)
        accept_launch(
            session, checked, session_seconds=settings.lti_session_seconds, browser_digest=browser_digest
        )
        response = templates.TemplateResponse(
            request,
            "lti_picker.html",
            {
                "choices": choices(),
                "graded": graded_edition(settings.edition, settings.lab),
                "assignments": [
                    (item, graded_edition(item.edition, item.lab))
                    for item in assignments_offered(
                        session, checked.platform.id, checked.deployment_id, context_id_of(checked.claims)
                    )
                ],
                "picker": token,
                "session_query": "",
            },
            headers=page_headers(frame_origins(checked)),
        )
    else:
        custom = checked.claims.get(names.CUSTOM)
        check_link_edition(
            custom if isinstance(custom, dict) else {}, _link_edition(session, settings, checked)
        )
        landing = accept_launch(
            session, checked, session_seconds=settings.lti_session_seconds, browser_digest=browser_digest
        )
        response = RedirectResponse("/?" + urlencode({SESSION_PARAMETER: landing.token}), status_code=303)
    if browser_secret is not None:
        set_cookie(response, SESSION_COOKIE, browser_secret, max_age=settings.lti_session_seconds, path="/")
    return response


def _link_edition(session: Session, settings: Settings, checked: Launch) -> str:
    """The edition a launch's link grades: its assignment's once a launch made it, else (a new link) the
    assignment's of the course its custom parameters name (a deep link to it), else (an assignment made as
    the default one) the service's."""
    link = existing_link(session, checked.platform, checked.deployment_id, checked.claims)
    assignment = session.get(Assignment, link.assignment_id) if link is not None else None
    if assignment is None:
        course = course_of_context(
            session, checked.platform.id, checked.deployment_id, context_id_of(checked.claims)
        )
        assignment = named_assignment(
            session, course.id if course else None, checked.claims.get(names.CUSTOM)
        )
    if assignment is None:
        return graded_edition(settings.edition, settings.lab)
    return graded_edition(assignment.edition, assignment.lab)


def _from_platform_storage(
    request: Request, session: Session, settings: Settings, id_token: str, state: str
) -> Response | None:
    """The page reading the login's secret back from the platform's storage (then posting the launch
    again), when the login stored it there; None when it did not."""
    claims = tool_state(session, state, settings.lti_key_grace_seconds)
    platform = session.get(LtiPlatform, claims.get("platform"))
    target = claims.get("store")
    if not target or platform is None:
        return None
    return templates.TemplateResponse(
        request,
        "lti_storage.html",
        {
            "action": "get",
            "target": target,
            "origin": _origin(platform.auth_url),
            "key": STORAGE_KEY_PREFIX + state_name(state),
            "value": "",
            "next": "",
            "id_token": id_token,
            "state": state,
            "session_query": "",
        },
        headers=page_headers("*"),
    )


@router.post("/lti/deep-link")
def deep_link(
    request: Request,
    session: SessionDep,
    settings: SettingsDep,
    picker: Annotated[str, Form()] = "",
    edition: Annotated[str, Form()] = "",
    assignment: Annotated[str, Form()] = "",
) -> Response:
    """The instructor's pick (an edition, or an assignment of the course): the signed LtiDeepLinkingResponse,
    posted back to the LMS by the browser."""
    urls = tool_urls(request, settings)
    return_url, response_jwt = deep_linking_response(
        session,
        picker,
        edition,
        urls.launch,
        graded=graded_edition(settings.edition, settings.lab),
        grace_seconds=settings.lti_key_grace_seconds,
        assignment=assignment,
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
def dynamic_registration_form(
    request: Request,
    session: SessionDep,
    settings: SettingsDep,
    openid_configuration: str = "",
    registration_token: str = "",
    ticket: str = "",
) -> Response:
    """LTI Dynamic Registration, opened by the platform with the instructor's registration URL: a form whose
    POST registers (a GET registers nothing and leaves the ticket unused)."""
    check_ticket(session, ticket, settings.lti_key_grace_seconds, use=False)
    if not openid_configuration:
        raise LtiRequestInvalid("the platform opens this URL with openid_configuration; found none")
    return templates.TemplateResponse(
        request,
        "lti_register.html",
        {
            "ticket": ticket,
            "openid_configuration": openid_configuration,
            "registration_token": registration_token,
            "session_query": "",
        },
        headers=page_headers("*"),
    )


@router.post("/lti/register")
def dynamic_registration(
    request: Request,
    session: SessionDep,
    context: ContextDep,
    openid_configuration: Annotated[str, Form()] = "",
    registration_token: Annotated[str, Form()] = "",
    ticket: Annotated[str, Form()] = "",
) -> Response:
    """Register: spend the ticket, read the platform's configuration, register the tool there."""
    settings = context.settings
    check_ticket(session, ticket, settings.lti_key_grace_seconds, use=True)
    if not openid_configuration:
        raise LtiRequestInvalid("the registration form carries no openid_configuration; open the URL again")
    platform = register_dynamically(
        session,
        context.outbound,
        tool_urls(request, settings),
        openid_configuration,
        registration_token or None,
        allowed_hosts=settings.lti_hosts,
    )
    return templates.TemplateResponse(
        request,
        "lti_registered.html",
        {"platform": platform, "session_query": ""},
        headers=page_headers("*"),
    )


class RegistrationUrl(BaseModel):
    """A URL the LMS administrator gives the LMS for dynamic registration (used once, valid
    GYMGRADE_LTI_REGISTRATION_TICKET_SECONDS)."""

    url: str


@router.post("/lti/registrations", status_code=201)
def new_registration(
    request: Request, session: SessionDep, settings: SettingsDep, _operator: OperatorDep
) -> RegistrationUrl:
    """A dynamic registration URL carrying a ticket the tool signed."""
    base = tool_urls(request, settings).base
    return RegistrationUrl(
        url=f"{base}/lti/register?"
        + urlencode({"ticket": registration_ticket(session, settings.lti_registration_ticket_seconds)})
    )


class PlatformIn(BaseModel):
    """A platform registered by hand, as the LMS's tool registration page shows it."""

    issuer: str = Field(min_length=1, max_length=500)
    client_id: str = Field(min_length=1, max_length=255)
    deployment_ids: list[str] = Field(min_length=1)
    jwks_url: str = Field(min_length=1, max_length=1000)
    auth_url: str = Field(min_length=1, max_length=1000)
    token_url: str = Field(min_length=1, max_length=1000)
    frame_ancestors: list[str] = Field(default_factory=list, max_length=10)
    """Origins of pages framing the LMS page that frames the tool (Open edX's learning MFE)."""


def _platform_view(row: LtiPlatform) -> dict[str, Any]:
    return {
        "id": row.id,
        "issuer": row.issuer,
        "client_id": row.client_id,
        "deployment_ids": row.deployment_ids,
        "jwks_url": row.jwks_url,
        "auth_url": row.auth_url,
        "token_url": row.token_url,
        "frame_ancestors": row.frame_ancestors,
    }


@router.post("/lti/platforms", status_code=201)
def post_platform(
    body: PlatformIn, session: SessionDep, settings: SettingsDep, _operator: OperatorDep
) -> dict[str, Any]:
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
            tuple(body.frame_ancestors),
        ),
        allow_http=settings.lti_allow_http,
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


class FrameAncestorsIn(BaseModel):
    """The origins, besides the launch's and the issuer's, whose pages frame the tool (every ancestor)."""

    frame_ancestors: list[str] = Field(max_length=10)


@router.put("/lti/platforms/{platform_id}/frame-ancestors")
def put_frame_ancestors(
    platform_id: int,
    body: FrameAncestorsIn,
    session: SessionDep,
    settings: SettingsDep,
    _operator: OperatorDep,
) -> dict[str, Any]:
    """Set the origins that may frame the tool's pages after a launch from this platform."""
    platform = session.get(LtiPlatform, platform_id)
    if platform is None:
        raise LtiRequestInvalid(f"no platform has id {platform_id}; list them with GET /lti/platforms")
    platform.frame_ancestors = checked_origins(body.frame_ancestors, allow_http=settings.lti_allow_http)
    session.commit()
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
def rotate_keys(session: SessionDep, settings: SettingsDep, _operator: OperatorDep) -> dict[str, str]:
    """Make a new signing key; the old ones stay published for GYMGRADE_LTI_KEY_GRACE_SECONDS."""
    return {"kid": rotate(session, settings.lti_key_grace_seconds)}


@router.get("/lti/links")
def get_links(session: SessionDep, instructor: InstructorDep, course: CourseDep) -> list[dict[str, Any]]:
    """The resource links students launched from, of the default course's assignments (the operator's: every
    course's); one assignment's: GET /courses/{course}/assignments/{assignment}/lti/links."""
    links = links_of(session, None if instructor.is_operator else course.id)
    return [LtiLinkView.model_validate(link).model_dump(mode="json") for link in links]


@router.post("/lti/links/{link_id}/roster")
def post_roster(
    link_id: int, session: SessionDep, context: ContextDep, instructor: InstructorDep, course: CourseDep
) -> dict[str, int]:
    """Import the link's course roster (Names and Role Provisioning): a link of the default course's only (the
    operator's: any); one assignment's link: POST .../assignments/{assignment}/lti/links/{id}/roster."""
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
    default course's; the operator's: every course's); one assignment's: GET
    /courses/{course}/assignments/{assignment}/lti/scores."""
    return publishing_status(session, None if instructor.is_operator else course.id)

"""An Open edX LMS on loopback for the LTI tests, whose LTI 1.3 side is Open edX's own code: the
`lti-consumer-xblock` package's :class:`LtiAdvantageConsumer` (not ours).

The consumer builds every launch (the OIDC login initiation URL, the id_token of resource link and deep
linking launches, with the claims Open edX's launch gate sets), grants the client credentials access
tokens (checking the tool's JWT assertion against the tool's JWKS URL) and checks them on every service
call, and decodes the deep linking responses; the launch form is the package's own Django template. This
module serves only the HTTP around it, at Open edX's paths (``/api/lti_consumer/v1/...``), as its Django
views do: one :class:`Passport` (a client id and the LMS's key, ``Lti1p3Passport``) shared by the blocks of
several course runs, deployment id ``"1"`` (Open edX's own), a line item per block made by the LMS
(declarative AGS: the tool may read it and post scores, not make line items) that keeps one score per
learner and refuses a score no newer than the one it holds, and the course's members (NRPS).

The courseware is modelled too: :meth:`OpenEdxPlatform.xblock_url` is the LMS's ``/xblock/`` page framing
the tool's launch; :meth:`OpenEdxPlatform.learning_url` is the Learning MFE's page (on its own origin)
framing that page, as Open edX shows a unit today.
"""

from __future__ import annotations

import html
import re
import secrets
import threading
import time
import uuid
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any
from urllib.parse import parse_qsl, quote

import httpx
import jwt
import uvicorn
from api_testing import free_port
from django.conf import settings as django_settings
from fastapi import FastAPI, Request
from fastapi.responses import HTMLResponse, JSONResponse, Response
from lti_platform import new_private_key

if not django_settings.configured:
    # What the consumer reads of Django: the platform's name (its tool_platform claim) and a cache (its
    # launch data, kept between the login initiation and the launch gate, as in the LMS).
    django_settings.configure(
        PLATFORM_NAME="Open edX (gymgrade tests)",
        CACHES={"default": {"BACKEND": "django.core.cache.backends.locmem.LocMemCache"}},
        OPENEDX_TELEMETRY=[],
        USE_TZ=True,
    )

import lti_consumer
from django.template import Context, Engine
from lti_consumer.data import Lti1p3LaunchData
from lti_consumer.lti_1p3 import exceptions as consumer_errors
from lti_consumer.lti_1p3.consumer import LtiAdvantageConsumer, LtiConsumer1p3
from lti_consumer.utils import get_data_from_cache, get_lti_1p3_context_types_claim

DEPLOYMENT_ID = "1"
"""Open edX's deployment id (``deployment_id="1"``: hard-coded, "we're not using multi-tenancy")."""
SCOPES = "https://purl.imsglobal.org/spec/"
SCORE_SCOPE = SCOPES + "lti-ags/scope/score"
LINEITEM_READ_SCOPES = [SCOPES + "lti-ags/scope/lineitem.readonly", SCOPES + "lti-ags/scope/lineitem"]
NRPS_SCOPE = SCOPES + "lti-nrps/scope/contextmembership.readonly"
CONTEXT_ROLES = {
    # lti_consumer.lti_1p3.constants.LTI_1P3_CONTEXT_ROLE_MAP, as Open edX's NRPS serializer maps them.
    "staff": ["http://purl.imsglobal.org/vocab/lis/v2/membership#Instructor"],
    "instructor": [
        "http://purl.imsglobal.org/vocab/lis/v2/membership#Administrator",
        "http://purl.imsglobal.org/vocab/lis/v2/membership#Instructor",
    ],
    "student": ["http://purl.imsglobal.org/vocab/lis/v2/membership#Learner"],
}
TEMPLATES = Engine(dirs=[str(Path(lti_consumer.__file__).parent / "templates")])


@dataclass
class Passport:
    """An ``Lti1p3Passport``: the client id the tool is registered under and the LMS's key for it."""

    client_id: str = field(default_factory=lambda: str(uuid.uuid4()))
    passport_id: str = field(default_factory=lambda: str(uuid.uuid4()))
    private_key: str = field(default_factory=new_private_key)
    kid: str = field(default_factory=lambda: str(uuid.uuid4()))


@dataclass
class User:
    """An LMS user: the external id the tool knows them by (``sub``), and their role in each course."""

    lms_id: int
    username: str
    full_name: str
    """Empty: the course shares no PII with LTI tools (Open edX's default), so no name is sent."""
    external_id: str = field(default_factory=lambda: uuid.uuid4().hex)
    roles: dict[str, str] = field(default_factory=dict)
    """By course key: ``student``, ``staff`` or ``instructor`` (Open edX's course roles)."""


@dataclass
class Block:
    """An LTI component in a course, its ``LtiConfiguration`` (``config_id``) and what the LMS keeps of it:
    its line item (with one score per learner, the newest) and the deep linking content items."""

    config_id: str
    usage_key: str
    course_key: str
    course_title: str
    passport: Passport
    weight: float
    scores: dict[str, dict[str, Any]] = field(default_factory=dict)
    """By external user id: the score the LMS keeps (``LtiAgsScore``)."""
    accepted: list[dict[str, Any]] = field(default_factory=list)
    """Every score the LMS accepted, in order."""
    refused: list[tuple[str, str]] = field(default_factory=list)
    """(userId, reason) of every score the LMS refused."""
    content_items: list[dict[str, Any]] = field(default_factory=list)
    """What the last deep linking response saved (``LtiDlContentItem``)."""


class OpenEdxPlatform:
    """The LMS: one issuer (``LTI_API_BASE``), passports, courses with LTI blocks, users, and its server."""

    def __init__(self) -> None:
        self.port = free_port()
        self.issuer = f"http://127.0.0.1:{self.port}"
        self.tool_base_url = ""
        self.users: dict[str, User] = {}
        self.blocks: dict[str, Block] = {}
        self.pages: dict[str, tuple[User, Block]] = {}
        self.denied: list[tuple[str, str]] = []
        """(path, reason) of every service call the LMS refused (no token, a bad one, a missing scope)."""
        self.served: list[str] = []
        """Paths of every service call the LMS answered with data."""
        self.lock = threading.Lock()
        self.app = self._make_app()

    # -- configuration ------------------------------------------------------------------------------------
    def use_tool(self, base_url: str) -> None:
        """The tool's URLs, as an author enters them in the block's settings (LTI 1.3 tool)."""
        self.tool_base_url = base_url

    def add_block(self, passport: Passport, course_key: str, course_title: str, weight: float = 3.0) -> Block:
        """An LTI block in ``course_key`` (a ``course-v1:`` key) using ``passport``."""
        name = uuid.uuid4().hex[:12]
        usage_key = "block-v1:" + course_key.removeprefix("course-v1:") + f"+type@lti_consumer+block@{name}"
        block = Block(str(uuid.uuid4()), usage_key, course_key, course_title, passport, weight)
        self.blocks[block.config_id] = block
        return block

    def add_user(self, username: str, full_name: str, roles: dict[str, str]) -> User:
        """A user with a role in each course of ``roles`` (by course key)."""
        user = User(len(self.users) + 1, username, full_name, roles=dict(roles))
        self.users[user.external_id] = user
        return user

    def registration(self, passport: Passport, frame_ancestors: list[str] | None = None) -> dict[str, Any]:
        """The body of the tool's POST /lti/platforms for a passport (what the LMS's admin copies from the
        block's settings: client id, deployment id, keyset, token and login URLs)."""
        body: dict[str, Any] = {
            "issuer": self.issuer,
            "client_id": passport.client_id,
            "deployment_ids": [DEPLOYMENT_ID],
            "jwks_url": f"{self.issuer}/api/lti_consumer/v1/public_keysets/{passport.passport_id}",
            "auth_url": f"{self.issuer}/api/lti_consumer/v1/launch/",
            "token_url": f"{self.issuer}/api/lti_consumer/v1/token/{passport.passport_id}",
        }
        if frame_ancestors is not None:
            body["frame_ancestors"] = frame_ancestors
        return body

    def line_item_url(self, block: Block) -> str:
        return f"{self.issuer}/api/lti_consumer/v1/lti/{block.config_id}/lti-ags/1"

    def consumer(self, block: Block) -> LtiAdvantageConsumer:
        """The block's consumer, made as ``LtiConfiguration.get_lti_consumer`` makes it: AGS (declarative:
        the LMS's line item), deep linking and NRPS enabled."""
        base = f"{self.issuer}/api/lti_consumer/v1/lti/{block.config_id}"
        consumer = LtiAdvantageConsumer(
            iss=self.issuer,
            lti_oidc_url=self.tool_base_url + "/lti/login",
            lti_launch_url=self.tool_base_url + "/lti/launch",
            client_id=block.passport.client_id,
            deployment_id=DEPLOYMENT_ID,
            rsa_key=block.passport.private_key,
            rsa_key_id=block.passport.kid,
            redirect_uris=[self.tool_base_url + "/lti/launch"],
            tool_keyset_url=self.tool_base_url + "/lti/jwks",
        )
        consumer.enable_ags(lineitems_url=base + "/lti-ags", lineitem_url=self.line_item_url(block))
        consumer.enable_deep_linking(self.tool_base_url + "/lti/launch", base + "/lti-dl/response")
        consumer.enable_nrps(base + "/memberships")
        return consumer

    # -- the browser --------------------------------------------------------------------------------------
    def login_url(self, user: User, block: Block, *, deep_linking: bool = False) -> str:
        """The OIDC login initiation URL the block's iframe opens (``get_lti_1p3_content_url``): made by the
        consumer from the block's launch data, with a content item when deep linking saved exactly one."""
        launch_data = Lti1p3LaunchData(
            user_id=user.lms_id,
            user_role=user.roles[block.course_key],
            config_id=block.config_id,
            resource_link_id=block.usage_key,
            external_user_id=user.external_id,
            name=user.full_name or None,
            launch_presentation_document_target="iframe",
            context_id=block.course_key,
            context_type=["course_offering"],
            context_title=block.course_title,
            context_label=block.course_key,
            message_type="LtiDeepLinkingRequest" if deep_linking else "LtiResourceLinkRequest",
            # A content item's id (its row's, from 1): the launch presents the one item deep linking saved.
            deep_linking_content_item_id=1 if not deep_linking and len(block.content_items) == 1 else None,
        )
        url: str = self.consumer(block).prepare_preflight_url(launch_data)
        return url

    def xblock_url(self, user: User, block: Block) -> str:
        """The LMS's ``/xblock/<usage key>`` page of ``user`` (the hint stands for the LMS's session)."""
        hint = secrets.token_urlsafe(8)
        self.pages[hint] = (user, block)
        return f"{self.issuer}/xblock/{quote(block.usage_key)}?view={hint}"

    def learning_url(self, user: User, block: Block, mfe_origin: str) -> str:
        """The Learning MFE's unit page (``mfe_origin``: this server under another site's name), which
        frames the LMS's ``/xblock/`` page."""
        hint = self.xblock_url(user, block).rsplit("=", 1)[1]
        return f"{mfe_origin}/learning/course/{quote(block.course_key)}/{hint}"

    def launch_form(self, client: httpx.Client, user: User, block: Block, **kwargs: Any) -> dict[str, str]:
        """Follow the login to the launch gate's auto-posting form: {action, id_token, state}."""
        response = client.get(self.login_url(user, block, **kwargs))
        if response.status_code not in (302, 303):
            raise AssertionError(f"the tool's login answered {response.status_code}: {response.text}")
        gate = client.get(response.headers["location"])
        if gate.status_code != 200:
            raise AssertionError(f"Open edX's launch gate answered {gate.status_code}: {gate.text}")
        return form_of(gate.text)

    def launch(self, client: httpx.Client, user: User, block: Block, **kwargs: Any) -> httpx.Response:
        """A whole launch, as the browser makes it; the tool's answer to the id_token's form post."""
        form = self.launch_form(client, user, block, **kwargs)
        action = form.pop("action")
        return client.post(action, data=form)

    # -- the LMS's endpoints ------------------------------------------------------------------------------
    def _authorise(self, params: dict[str, str]) -> str:
        """``launch_gate_endpoint``: the launch form, or raises ``LookupError`` (Open edX's 400 page)."""
        launch_data = get_data_from_cache(params.get("lti_message_hint", ""))
        if not params.get("login_hint") or launch_data is None:
            raise LookupError("Unable to find record of an OIDC launch for the provided lti_message_hint")
        block = self.blocks[str(launch_data.config_id)]
        consumer = self.consumer(block)
        consumer.set_user_data(
            user_id=launch_data.external_user_id,
            role=launch_data.user_role,
            full_name=launch_data.name,
        )
        consumer.set_resource_link_claim(launch_data.resource_link_id)
        consumer.set_launch_presentation_claim(
            document_target=launch_data.launch_presentation_document_target,
            return_url=launch_data.launch_presentation_return_url,
        )
        consumer.set_context_claim(
            launch_data.context_id,
            get_lti_1p3_context_types_claim(launch_data.context_type),
            launch_data.context_title,
            launch_data.context_label,
        )
        if launch_data.message_type == "LtiDeepLinkingRequest":
            if launch_data.user_role not in ("instructor", "staff"):
                raise LookupError("Deep Linking can only be performed by instructors and staff.")
        elif launch_data.deep_linking_content_item_id:
            item = block.content_items[launch_data.deep_linking_content_item_id - 1]
            consumer.set_dl_content_launch_parameters(url=item.get("url"), custom=item.get("custom"))
        try:
            launch_request = consumer.generate_launch_request(preflight_response=params)
        except consumer_errors.Lti1p3Exception as error:
            raise LookupError(f"Error preparing LTI 1.3 launch: {error!r}") from None
        page: str = TEMPLATES.get_template("html/lti_1p3_launch.html").render(
            Context({"launch_url": params.get("redirect_uri"), "launch_request": launch_request})
        )
        return page

    def _authenticated(self, request: Request, block: Block, scopes: list[str]) -> None:
        """``Lti1p3ApiAuthentication`` then the view's permission class: a valid token of the block's
        consumer holding one of ``scopes`` (raises PermissionError)."""
        auth = request.headers.get("authorization", "").split()
        if len(auth) != 2 or auth[0].lower() != "bearer":
            raise PermissionError("Missing LTI 1.3 authentication token.")
        consumer = self.consumer(block)
        try:
            consumer.check_token(auth[1])
        except Exception:
            raise PermissionError("Invalid token signature.") from None
        if not consumer.check_token(auth[1], scopes):
            raise PermissionError(f"the token grants none of {scopes}")

    def _make_app(self) -> FastAPI:
        app = FastAPI()
        api = "/api/lti_consumer/v1"

        @app.exception_handler(PermissionError)
        async def _forbidden(request: Request, error: Exception) -> Response:
            with self.lock:
                self.denied.append((request.url.path, str(error)))
            return JSONResponse({"detail": str(error)}, status_code=403)

        def passport_of(passport_id: str) -> Passport:
            for block in self.blocks.values():
                if block.passport.passport_id == passport_id:
                    return block.passport
            raise KeyError(passport_id)

        @app.get(api + "/public_keysets/{passport_id}")
        def public_keyset(passport_id: str) -> Response:
            passport = passport_of(passport_id)
            consumer = LtiConsumer1p3(
                self.issuer, None, None, passport.client_id, None, passport.private_key, passport.kid, None
            )
            return JSONResponse(consumer.get_public_keyset())

        @app.api_route(api + "/launch/", methods=["GET", "POST"])
        async def launch_gate(request: Request) -> Response:
            if request.method == "GET":
                params = dict(request.query_params)
            else:
                params = {key: str(value) for key, value in (await request.form()).items()}
            try:
                return HTMLResponse(self._authorise(params))
            except LookupError as error:
                return HTMLResponse(f"<p>{html.escape(str(error))}</p>", status_code=400)

        @app.post(api + "/token/{passport_id}")
        async def token(passport_id: str, request: Request) -> Response:
            passport = passport_of(passport_id)
            consumer = LtiConsumer1p3(
                iss=self.issuer,
                lti_oidc_url=None,
                lti_launch_url=None,
                client_id=passport.client_id,
                deployment_id=None,
                rsa_key=passport.private_key,
                rsa_key_id=passport.kid,
                redirect_uris=None,
                tool_keyset_url=self.tool_base_url + "/lti/jwks",
            )
            form = dict(parse_qsl((await request.body()).decode("utf-8"), keep_blank_values=True))
            try:
                return JSONResponse(consumer.access_token(form))
            except consumer_errors.MissingRequiredClaim:
                return JSONResponse({"error": "invalid_request"}, status_code=400)
            except consumer_errors.UnsupportedGrantType:
                return JSONResponse({"error": "unsupported_grant_type"}, status_code=400)
            except (jwt.exceptions.DecodeError, consumer_errors.NoSuitableKeys, KeyError):
                return JSONResponse({"error": "invalid_client"}, status_code=400)
            except Exception:
                return JSONResponse({"error": "unidentified_error"}, status_code=400)

        def line_item(block: Block) -> dict[str, Any]:
            return {
                "id": self.line_item_url(block),
                "scoreMaximum": block.weight,
                "label": f"LTI Consumer at {block.usage_key}",
                "resourceId": block.usage_key,
                "resourceLinkId": block.usage_key,
                "tag": "",
            }

        @app.get(api + "/lti/{config_id}/lti-ags")
        def line_items(config_id: str, request: Request) -> Response:
            block = self.blocks[config_id]
            self._authenticated(request, block, LINEITEM_READ_SCOPES)
            item = line_item(block)
            wanted = {"resource_link_id": "resourceLinkId", "resource_id": "resourceId", "tag": "tag"}
            matches = all(
                item[key] == request.query_params[q] for q, key in wanted.items() if q in request.query_params
            )
            self.served.append(request.url.path)
            return JSONResponse(
                [item] if matches else [], media_type="application/vnd.ims.lis.v2.lineitemcontainer+json"
            )

        @app.get(api + "/lti/{config_id}/lti-ags/1")
        def one_line_item(config_id: str, request: Request) -> Response:
            block = self.blocks[config_id]
            self._authenticated(request, block, LINEITEM_READ_SCOPES)
            self.served.append(request.url.path)
            return JSONResponse(line_item(block), media_type="application/vnd.ims.lis.v2.lineitem+json")

        @app.post(api + "/lti/{config_id}/lti-ags/1/scores")
        async def scores(config_id: str, request: Request) -> Response:
            block = self.blocks[config_id]
            self._authenticated(request, block, [SCORE_SCOPE])
            body = await request.json()
            refusal = _score_refusal(body, block.scores.get(str(body.get("userId"))))
            with self.lock:
                if refusal:
                    block.refused.append((str(body.get("userId")), refusal))
                    return JSONResponse({"detail": refusal}, status_code=400)
                block.scores[str(body["userId"])] = body
                block.accepted.append(body)
            self.served.append(request.url.path)
            return JSONResponse(body, status_code=201, media_type="application/vnd.ims.lis.v1.score+json")

        @app.get(api + "/lti/{config_id}/memberships")
        def memberships(config_id: str, request: Request) -> Response:
            block = self.blocks[config_id]
            self._authenticated(request, block, [NRPS_SCOPE])
            members = [
                {
                    "status": "Active",
                    "user_id": user.external_id,
                    "roles": CONTEXT_ROLES[user.roles[block.course_key]],
                    **({"name": user.full_name} if user.full_name else {}),
                }
                for user in self.users.values()
                if block.course_key in user.roles
            ]
            self.served.append(request.url.path)
            return JSONResponse(
                {"id": str(request.url), "context": {"id": block.course_key}, "members": members},
                media_type="application/vnd.ims.lti-nrps.v2.membershipcontainer+json",
            )

        @app.post(api + "/lti/{config_id}/lti-dl/response")
        async def deep_linking_response(config_id: str, request: Request) -> Response:
            block = self.blocks[config_id]
            form = {key: str(value) for key, value in (await request.form()).items()}
            try:
                items = self.consumer(block).check_and_decode_deep_linking_token(form.get("JWT"))
            except (consumer_errors.Lti1p3Exception, jwt.exceptions.PyJWTError) as error:
                return HTMLResponse(f"<p>You don't have access to save LTI Content Items: {error!r}</p>", 403)
            block.content_items = list(items)
            return HTMLResponse("<p id='saved'>The LTI content was saved.</p>")

        @app.get("/xblock/{usage_key:path}")
        def xblock(usage_key: str, view: str) -> Response:
            # The LMS's page of one unit's block (what the Learning MFE frames): the block's iframe opens the
            # tool's login initiation.
            user, block = self.pages[view]
            return HTMLResponse(
                f"<h1>{html.escape(block.course_title)}</h1>"
                f'<iframe id="lti" class="ltiLaunchFrame" src="{html.escape(self.login_url(user, block))}" '
                'width="1000" height="800" allow="fullscreen"></iframe>'
            )

        @app.get("/learning/course/{course_key}/{view}")
        def learning_mfe(course_key: str, view: str) -> Response:
            _, block = self.pages[view]
            unit = f"{self.issuer}/xblock/{quote(block.usage_key)}?view={view}"
            return HTMLResponse(
                f'<h1>Learning</h1><iframe id="unit" src="{html.escape(unit)}" '
                'width="1100" height="900"></iframe>'
            )

        return app

    # -- running ------------------------------------------------------------------------------------------
    @contextmanager
    def running(self) -> Iterator[OpenEdxPlatform]:
        """Serve the LMS with uvicorn on loopback while the block runs."""
        server = uvicorn.Server(
            uvicorn.Config(self.app, host="127.0.0.1", port=self.port, log_level="warning")
        )
        thread = threading.Thread(target=server.run, daemon=True)
        thread.start()
        deadline = time.monotonic() + 20
        while not server.started:
            if time.monotonic() > deadline or not thread.is_alive():
                raise RuntimeError("the Open edX platform did not start")
            time.sleep(0.05)
        try:
            yield self
        finally:
            server.should_exit = True
            thread.join(timeout=10)


def _score_refusal(body: Any, held: dict[str, Any] | None) -> str | None:
    """Why Open edX's ``LtiAgsScoreSerializer`` refuses a score (None: it keeps it)."""
    if not isinstance(body, dict):
        return "a score is a JSON object"
    for name in ("timestamp", "activityProgress", "gradingProgress", "userId"):
        if not isinstance(body.get(name), str) or not body[name]:
            return f"{name}: This field is required."
    try:
        timestamp = _utc(body["timestamp"])
    except ValueError:
        return "timestamp: Datetime has wrong format."
    if body.get("scoreGiven") is not None:
        maximum = body.get("scoreMaximum")
        if maximum is None:
            return "scoreMaximum is a required field when providing a scoreGiven value."
        if maximum <= 0:
            return "scoreMaximum must be a positive number when scoreGiven is provided."
    if held is not None:
        before = _utc(held["timestamp"])
        if before > timestamp:
            return "Score timestamp can only be updated to a later point in time"
        if before == timestamp:
            return "Score already exists for the provided timestamp"
    return None


def _utc(timestamp: str) -> datetime:
    """An ISO 8601 time, in UTC when it names no zone (DRF's ``default_timezone=timezone.utc``)."""
    parsed = datetime.fromisoformat(timestamp)
    return parsed if parsed.tzinfo is not None else parsed.replace(tzinfo=UTC)


def form_of(page: str) -> dict[str, str]:
    """The action and fields of the launch gate's form (the package's template ``lti_1p3_launch.html``)."""
    action = re.search(r'action="([^"]*)"', page)
    if action is None:
        raise AssertionError(f"no launch form in the page: {page[:500]}")
    fields = dict(re.findall(r'<input name="(\w+)" value="([^"]*)"', page))
    return {"action": html.unescape(action.group(1)), **{k: html.unescape(v) for k, v in fields.items()}}

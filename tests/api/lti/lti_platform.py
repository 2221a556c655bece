"""A real LTI 1.3 platform on loopback, built on the `lti1p3platform` package (not ours), for the tests.

The package signs the launches (OIDC login initiation, the id_token of resource link and deep linking
launches), issues access tokens for the client credentials grant (checking the tool's JWT assertion
against the tool's JWKS URL) and verifies deep linking responses. It has no HTTP endpoints of its own,
nor the Assignment and Grade, Names and Role Provisioning or Dynamic Registration services; this module
serves them (FastAPI under a real uvicorn), guarding each with the package's own token validation.

A test plays the browser: :meth:`LtiPlatform.launch` follows the login initiation, the tool's redirect
to the platform's authorisation endpoint and the form post of the id_token to the tool.
"""

from __future__ import annotations

import copy
import html
import secrets
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any
from urllib.parse import parse_qsl, urlencode, urlsplit

import httpx
import uvicorn
from api_testing import free_port
from cryptography.hazmat.primitives import serialization
from cryptography.hazmat.primitives.asymmetric import rsa
from fastapi import FastAPI, Request
from fastapi.responses import HTMLResponse, JSONResponse, Response
from lti1p3platform.exceptions import LtiException
from lti1p3platform.ltiplatform import LTI1P3PlatformConfAbstract
from lti1p3platform.message_launch import LTIAdvantageMessageLaunchAbstract
from lti1p3platform.oidc_login import OIDCLoginAbstract
from lti1p3platform.registration import Registration
from lti1p3platform.request import Request as PlatformRequest

LEARNER = "http://purl.imsglobal.org/vocab/lis/v2/membership#Learner"
INSTRUCTOR = "http://purl.imsglobal.org/vocab/lis/v2/membership#Instructor"
TEACHING_ASSISTANT = "http://purl.imsglobal.org/vocab/lis/v2/membership/Instructor#TeachingAssistant"
CONTEXT_ID = "course-rl-2026"
REGISTRATION_TOKEN = "platform-registration-" + "k3y9"
PLATFORM_STORAGE = """
var stored = {};
window.addEventListener("message", function (event) {
  var message = event.data;
  if (!message || typeof message.subject !== "string") { return; }
  var key = event.origin + " " + message.key;
  var answer = { message_id: message.message_id, key: message.key };
  if (message.subject === "lti.put_data") {
    stored[key] = message.value;
    answer.subject = "lti.put_data.response";
    answer.value = message.value;
  } else if (message.subject === "lti.get_data") {
    answer.subject = "lti.get_data.response";
    answer.value = stored[key];
  } else { return; }
  event.source.postMessage(answer, event.origin);
});
"""
"""The platform's storage for LTI client-side OIDC (lti.put_data, lti.get_data), kept per tool origin, on
the course page that frames the tool (its ``lti_storage_target`` is ``_parent``)."""


def new_private_key() -> str:
    """A fresh 2048-bit RSA private key in PEM."""
    key = rsa.generate_private_key(public_exponent=65537, key_size=2048)
    return key.private_bytes(
        serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8, serialization.NoEncryption()
    ).decode("ascii")


def public_pem(private_pem: str) -> str:
    """The public half of a private key, in PEM."""
    key = serialization.load_pem_private_key(private_pem.encode("ascii"), password=None)
    return (
        key.public_key()
        .public_bytes(  # type: ignore[union-attr]
            serialization.Encoding.PEM, serialization.PublicFormat.SubjectPublicKeyInfo
        )
        .decode("ascii")
    )


class KeyedRegistration(Registration):
    """The package's registration, with a key id in the id_token's header and the JWKS (as LMSs send)."""

    def __init__(self, kid: str) -> None:
        self._kid = kid

    def get_kid(self) -> str:
        return self._kid

    def get_jwks(self) -> list[dict[str, Any]]:
        return [{**key, "kid": self._kid} for key in super().get_jwks()]


@dataclass
class Person:
    """A user of the platform's course."""

    sub: str
    name: str
    roles: list[str]


@dataclass
class LaunchSpec:
    """What the next launch carries (looked up by its lti_message_hint at the authorisation endpoint)."""

    person: Person
    resource_link_id: str
    deep_linking: bool = False
    custom: dict[str, str] = field(default_factory=dict)
    claims: dict[str, Any] = field(default_factory=dict)
    """Claims overriding the signed message (a hostile platform: wrong aud, deployment...)."""
    expiration: int = 300
    signing_key: str | None = None
    """Another private key to sign with (under the platform's key id): a forged launch."""
    lineitem: str | None = None
    """The line item the platform made for the link (as Canvas and Moodle do for an assignment)."""
    browser: bool = False
    """The authorisation endpoint answers as an LMS does for a browser: a form posted by a script."""
    kid: str | None = None
    """Another key id in the id_token's header (a key the platform's JWKS does not hold)."""
    storage_target: str | None = None
    """The login offers the platform's storage (LTI client-side OIDC): ``lti_storage_target``."""


class _Config(LTI1P3PlatformConfAbstract):
    def init_platform_config(self, **kwargs: Any) -> None:
        self._registration = kwargs["registration"]

    def get_registration_by_params(self, **kwargs: Any) -> Registration:
        return self._registration


class _Login(OIDCLoginAbstract):
    def set_lti_message_hint(self, **kwargs: Any) -> None:
        self._lti_message_hint = kwargs["hint"]

    def get_redirect(self, url: str) -> str:
        return url


class _Preflight(PlatformRequest):
    def build_metadata(self, request: Any) -> Any:
        return {"method": "GET", "form_data": {}, "get_data": request, "headers": {}, "path": "/auth"}


class _Launch(LTIAdvantageMessageLaunchAbstract):
    def render_launch_form(self, launch_data: dict[str, Any], **kwargs: Any) -> dict[str, Any]:
        return launch_data


class LtiPlatform:
    """The platform: its keys, one registration of the tool, a course with members, line items, scores."""

    def __init__(self) -> None:
        self.port = free_port()
        self.issuer = f"http://127.0.0.1:{self.port}"
        self.kid = "platform-key-1"
        self.private_key = new_private_key()
        self.client_id = ""
        self.deployment_id = "deployment-1"
        self.tool_login_url = ""
        self.tool_launch_url = ""
        self.tool_jwks_url = ""
        self.people: dict[str, Person] = {}
        self.launches: dict[str, LaunchSpec] = {}
        self.line_items: dict[str, dict[str, Any]] = {}
        self.scores: dict[str, list[dict[str, Any]]] = {}
        self.score_failures: dict[str, int] = {}
        """By user id: score POSTs still to answer with 500 (an LMS in trouble)."""
        self.refused_scores = 0
        self.registrations: list[dict[str, Any]] = []
        self.deep_link_items: list[dict[str, Any]] = []
        self.course_pages: dict[str, str] = {}
        self.configuration: dict[str, Any] = {}
        """Fields overriding the OpenID configuration served (a hostile platform's issuer, endpoints)."""
        self.jwks_padding = 0
        """Bytes of padding added to the JWKS document (a huge one)."""
        self.memberships_next: str | None = None
        """A ``Link: <...>; rel="next"`` the roster's pages carry."""
        self.requests: list[tuple[str, str]] = []
        """Every request the platform received: (Host header, path)."""
        self.lock = threading.Lock()
        self.app = self._make_app()
        self._server: uvicorn.Server | None = None

    # -- the tool's registration --------------------------------------------------------------------------
    def register_tool(self, base_url: str, client_id: str = "gymgrade-client") -> None:
        """Register the tool by hand (as an administrator enters its URLs)."""
        self.client_id = client_id
        self.tool_login_url = base_url + "/lti/login"
        self.tool_launch_url = base_url + "/lti/launch"
        self.tool_jwks_url = base_url + "/lti/jwks"

    def registration(self, signing_key: str | None = None, kid: str | None = None) -> KeyedRegistration:
        """The package's registration object of the tool."""
        registration = KeyedRegistration(kid or self.kid)
        (
            registration.set_iss(self.issuer)
            .set_client_id(self.client_id)
            .set_deployment_id(self.deployment_id)
            .set_oidc_login_url(self.tool_login_url)
            .set_launch_url(self.tool_launch_url)
            .set_deeplink_launch_url(self.tool_launch_url)
            .set_platform_private_key(signing_key or self.private_key)
            .set_platform_public_key(public_pem(self.private_key))
            .set_tool_key_set_url(self.tool_jwks_url)
        )
        return registration

    def config(self, signing_key: str | None = None, kid: str | None = None) -> _Config:
        return _Config(registration=self.registration(signing_key, kid))

    @property
    def manual_registration(self) -> dict[str, Any]:
        """The body of the tool's POST /lti/platforms for this platform."""
        return {
            "issuer": self.issuer,
            "client_id": self.client_id,
            "deployment_ids": [self.deployment_id],
            "jwks_url": self.issuer + "/jwks",
            "auth_url": self.issuer + "/auth",
            "token_url": self.issuer + "/token",
        }

    # -- the browser --------------------------------------------------------------------------------------
    def login_url(self, spec: LaunchSpec) -> str:
        """The OIDC login initiation URL the platform sends the browser to (made by the package)."""
        hint = secrets.token_urlsafe(8)
        self.launches[hint] = spec
        login = _Login(None, self.config())
        login.set_lti_message_hint(hint=hint)
        if spec.deep_linking:
            login.set_deeplinking_launch_url()
        url: str = login.initiate_login(spec.person.sub)
        if spec.storage_target:
            url += "&" + urlencode({"lti_storage_target": spec.storage_target})
        return url

    def course_page(self, spec: LaunchSpec, *, mfe_origin: str | None = None) -> str:
        """The URL of the course's page framing the tool, which a browser opens (the launch starts there);
        with ``mfe_origin`` (another name of this server), a page there framing the course's page."""
        hint = secrets.token_urlsafe(8)
        self.course_pages[hint] = self.login_url(spec)
        if mfe_origin is not None:
            return f"{mfe_origin}/mfe/{hint}"
        return f"{self.issuer}/course/{hint}"

    def id_token_post(self, client: httpx.Client, spec: LaunchSpec) -> dict[str, str]:
        """Follow the login to the form the platform posts to the tool: {launch_url, id_token, state}."""
        response = client.get(self.login_url(spec))
        if response.status_code not in (302, 303):
            raise AssertionError(f"the tool's login answered {response.status_code}: {response.text}")
        answer = client.get(response.headers["location"])
        answer.raise_for_status()
        form: dict[str, str] = answer.json()
        return form

    def launch(self, client: httpx.Client, spec: LaunchSpec) -> httpx.Response:
        """A whole launch; the tool's answer to the id_token's form post."""
        form = self.id_token_post(client, spec)
        return client.post(form["launch_url"], data={"id_token": form["id_token"], "state": form["state"]})

    # -- the platform's endpoints -------------------------------------------------------------------------
    def _authorise(self, query: dict[str, str]) -> dict[str, Any]:
        spec = self.launches[query["lti_message_hint"]]
        if query.get("login_hint") != spec.person.sub:
            raise LtiException("login_hint does not name the user of this launch")
        launch = _Launch(_Preflight(query), self.config(spec.signing_key, spec.kid))
        launch.set_user_data(spec.person.sub, spec.person.roles, full_name=spec.person.name)
        launch.set_launch_context_claim(CONTEXT_ID, context_title="Reinforcement learning")
        launch.set_launch_presentation_claim("iframe", return_url=self.issuer + "/course")
        launch.set_id_token_expiration(spec.expiration)
        if spec.deep_linking:
            launch.set_dl(
                self.issuer + "/deep_link_return", accept_types={"ltiResourceLink"}, extra_data={"d": 1}
            )
        else:
            launch.set_resource_link_claim(spec.resource_link_id, title="Lab: OpenGym")
            launch.set_ags(
                self.issuer + f"/lineitems?context={CONTEXT_ID}",
                lineitem_url=spec.lineitem,
                allow_creating_lineitems=True,
            )
            launch.set_nrps(self.issuer + "/memberships")
            if spec.custom:
                launch.set_custom_parameters_claim(spec.custom)
        if spec.claims:
            launch.set_extra_claims(copy.deepcopy(spec.claims))
        return launch.lti_launch()

    def _check_token(self, request: Request, scope: str) -> None:
        header = request.headers.get("authorization", "")
        if not header.startswith("Bearer "):
            raise PermissionError("no bearer token")
        config = self.config()
        config.get_registration()
        if not config.validate_token(header.removeprefix("Bearer "), allowed_scopes=[scope]):
            raise PermissionError(f"the token does not grant {scope}")

    def _make_app(self) -> FastAPI:
        app = FastAPI()
        ags = "https://purl.imsglobal.org/spec/lti-ags/scope/"

        @app.middleware("http")
        async def _count(request: Request, call_next: Any) -> Response:
            with self.lock:
                self.requests.append((request.headers.get("host", ""), request.url.path))
            response: Response = await call_next(request)
            return response

        @app.exception_handler(PermissionError)
        async def _forbidden(_request: Request, error: Exception) -> Response:
            return JSONResponse({"error": str(error)}, status_code=401)

        @app.exception_handler(LtiException)
        async def _refused(_request: Request, error: Exception) -> Response:
            return JSONResponse({"error": str(error)}, status_code=400)

        @app.get("/.well-known/openid-configuration")
        def openid_configuration() -> dict[str, Any]:
            return {
                "issuer": self.issuer,
                "authorization_endpoint": self.issuer + "/auth",
                "token_endpoint": self.issuer + "/token",
                "jwks_uri": self.issuer + "/jwks",
                "registration_endpoint": self.issuer + "/register",
                "token_endpoint_auth_methods_supported": ["private_key_jwt"],
                "scopes_supported": ["openid"],
                "response_types_supported": ["id_token"],
                "id_token_signing_alg_values_supported": ["RS256"],
                "https://purl.imsglobal.org/spec/lti-platform-configuration": {
                    "product_family_code": "lti1p3platform-tests",
                    "version": "0.1.8",
                },
                **self.configuration,
            }

        @app.post("/register")
        async def register(request: Request) -> Response:
            if request.headers.get("authorization") != f"Bearer {REGISTRATION_TOKEN}":
                return JSONResponse({"error": "registration token missing or wrong"}, status_code=401)
            body = await request.json()
            self.registrations.append(body)
            self.client_id = "dynamic-" + secrets.token_hex(4)
            self.tool_login_url = body["initiate_login_uri"]
            self.tool_launch_url = body["redirect_uris"][0]
            self.tool_jwks_url = body["jwks_uri"]
            return JSONResponse(
                {
                    **body,
                    "client_id": self.client_id,
                    "https://purl.imsglobal.org/spec/lti-tool-configuration": {
                        **body["https://purl.imsglobal.org/spec/lti-tool-configuration"],
                        "deployment_id": self.deployment_id,
                    },
                }
            )

        @app.get("/jwks")
        def jwks() -> dict[str, Any]:
            config = self.config()
            config.get_registration()
            document = dict(config.get_jwks())
            if self.jwks_padding:
                document["padding"] = "x" * self.jwks_padding
            return document

        @app.get("/auth", response_model=None)
        def auth(request: Request) -> dict[str, Any] | Response:
            query = dict(request.query_params)
            form = self._authorise(query)
            if not self.launches[query["lti_message_hint"]].browser:
                return form
            fields = "".join(
                f'<input type="hidden" name="{name}" value="{html.escape(form[name])}">'
                for name in ("id_token", "state")
            )
            return HTMLResponse(
                f'<form id="launch" method="post" action="{html.escape(form["launch_url"])}">{fields}</form>'
                '<script>document.getElementById("launch").submit();</script>'
            )

        @app.get("/course/{hint}")
        def course(hint: str) -> Response:
            login = self.course_pages[hint]
            return HTMLResponse(
                "<h1>Reinforcement learning</h1>"
                f'<iframe id="tool" src="{html.escape(login)}" width="1000" height="800"></iframe>'
                f"<script>{PLATFORM_STORAGE}</script>"
            )

        @app.get("/mfe/{hint}")
        def learning_mfe(hint: str) -> Response:
            # Open edX's learning MFE: a page of another origin framing the LMS's page that frames the tool.
            return HTMLResponse(
                "<h1>Learning</h1>"
                f'<iframe id="lms" src="{html.escape(self.issuer)}/course/{html.escape(hint)}" width="1100" height="900"></iframe>'  # noqa: E501
            )

        @app.post("/token")
        async def token(request: Request) -> Response:
            form = {key: str(value) for key, value in (await request.form()).items()}
            config = self.config()
            config.get_registration()
            try:
                return JSONResponse(dict(config.get_access_token(form)))
            except Exception as error:
                return JSONResponse({"error": "invalid_client", "detail": repr(error)}, status_code=400)

        @app.get("/lineitems")
        def list_line_items(request: Request) -> list[dict[str, Any]]:
            self._check_token(request, ags + "lineitem")
            wanted = dict(request.query_params)
            return [
                item
                for item in self.line_items.values()
                if wanted.get("resource_link_id") in (None, item.get("resourceLinkId"))
                and wanted.get("resource_id") in (None, item.get("resourceId"))
            ]

        @app.post("/lineitems")
        async def create_line_item(request: Request) -> Response:
            self._check_token(request, ags + "lineitem")
            body = await request.json()
            with self.lock:
                item_id = f"{self.issuer}/lineitems/{len(self.line_items) + 1}"
                self.line_items[item_id] = {**body, "id": item_id}
            return JSONResponse(self.line_items[item_id], status_code=201)

        @app.post("/lineitems/{number}/scores")
        async def post_score(number: int, request: Request) -> Response:
            self._check_token(request, ags + "score")
            body = await request.json()
            with self.lock:
                if self.score_failures.get(body.get("userId"), 0) > 0:
                    self.score_failures[body["userId"]] -= 1
                    self.refused_scores += 1
                    return JSONResponse({"error": "the gradebook is down"}, status_code=500)
            item_id = f"{self.issuer}/lineitems/{number}"
            if item_id not in self.line_items:
                return JSONResponse({"error": "no such line item"}, status_code=404)
            self.scores.setdefault(item_id, []).append(body)
            return Response(status_code=204)

        @app.get("/memberships")
        def memberships(request: Request) -> Response:
            self._check_token(
                request, "https://purl.imsglobal.org/spec/lti-nrps/scope/contextmembership.readonly"
            )
            headers = {"Link": f'<{self.memberships_next}>; rel="next"'} if self.memberships_next else {}
            return JSONResponse(
                headers=headers,
                content={
                    "id": self.issuer + "/memberships",
                    "context": {"id": CONTEXT_ID},
                    "members": [
                        {
                            "status": "Active",
                            "user_id": person.sub,
                            "name": person.name,
                            "roles": person.roles,
                        }
                        for person in self.people.values()
                    ],
                },
            )

        @app.post("/deep_link_return")
        async def deep_link_return(request: Request) -> dict[str, Any]:
            form = {key: str(value) for key, value in (await request.form()).items()}
            config = self.config()
            config.get_registration()
            items = config.validate_deeplinking_resp(form)
            self.deep_link_items.extend(items)
            return {"items": items}

        return app

    # -- running ------------------------------------------------------------------------------------------
    @contextmanager
    def running(self) -> Iterator[LtiPlatform]:
        """Serve the platform with uvicorn on loopback while the block runs."""
        server = uvicorn.Server(
            uvicorn.Config(self.app, host="127.0.0.1", port=self.port, log_level="warning")
        )
        thread = threading.Thread(target=server.run, daemon=True)
        thread.start()
        deadline = time.monotonic() + 20
        while not server.started:
            if time.monotonic() > deadline or not thread.is_alive():
                raise RuntimeError("the LTI platform did not start")
            time.sleep(0.05)
        try:
            yield self
        finally:
            server.should_exit = True
            thread.join(timeout=10)

    def add_line_item(self, resource_link_id: str, score_maximum: float) -> str:
        """A line item the platform makes itself for a link; its URL."""
        with self.lock:
            item_id = f"{self.issuer}/lineitems/{len(self.line_items) + 1}"
            self.line_items[item_id] = {
                "id": item_id,
                "scoreMaximum": score_maximum,
                "label": "Lab",
                "resourceLinkId": resource_link_id,
            }
        return item_id

    def add_person(self, sub: str, name: str, *roles: str) -> Person:
        """A member of the course."""
        person = Person(sub, name, list(roles))
        self.people[sub] = person
        return person


def query_of(url: str) -> dict[str, str]:
    """A URL's query parameters."""
    return dict(parse_qsl(urlsplit(url).query))

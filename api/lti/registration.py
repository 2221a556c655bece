"""LTI Dynamic Registration (1.0): the platform opens ``/lti/register`` with its ``openid_configuration``
and a ``registration_token``; the tool reads the configuration, registers its URLs and stores the platform.

The instructor hands the LMS administrator a registration URL (``POST /lti/registrations``) carrying a
ticket the tool signed: without a valid ticket nobody can make the tool register with a platform.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any
from urllib.parse import urlsplit

import httpx
from joserfc import jwt
from joserfc.errors import JoseError
from sqlalchemy.orm import Session

from api.errors import LtiRequestInvalid, NotAuthenticated, PlatformUnreachable
from api.lti.claims import DEEP_LINKING_REQUEST, TOOL_SCOPES
from api.lti.keys import ALGORITHM, published_keys, sign
from api.lti.platforms import HTTP_TIMEOUT_SECONDS, PlatformRegistration, fetch_json, register_platform
from api.models import LtiPlatform

TICKET_PURPOSE = "lti-registration"
TICKET_SECONDS = 7 * 24 * 3600
TOOL_CONFIGURATION = "https://purl.imsglobal.org/spec/lti-tool-configuration"
TOOL_NAME = "gymgrade"


@dataclass(frozen=True)
class ToolUrls:
    """The tool's own URLs, made from GYMGRADE_PUBLIC_URL or the request's address."""

    base: str

    @property
    def login(self) -> str:
        """OIDC login initiation."""
        return self.base + "/lti/login"

    @property
    def launch(self) -> str:
        """Launch (resource link and deep linking): the redirect URI."""
        return self.base + "/lti/launch"

    @property
    def jwks(self) -> str:
        """The tool's public keys."""
        return self.base + "/lti/jwks"

    @property
    def origin(self) -> str:
        """scheme://host[:port]."""
        parts = urlsplit(self.base)
        return f"{parts.scheme}://{parts.netloc}"


def registration_ticket(session: Session) -> str:
    """A ticket allowing dynamic registrations for ``TICKET_SECONDS`` (each registers one platform)."""
    now = int(time.time())
    return sign(session, {"purpose": TICKET_PURPOSE, "iat": now, "exp": now + TICKET_SECONDS})


def check_ticket(session: Session, ticket: str, grace_seconds: float) -> None:
    """Raise NotAuthenticated unless ``ticket`` is a registration ticket this tool issued and unexpired."""
    try:
        token = jwt.decode(ticket, published_keys(session, grace_seconds), algorithms=[ALGORITHM])
        jwt.JWTClaimsRegistry(exp={"essential": True}).validate(token.claims)
    except (JoseError, ValueError, UnicodeError):
        raise NotAuthenticated(
            "this registration URL carries no valid ticket (missing, altered or expired); "
            "the instructor makes a new one with POST /lti/registrations"
        ) from None
    if token.claims.get("purpose") != TICKET_PURPOSE:
        raise NotAuthenticated("the ticket was issued for something else than a registration")


def tool_configuration(urls: ToolUrls) -> dict[str, Any]:
    """The client registration the tool sends (OpenID Connect Dynamic Client Registration + LTI)."""
    return {
        "application_type": "web",
        "response_types": ["id_token"],
        "grant_types": ["implicit", "client_credentials"],
        "initiate_login_uri": urls.login,
        "redirect_uris": [urls.launch],
        "client_name": TOOL_NAME,
        "jwks_uri": urls.jwks,
        "token_endpoint_auth_method": "private_key_jwt",
        "scope": " ".join(TOOL_SCOPES),
        TOOL_CONFIGURATION: {
            "domain": urlsplit(urls.base).netloc,
            "target_link_uri": urls.launch,
            "claims": ["iss", "sub", "name", "given_name", "family_name", "email"],
            "messages": [
                {"type": DEEP_LINKING_REQUEST, "target_link_uri": urls.launch, "label": "gymgrade lab"}
            ],
        },
    }


def register_dynamically(
    session: Session, urls: ToolUrls, openid_configuration: str, registration_token: str | None
) -> LtiPlatform:
    """Read the platform's configuration, register the tool there, and store the platform.

    Raises:
        LtiRequestInvalid: The configuration's issuer does not own its URL, or a field is missing.
        PlatformUnreachable: The platform could not be read or refused the registration.
    """
    if urlsplit(openid_configuration).scheme not in ("http", "https"):
        raise LtiRequestInvalid(
            f"openid_configuration must be an http(s) URL, found {openid_configuration!r}"
        )
    config = fetch_json(openid_configuration)
    if not isinstance(config, dict):
        raise LtiRequestInvalid("the platform's OpenID configuration is not a JSON object")
    issuer = str(config.get("issuer") or "")
    if not issuer or not openid_configuration.startswith(issuer.rstrip("/")):
        raise LtiRequestInvalid(
            f"the platform's OpenID configuration at {openid_configuration} names issuer {issuer!r}, which does not own that URL; "  # noqa: E501
            "the spec requires the configuration URL to start with the issuer"
        )
    missing = [
        field
        for field in ("authorization_endpoint", "token_endpoint", "jwks_uri", "registration_endpoint")
        if not config.get(field)
    ]
    if missing:
        raise LtiRequestInvalid(f"the platform's OpenID configuration lacks {', '.join(missing)}")
    headers = {"Authorization": f"Bearer {registration_token}"} if registration_token else {}
    try:
        response = httpx.post(
            str(config["registration_endpoint"]),
            json=tool_configuration(urls),
            headers=headers,
            timeout=HTTP_TIMEOUT_SECONDS,
        )
    except httpx.HTTPError as error:
        raise PlatformUnreachable(f"the platform's registration endpoint did not answer: {error}") from None
    if response.status_code not in (200, 201):
        raise PlatformUnreachable(
            f"the platform refused the registration: {response.status_code} {response.text[:200]!r}"
        )
    answer = response.json()
    deployment = (answer.get(TOOL_CONFIGURATION) or {}).get("deployment_id")
    return register_platform(
        session,
        PlatformRegistration(
            issuer=issuer,
            client_id=str(answer.get("client_id") or ""),
            deployment_ids=(str(deployment),) if deployment else (),
            jwks_url=str(config["jwks_uri"]),
            auth_url=str(config["authorization_endpoint"]),
            token_url=str(config["token_endpoint"]),
        ),
    )

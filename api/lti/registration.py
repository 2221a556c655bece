"""LTI Dynamic Registration (1.0): the platform opens ``/lti/register`` with its ``openid_configuration``
and a ``registration_token``; the tool reads the configuration, registers its URLs and stores the platform.

The instructor hands the LMS administrator a registration URL (``POST /lti/registrations``) carrying a
ticket the tool signed: without a valid ticket nobody can make the tool register with a platform. A ticket
is short-lived (``GYMGRADE_LTI_REGISTRATION_TICKET_SECONDS``) and used once: the platform's GET only shows a
form, whose POST spends the ticket (its ``jti`` stored in ``lti_spent_tokens``) before anything is asked of
the platform. The configuration's issuer must have the configuration URL's origin (scheme, host and port,
exactly), and its endpoints must be on the issuer's origin or on hosts the operator allows
(``GYMGRADE_LTI_SERVICE_HOSTS``); every request goes through :mod:`api.lti.outbound`.
"""

from __future__ import annotations

import secrets
import time
from dataclasses import dataclass
from typing import Any
from urllib.parse import urlsplit

from joserfc import jwt
from joserfc.errors import JoseError
from sqlalchemy.orm import Session

from api.errors import LtiRequestInvalid, NotAuthenticated, PlatformUnreachable
from api.lti.claims import DEEP_LINKING_REQUEST, TOOL_SCOPES
from api.lti.keys import ALGORITHM, published_keys, sign
from api.lti.outbound import Outbound, on_hosts
from api.lti.platforms import PlatformRegistration, register_platform
from api.lti.spent import TokenSpent, spend
from api.models import LtiPlatform

TICKET_PURPOSE = "lti-registration"
ENDPOINTS = ("authorization_endpoint", "token_endpoint", "jwks_uri", "registration_endpoint")
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


def registration_ticket(session: Session, seconds: float) -> str:
    """A ticket allowing one dynamic registration within ``seconds``."""
    now = int(time.time())
    claims = {
        "purpose": TICKET_PURPOSE,
        "jti": secrets.token_urlsafe(16),
        "iat": now,
        "exp": now + int(seconds),
    }
    return sign(session, claims)


def check_ticket(session: Session, ticket: str, grace_seconds: float, *, use: bool) -> None:
    """Raise NotAuthenticated unless ``ticket`` is an unexpired registration ticket this tool issued and
    never used; ``use``: spend it (committed at once: a second use is refused even if this one fails)."""
    try:
        token = jwt.decode(ticket, published_keys(session, grace_seconds), algorithms=[ALGORITHM])
        jwt.JWTClaimsRegistry(exp={"essential": True}, jti={"essential": True}).validate(token.claims)
    except (JoseError, ValueError, UnicodeError):
        raise NotAuthenticated(
            "this registration URL carries no valid ticket (missing, altered or expired); "
            "the instructor makes a new one with POST /lti/registrations"
        ) from None
    if token.claims.get("purpose") != TICKET_PURPOSE:
        raise NotAuthenticated("the ticket was issued for something else than a registration")
    try:
        spend(session, TICKET_PURPOSE, str(token.claims["jti"]), int(token.claims["exp"]), check_only=not use)
    except TokenSpent:
        raise NotAuthenticated(
            "this registration URL was used already (a ticket registers one platform); "
            "the instructor makes a new one with POST /lti/registrations"
        ) from None


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
    session: Session,
    outbound: Outbound,
    urls: ToolUrls,
    openid_configuration: str,
    registration_token: str | None,
    *,
    allowed_hosts: tuple[str, ...],
) -> LtiPlatform:
    """Read the platform's configuration, register the tool there, and store the platform.

    Raises:
        LtiRequestInvalid: The configuration's issuer does not own its URL, an endpoint is elsewhere, or a
            field is missing.
        PlatformUnreachable: The platform could not be read or refused the registration.
    """
    what = "reading the platform's OpenID configuration"
    outbound.checked_url(openid_configuration, what)
    config = outbound.get_json(openid_configuration, what=what)
    if not isinstance(config, dict):
        raise LtiRequestInvalid("the platform's OpenID configuration is not a JSON object")
    issuer = str(config.get("issuer") or "")
    if not issuer or not on_hosts(openid_configuration, [issuer], allowed_hosts):
        raise LtiRequestInvalid(
            f"the platform's OpenID configuration at {openid_configuration} names issuer {issuer!r}, whose origin (scheme, host and port) is not the configuration's; "  # noqa: E501
            "the configuration must be served by its issuer (or from a host in GYMGRADE_LTI_SERVICE_HOSTS)"
        )
    missing = [field for field in ENDPOINTS if not isinstance(config.get(field), str) or not config[field]]
    if missing:
        raise LtiRequestInvalid(f"the platform's OpenID configuration lacks {', '.join(missing)}")
    for field in ENDPOINTS:
        outbound.checked_url(config[field], f"the platform's {field}")
        if not on_hosts(config[field], [issuer], allowed_hosts):
            raise LtiRequestInvalid(
                f"the platform's {field} {config[field]!r} is not on its issuer's origin {issuer!r}; "
                "the operator allows other hosts with GYMGRADE_LTI_SERVICE_HOSTS"
            )
    headers = {"Authorization": f"Bearer {registration_token}"} if registration_token else {}
    answer = outbound.request(
        "POST",
        config["registration_endpoint"],
        what="registering the tool with the platform",
        headers=headers,
        json_body=tool_configuration(urls),
    )
    if answer.status not in (200, 201):
        raise PlatformUnreachable(
            f"the platform refused the registration: its registration endpoint answered {answer.status}; "
            "the LMS administrator sees why in the LMS"
        )
    registered = answer.json("registering the tool with the platform")
    if not isinstance(registered, dict):
        raise PlatformUnreachable("the platform's registration answer is not a JSON object")
    deployment = (registered.get(TOOL_CONFIGURATION) or {}).get("deployment_id")
    return register_platform(
        session,
        PlatformRegistration(
            issuer=issuer,
            client_id=str(registered.get("client_id") or ""),
            deployment_ids=(str(deployment),) if deployment else (),
            jwks_url=config["jwks_uri"],
            auth_url=config["authorization_endpoint"],
            token_url=config["token_endpoint"],
        ),
        allow_http=outbound.policy.allow_http,
    )

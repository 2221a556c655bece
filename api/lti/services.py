"""The LTI Advantage services the tool calls: OAuth 2 client credentials (a JWT assertion signed by the
tool's key), Assignment and Grade Services (line items, scores) and Names and Role Provisioning."""

from __future__ import annotations

import secrets
import threading
import time
from dataclasses import dataclass
from datetime import datetime
from typing import Any
from urllib.parse import urlencode, urlsplit, urlunsplit

from sqlalchemy.orm import Session

from api.errors import PlatformUnreachable
from api.lti.keys import sign
from api.lti.outbound import Answer, Outbound, on_hosts
from api.models import LtiLink, LtiPlatform

ASSERTION_SECONDS = 300
RESOURCE_ID = "gymgrade"
"""The resourceId of the tool's line items: a link's line item is found by it, never made twice."""
LINEITEM = "application/vnd.ims.lis.v2.lineitem+json"
LINEITEMS = "application/vnd.ims.lis.v2.lineitemcontainer+json"
SCORE = "application/vnd.ims.lis.v1.score+json"
MEMBERSHIPS = "application/vnd.ims.lti-nrps.v2.membershipcontainer+json"
MAX_ROSTER_PAGES = 100


class ServiceFailed(Exception):
    """A platform's service refused or failed a request (the message says which, never its answer's body)."""


def _refused(what: str, answer: Answer) -> ServiceFailed:
    return ServiceFailed(f"{what}: the LMS answered {answer.status}")


def _json(answer: Answer, what: str) -> Any:
    try:
        return answer.json(what)
    except PlatformUnreachable as error:
        raise ServiceFailed(str(error)) from None


def platform_origins(platform: LtiPlatform) -> tuple[str, ...]:
    """The URLs whose origins are the platform's own: its issuer and registered endpoints."""
    return (platform.issuer, platform.token_url, platform.jwks_url, platform.auth_url)


@dataclass(frozen=True)
class Grant:
    """A platform's access token, and where it may be sent: only URLs on the platform's own origins or
    hosts the operator allows (GYMGRADE_LTI_SERVICE_HOSTS), whatever URL a launch or a roster page names."""

    bearer: str
    origins: tuple[str, ...]
    allowed_hosts: tuple[str, ...]
    outbound: Outbound

    def call(
        self,
        method: str,
        url: str,
        *,
        what: str,
        accept: str,
        json_body: Any = None,
        content_type: str | None = None,
    ) -> Answer:
        """One request with the token (raises ServiceFailed: a foreign host, no answer, a refused one)."""
        if not on_hosts(url, self.origins, self.allowed_hosts):
            raise ServiceFailed(
                f"{what}: {url!r} is not on the platform's own hosts ({', '.join(sorted({urlsplit(o).netloc for o in self.origins}))}); "  # noqa: E501
                "the access token is never sent elsewhere; the operator allows other hosts with GYMGRADE_LTI_SERVICE_HOSTS"  # noqa: E501
            )
        headers = {"Authorization": f"Bearer {self.bearer}", "Accept": accept}
        if content_type is not None:
            headers["Content-Type"] = content_type
        try:
            return self.outbound.request(method, url, what=what, headers=headers, json_body=json_body)
        except PlatformUnreachable as error:
            raise ServiceFailed(str(error)) from None


class AccessTokens:
    """Access tokens per (platform, scopes), requested with client_credentials and kept until near expiry.
    Threads asking at once for a token not held yet wait for one request: the platform is asked once."""

    def __init__(self, outbound: Outbound, allowed_hosts: tuple[str, ...] = ()) -> None:
        self._outbound = outbound
        self._allowed_hosts = allowed_hosts
        self._lock = threading.Lock()
        self._tokens: dict[tuple[int, str], tuple[float, str]] = {}
        self._asking: dict[tuple[int, str], threading.Lock] = {}

    def token(self, session: Session, platform: LtiPlatform, scopes: tuple[str, ...]) -> Grant:
        """A bearer token for ``scopes`` at the platform (raises ServiceFailed)."""
        key = (platform.id, " ".join(sorted(scopes)))
        with self._lock:
            asking = self._asking.setdefault(key, threading.Lock())
        with asking:
            return self._held_or_new(session, platform, key)

    def _held_or_new(self, session: Session, platform: LtiPlatform, key: tuple[int, str]) -> Grant:
        with self._lock:
            cached = self._tokens.get(key)
        if cached is not None and cached[0] > time.monotonic():
            return self._grant(platform, cached[1])
        now = int(time.time())
        assertion = sign(
            session,
            {
                "iss": platform.client_id,
                "sub": platform.client_id,
                "aud": platform.token_url,
                "iat": now,
                "exp": now + ASSERTION_SECONDS,
                "jti": secrets.token_urlsafe(16),
            },
        )
        what = f"asking the LMS's token endpoint {platform.token_url} for an access token"
        try:
            answer = self._outbound.request(
                "POST",
                platform.token_url,
                what=what,
                headers={"Accept": "application/json"},
                form={
                    "grant_type": "client_credentials",
                    "client_assertion_type": "urn:ietf:params:oauth:client-assertion-type:jwt-bearer",
                    "client_assertion": assertion,
                    "scope": key[1],
                },
            )
        except PlatformUnreachable as error:
            raise ServiceFailed(str(error)) from None
        if answer.status != 200:
            raise _refused(what, answer)
        body = _json(answer, what)
        if not isinstance(body, dict) or not isinstance(body.get("access_token"), str):
            raise ServiceFailed(f"{what}: the answer holds no access_token")
        token = str(body["access_token"])
        try:
            lifetime = float(body.get("expires_in", 3600))
        except (TypeError, ValueError):
            lifetime = 60.0
        with self._lock:
            self._tokens[key] = (time.monotonic() + max(lifetime - 60.0, 1.0), token)
        return self._grant(platform, token)

    def _grant(self, platform: LtiPlatform, bearer: str) -> Grant:
        return Grant(bearer, platform_origins(platform), self._allowed_hosts, self._outbound)

    def forget(self, platform: LtiPlatform) -> None:
        """Drop a platform's tokens (after the platform refused one)."""
        with self._lock:
            for key in [key for key in self._tokens if key[0] == platform.id]:
                del self._tokens[key]


def _with_path(url: str, suffix: str) -> str:
    parts = urlsplit(url)
    return urlunsplit(parts._replace(path=parts.path.rstrip("/") + suffix))


def line_item(link: LtiLink, grant: Grant, *, score_maximum: float) -> str:
    """The URL of the link's line item: the launch's, else the one found by resourceId, else a new one."""
    if link.lineitem_url:
        return link.lineitem_url
    if not link.lineitems_url:
        raise ServiceFailed(
            "the LMS gave this link no line items service (Assignment and Grade Services off)"
        )
    query = urlencode({"resource_link_id": link.resource_link_id, "resource_id": RESOURCE_ID})
    separator = "&" if urlsplit(link.lineitems_url).query else "?"
    what = "listing the link's line items"
    answer = grant.call("GET", link.lineitems_url + separator + query, what=what, accept=LINEITEMS)
    if answer.status != 200:
        raise _refused(what, answer)
    listed = _json(answer, what)
    for item in listed if isinstance(listed, list) else []:
        if (
            isinstance(item, dict)
            and item.get("resourceId") == RESOURCE_ID
            and item.get("resourceLinkId") == link.resource_link_id
            and item.get("id")
        ):
            return str(item["id"])
    what = "creating the link's line item"
    answer = grant.call(
        "POST",
        link.lineitems_url,
        what=what,
        accept=LINEITEM,
        content_type=LINEITEM,
        json_body={
            "scoreMaximum": score_maximum,
            "label": link.title or "gymgrade",
            "resourceId": RESOURCE_ID,
            "resourceLinkId": link.resource_link_id,
            "tag": "gymgrade",
        },
    )
    if answer.status not in (200, 201):
        raise _refused(what, answer)
    created = _json(answer, what)
    if not isinstance(created, dict) or not created.get("id"):
        raise ServiceFailed(f"{what}: the LMS made a line item without an id")
    return str(created["id"])


def publish_score(
    lineitem_url: str,
    grant: Grant,
    *,
    user_id: str,
    score: float | None,
    maximum: float | None,
    timestamp: datetime,
) -> None:
    """POST one score to a line item's scores endpoint (raises ServiceFailed); ``score`` None: submitted,
    being graded (no score given)."""
    body: dict[str, Any] = {
        "userId": user_id,
        "timestamp": timestamp.isoformat(timespec="microseconds") + "Z",
        "activityProgress": "Submitted",
        "gradingProgress": "Pending",
    }
    if score is not None:
        body.update(
            scoreGiven=score,
            scoreMaximum=maximum,
            activityProgress="Completed",
            gradingProgress="FullyGraded",
        )
    what = "publishing the score"
    answer = grant.call(
        "POST",
        _with_path(lineitem_url, "/scores"),
        what=what,
        accept="application/json",
        content_type=SCORE,
        json_body=body,
    )
    if answer.status not in (200, 201, 202, 204):
        raise _refused(what, answer)


def roster(memberships_url: str, grant: Grant) -> list[dict[str, Any]]:
    """Every member of the context (Names and Role Provisioning, following ``rel="next"`` pages, each on
    the platform's own hosts)."""
    members: list[dict[str, Any]] = []
    url: str | None = memberships_url
    what = "reading the course roster"
    for _ in range(MAX_ROSTER_PAGES):
        if url is None:
            return members
        try:
            answer = grant.call("GET", url, what=what, accept=MEMBERSHIPS)
            if answer.status != 200:
                raise _refused(what, answer)
            page = _json(answer, what)
        except ServiceFailed as error:
            raise PlatformUnreachable(str(error)) from None
        found = page.get("members") if isinstance(page, dict) else None
        if not isinstance(found, list):
            raise PlatformUnreachable("the LMS's roster has no members list")
        members.extend(member for member in found if isinstance(member, dict))
        url = answer.next_url
    raise PlatformUnreachable(f"the roster has more than {MAX_ROSTER_PAGES} pages; expected a course's")

"""The LTI Advantage services the tool calls: OAuth 2 client credentials (a JWT assertion signed by the
tool's key), Assignment and Grade Services (line items, scores) and Names and Role Provisioning."""

from __future__ import annotations

import secrets
import threading
import time
from datetime import datetime
from typing import Any
from urllib.parse import urlencode, urlsplit, urlunsplit

import httpx
from sqlalchemy.orm import Session

from api.errors import PlatformUnreachable
from api.lti.keys import sign
from api.models import LtiLink, LtiPlatform

HTTP_TIMEOUT_SECONDS = 15.0
ASSERTION_SECONDS = 300
RESOURCE_ID = "gymgrade"
"""The resourceId of the tool's line items: a link's line item is found by it, never made twice."""
LINEITEM = "application/vnd.ims.lis.v2.lineitem+json"
LINEITEMS = "application/vnd.ims.lis.v2.lineitemcontainer+json"
SCORE = "application/vnd.ims.lis.v1.score+json"
MEMBERSHIPS = "application/vnd.ims.lti-nrps.v2.membershipcontainer+json"
MAX_ROSTER_PAGES = 100


class ServiceFailed(Exception):
    """A platform's service refused or failed a request (the message says which, and its answer)."""


def _refused(what: str, response: httpx.Response) -> ServiceFailed:
    return ServiceFailed(f"{what}: the LMS answered {response.status_code} {response.text[:200]!r}")


def _json(response: httpx.Response, what: str) -> Any:
    try:
        return response.json()
    except ValueError:
        raise ServiceFailed(f"{what}: the LMS answered {response.text[:200]!r}, which is not JSON") from None


class AccessTokens:
    """Access tokens per (platform, scopes), requested with client_credentials and kept until near expiry."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._tokens: dict[tuple[int, str], tuple[float, str]] = {}

    def token(self, session: Session, platform: LtiPlatform, scopes: tuple[str, ...]) -> str:
        """A bearer token for ``scopes`` at the platform (raises ServiceFailed)."""
        key = (platform.id, " ".join(sorted(scopes)))
        with self._lock:
            cached = self._tokens.get(key)
        if cached is not None and cached[0] > time.monotonic():
            return cached[1]
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
        try:
            response = httpx.post(
                platform.token_url,
                data={
                    "grant_type": "client_credentials",
                    "client_assertion_type": "urn:ietf:params:oauth:client-assertion-type:jwt-bearer",
                    "client_assertion": assertion,
                    "scope": key[1],
                },
                timeout=HTTP_TIMEOUT_SECONDS,
            )
        except httpx.HTTPError as error:
            raise ServiceFailed(
                f"the LMS's token endpoint {platform.token_url} did not answer: {error}"
            ) from None
        if response.status_code != 200:
            raise _refused(f"the LMS refused an access token at {platform.token_url}", response)
        body = _json(response, "asking for an access token")
        if not isinstance(body, dict) or not isinstance(body.get("access_token"), str):
            raise ServiceFailed(f"the LMS's token endpoint answered {body!r:.200} without an access_token")
        token = str(body["access_token"])
        try:
            lifetime = float(body.get("expires_in", 3600))
        except (TypeError, ValueError):
            lifetime = 60.0
        with self._lock:
            self._tokens[key] = (time.monotonic() + max(lifetime - 60.0, 1.0), token)
        return token

    def forget(self, platform: LtiPlatform) -> None:
        """Drop a platform's tokens (after the platform refused one)."""
        with self._lock:
            for key in [key for key in self._tokens if key[0] == platform.id]:
                del self._tokens[key]


def _with_path(url: str, suffix: str) -> str:
    parts = urlsplit(url)
    return urlunsplit(parts._replace(path=parts.path.rstrip("/") + suffix))


def line_item(link: LtiLink, token: str, *, score_maximum: float) -> str:
    """The URL of the link's line item: the launch's, else the one found by resourceId, else a new one."""
    if link.lineitem_url:
        return link.lineitem_url
    if not link.lineitems_url:
        raise ServiceFailed(
            "the LMS gave this link no line items service (Assignment and Grade Services off)"
        )
    headers = {"Authorization": f"Bearer {token}"}
    query = urlencode({"resource_link_id": link.resource_link_id, "resource_id": RESOURCE_ID})
    separator = "&" if urlsplit(link.lineitems_url).query else "?"
    try:
        response = httpx.get(
            link.lineitems_url + separator + query,
            headers={**headers, "Accept": LINEITEMS},
            timeout=HTTP_TIMEOUT_SECONDS,
        )
        if response.status_code != 200:
            raise _refused("listing the link's line items", response)
        for item in _json(response, "listing the link's line items"):
            if (
                isinstance(item, dict)
                and item.get("resourceId") == RESOURCE_ID
                and item.get("resourceLinkId") == link.resource_link_id
                and item.get("id")
            ):
                return str(item["id"])
        response = httpx.post(
            link.lineitems_url,
            json={
                "scoreMaximum": score_maximum,
                "label": link.title or "gymgrade",
                "resourceId": RESOURCE_ID,
                "resourceLinkId": link.resource_link_id,
                "tag": "gymgrade",
            },
            headers={**headers, "Content-Type": LINEITEM, "Accept": LINEITEM},
            timeout=HTTP_TIMEOUT_SECONDS,
        )
    except httpx.HTTPError as error:
        raise ServiceFailed(f"the LMS's line items service did not answer: {error}") from None
    if response.status_code not in (200, 201):
        raise _refused("creating the link's line item", response)
    created = _json(response, "creating the link's line item")
    if not isinstance(created, dict) or not created.get("id"):
        raise ServiceFailed(f"the LMS made a line item without an id: {created!r:.200}")
    return str(created["id"])


def publish_score(
    lineitem_url: str,
    token: str,
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
    try:
        response = httpx.post(
            _with_path(lineitem_url, "/scores"),
            json=body,
            headers={"Authorization": f"Bearer {token}", "Content-Type": SCORE},
            timeout=HTTP_TIMEOUT_SECONDS,
        )
    except httpx.HTTPError as error:
        raise ServiceFailed(f"the LMS's scores service did not answer: {error}") from None
    if response.status_code not in (200, 201, 202, 204):
        raise _refused("publishing the score", response)


def roster(memberships_url: str, token: str) -> list[dict[str, Any]]:
    """Every member of the context (Names and Role Provisioning, following ``rel="next"`` pages)."""
    members: list[dict[str, Any]] = []
    url: str | None = memberships_url
    for _ in range(MAX_ROSTER_PAGES):
        if url is None:
            return members
        try:
            response = httpx.get(
                url,
                headers={"Authorization": f"Bearer {token}", "Accept": MEMBERSHIPS},
                timeout=HTTP_TIMEOUT_SECONDS,
            )
        except httpx.HTTPError as error:
            raise PlatformUnreachable(f"the LMS's roster service did not answer: {error}") from None
        if response.status_code != 200:
            raise PlatformUnreachable(str(_refused("reading the course roster", response)))
        try:
            page = _json(response, "reading the course roster")
        except ServiceFailed as error:
            raise PlatformUnreachable(str(error)) from None
        found = page.get("members") if isinstance(page, dict) else None
        if not isinstance(found, list):
            raise PlatformUnreachable("the LMS's roster has no members list")
        members.extend(member for member in found if isinstance(member, dict))
        url = response.links.get("next", {}).get("url")
    raise PlatformUnreachable(f"the roster has more than {MAX_ROSTER_PAGES} pages; expected a course's")

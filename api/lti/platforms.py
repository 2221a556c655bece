"""Platforms registered with the tool, and their public keys (fetched from their JWKS URL, cached)."""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass
from urllib.parse import urlsplit

import httpx
from joserfc.errors import JoseError
from joserfc.jwk import KeySet
from sqlalchemy import select
from sqlalchemy.exc import IntegrityError
from sqlalchemy.orm import Session

from api.errors import LaunchRefused, LtiRequestInvalid, PlatformExists, PlatformUnreachable
from api.models import LtiPlatform

HTTP_TIMEOUT_SECONDS = 10.0
JWKS_CACHE_SECONDS = 300.0
MAX_DOCUMENT_BYTES = 1_000_000


@dataclass(frozen=True)
class PlatformRegistration:
    """What the tool needs of a platform: the instructor's manual registration, or dynamic registration's."""

    issuer: str
    client_id: str
    deployment_ids: tuple[str, ...]
    jwks_url: str
    auth_url: str
    token_url: str

    def checked(self) -> PlatformRegistration:
        """The registration itself, once every field is present and every URL is http(s)."""
        for field in ("issuer", "client_id"):
            if not getattr(self, field).strip():
                raise LtiRequestInvalid(f"a platform registration needs its {field}; found an empty value")
        for field in ("issuer", "jwks_url", "auth_url", "token_url"):
            value = getattr(self, field)
            if urlsplit(value).scheme not in ("http", "https") or not urlsplit(value).netloc:
                raise LtiRequestInvalid(
                    f"a platform's {field} must be an http(s) URL, found {value!r}; "
                    "copy it from the LMS's tool registration page"
                )
        return self


def register_platform(session: Session, registration: PlatformRegistration) -> LtiPlatform:
    """Store a platform (refused when the issuer and client id are registered already)."""
    registration.checked()
    row = LtiPlatform(
        issuer=registration.issuer,
        client_id=registration.client_id,
        deployment_ids=list(registration.deployment_ids),
        jwks_url=registration.jwks_url,
        auth_url=registration.auth_url,
        token_url=registration.token_url,
    )
    session.add(row)
    try:
        session.commit()
    except IntegrityError:
        session.rollback()
        raise PlatformExists(
            f"the platform {registration.issuer!r} with client id {registration.client_id!r} is registered "
            "already; add a deployment to it instead"
        ) from None
    return row


def add_deployment(session: Session, platform: LtiPlatform, deployment_id: str) -> None:
    """Accept launches of one more deployment of a registered platform."""
    if deployment_id not in platform.deployment_ids:
        platform.deployment_ids = [*platform.deployment_ids, deployment_id]
        session.commit()


def find_platform(session: Session, issuer: str, client_id: str | None) -> LtiPlatform:
    """The platform registered for ``issuer`` (and ``client_id`` when the platform sends one).

    Raises:
        LaunchRefused: No such platform, or several for the issuer and no client id to choose.
    """
    query = select(LtiPlatform).where(LtiPlatform.issuer == issuer)
    if client_id:
        query = query.where(LtiPlatform.client_id == client_id)
    rows = list(session.scalars(query))
    if len(rows) == 1:
        return rows[0]
    if not rows:
        raise LaunchRefused(
            f"no platform is registered with issuer {issuer!r}"
            + (f" and client id {client_id!r}" if client_id else "")
            + "; the instructor registers the LMS first (docs/operations.md, LTI)"
        )
    raise LaunchRefused(
        f"several client ids are registered for issuer {issuer!r} and the LMS sent none; "
        "expected client_id in the login request"
    )


def fetch_json(url: str, *, headers: dict[str, str] | None = None) -> object:
    """GET a JSON document of at most ``MAX_DOCUMENT_BYTES`` (raises PlatformUnreachable)."""
    try:
        response = httpx.get(url, headers=headers, timeout=HTTP_TIMEOUT_SECONDS)
        response.raise_for_status()
        if len(response.content) > MAX_DOCUMENT_BYTES:
            raise PlatformUnreachable(f"{url} answered {len(response.content)} bytes; expected a small JSON")
        return response.json()
    except (httpx.HTTPError, ValueError) as error:
        raise PlatformUnreachable(f"could not read JSON from {url}: {error}") from None


class PlatformKeys:
    """The platforms' key sets by JWKS URL, kept ``JWKS_CACHE_SECONDS``, fetched again for an unknown kid."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._cached: dict[str, tuple[float, KeySet]] = {}

    def key_set(self, jwks_url: str, kid: str | None) -> KeySet:
        """The key set at ``jwks_url`` holding ``kid`` if the platform publishes it."""
        with self._lock:
            cached = self._cached.get(jwks_url)
        fresh = cached is not None and time.monotonic() - cached[0] < JWKS_CACHE_SECONDS
        if cached is not None and fresh and (kid is None or _holds(cached[1], kid)):
            return cached[1]
        document = fetch_json(jwks_url)
        try:
            keys = KeySet.import_key_set(document)  # type: ignore[arg-type]
        except (JoseError, ValueError, TypeError, KeyError) as error:
            raise PlatformUnreachable(f"{jwks_url} is not a JWKS document: {error}") from None
        with self._lock:
            self._cached[jwks_url] = (time.monotonic(), keys)
        return keys


def _holds(keys: KeySet, kid: str) -> bool:
    return any(key.kid == kid for key in keys.keys)

"""Platforms registered with the tool, and their public keys (fetched from their JWKS URL, cached).

A platform's keys are kept ``JWKS_CACHE_SECONDS``; a launch naming a key id the cached set lacks (a
rotation at the platform) fetches them again, at most once every ``JWKS_REFETCH_SECONDS`` per JWKS URL,
failures included: unauthenticated launches with made-up key ids cannot make the tool fetch on each.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass
from urllib.parse import urlsplit

from joserfc.errors import JoseError
from joserfc.jwk import KeySet
from sqlalchemy import select
from sqlalchemy.exc import IntegrityError
from sqlalchemy.orm import Session

from api.errors import LaunchRefused, LtiRequestInvalid, PlatformExists, PlatformUnreachable
from api.lti.outbound import Outbound
from api.models import LtiPlatform

JWKS_CACHE_SECONDS = 300.0
JWKS_REFETCH_SECONDS = 60.0


@dataclass(frozen=True)
class PlatformRegistration:
    """What the tool needs of a platform: the instructor's manual registration, or dynamic registration's."""

    issuer: str
    client_id: str
    deployment_ids: tuple[str, ...]
    jwks_url: str
    auth_url: str
    token_url: str
    frame_ancestors: tuple[str, ...] = ()
    """Origins besides the launch's and the issuer's that frame the tool (every ancestor frame's)."""

    def checked(self, *, allow_http: bool) -> PlatformRegistration:
        """The registration itself, once every field is present and every URL is https (or http when
        ``allow_http``, GYMGRADE_LTI_ALLOW_HTTP)."""
        for field in ("issuer", "client_id"):
            if not getattr(self, field).strip():
                raise LtiRequestInvalid(f"a platform registration needs its {field}; found an empty value")
        schemes = ("https", "http") if allow_http else ("https",)
        for field in ("issuer", "jwks_url", "auth_url", "token_url"):
            value = getattr(self, field)
            if urlsplit(value).scheme not in schemes or not urlsplit(value).hostname:
                raise LtiRequestInvalid(
                    f"a platform's {field} must be an {' or '.join(schemes)} URL, found {value!r}; "
                    "copy it from the LMS's tool registration page (LMSs serve LTI over https)"
                )
        checked_origins(self.frame_ancestors, allow_http=allow_http)
        return self


def checked_origins(origins: tuple[str, ...] | list[str], *, allow_http: bool) -> list[str]:
    """``origins`` when each is an origin (scheme://host[:port], https or, when ``allow_http``, http).

    Raises:
        LtiRequestInvalid: One is not.
    """
    schemes = ("https", "http") if allow_http else ("https",)
    for origin in origins:
        parts = urlsplit(origin)
        if (
            parts.scheme not in schemes
            or not parts.hostname
            or parts.path not in ("", "/")
            or parts.query
            or parts.fragment
            or any(character in origin for character in " ;,'\"")
        ):
            raise LtiRequestInvalid(
                f"a frame ancestor must be an origin such as https://apps.lms.example.edu ({' or '.join(schemes)}, no path); found {origin!r}"  # noqa: E501
            )
    return [origin.rstrip("/") for origin in origins]


def register_platform(
    session: Session, registration: PlatformRegistration, *, allow_http: bool
) -> LtiPlatform:
    """Store a platform (refused when the issuer and client id are registered already)."""
    registration.checked(allow_http=allow_http)
    row = LtiPlatform(
        issuer=registration.issuer,
        client_id=registration.client_id,
        deployment_ids=list(registration.deployment_ids),
        jwks_url=registration.jwks_url,
        auth_url=registration.auth_url,
        token_url=registration.token_url,
        frame_ancestors=checked_origins(registration.frame_ancestors, allow_http=allow_http),
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


class PlatformKeys:
    """The platforms' key sets by JWKS URL, kept ``JWKS_CACHE_SECONDS``, fetched again for an unknown kid
    at most every ``JWKS_REFETCH_SECONDS``."""

    def __init__(self, outbound: Outbound) -> None:
        self._outbound = outbound
        self._lock = threading.Lock()
        self._cached: dict[str, tuple[float, KeySet]] = {}
        self._tried: dict[str, float] = {}

    def key_set(self, jwks_url: str, kid: str | None) -> KeySet:
        """The key set at ``jwks_url``, holding ``kid`` if the platform publishes it (the cached set, which
        lacks it, when the URL was fetched less than ``JWKS_REFETCH_SECONDS`` ago)."""
        now = time.monotonic()
        with self._lock:
            cached = self._cached.get(jwks_url)
            fresh = cached is not None and now - cached[0] < JWKS_CACHE_SECONDS
            if cached is not None and fresh and (kid is None or _holds(cached[1], kid)):
                return cached[1]
            recently = now - self._tried.get(jwks_url, -JWKS_REFETCH_SECONDS) < JWKS_REFETCH_SECONDS
            if recently and cached is not None:
                return cached[1]
            if recently:
                raise PlatformUnreachable(
                    f"the platform's keys at {jwks_url} could not be read a moment ago; "
                    f"the tool tries again at most every {JWKS_REFETCH_SECONDS:g} s"
                )
            self._tried[jwks_url] = now
        document = self._outbound.get_json(jwks_url, what="reading the platform's keys (JWKS)")
        try:
            keys = KeySet.import_key_set(document)
        except (JoseError, ValueError, TypeError, KeyError) as error:
            raise PlatformUnreachable(f"{jwks_url} is not a JWKS document: {error}") from None
        with self._lock:
            self._cached[jwks_url] = (time.monotonic(), keys)
        return keys


def _holds(keys: KeySet, kid: str) -> bool:
    return any(key.kid == kid for key in keys.keys)

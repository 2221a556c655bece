"""What binds a launch's OIDC state and its session to the browser that started them.

A login makes a random secret; the state (signed by the tool) carries only its SHA-256 (``bind``). The
browser keeps the secret in a cookie (``SameSite=None; Secure; HttpOnly; Partitioned``: an LMS frames the
tool, and partitioned cookies are kept by browsers blocking third-party cookies) and, when the platform
offers it (``lti_storage_target``), in the platform's storage too, through LTI's client-side OIDC
postMessage API (``lti.put_data``; the launch reads it back with ``lti.get_data``). The launch is accepted
only with the secret: an id_token and state replayed from another browser (login CSRF) is refused.

The session a launch opens is bound the same way: its row keeps the SHA-256 of the browser cookie's secret
(one per browser: every session a browser opens is bound to it), and its ``?lti_session=`` link works
only in a browser sending that cookie. A launch verified through the
platform's storage (the browser sent no cookie) opens a session the browser could not prove again:
that one is bound to nothing but its link, as before.
"""

from __future__ import annotations

import hashlib
import hmac
import secrets

from starlette.responses import Response

LOGIN_COOKIE_PREFIX = "lti_bind_"
"""The login's cookie: one per state (several logins in several tabs), read on the launch's path only."""
SESSION_COOKIE = "lti_browser"
"""The session's cookie."""
STORAGE_KEY_PREFIX = "gymgrade_bind_"
"""The platform storage's key of a login's secret."""
LAUNCH_PATH = "/lti/launch"


def new_secret() -> tuple[str, str]:
    """A fresh secret and its digest (what the state or the session row keeps)."""
    secret = secrets.token_urlsafe(32)
    return secret, digest(secret)


def digest(secret: str) -> str:
    """The SHA-256 (hex) of a secret."""
    return hashlib.sha256(secret.encode("utf-8")).hexdigest()


def matches(secret: str | None, expected: str | None) -> bool:
    """Whether ``secret`` has the digest ``expected`` (constant time; False when either is missing)."""
    if not secret or not expected:
        return False
    return hmac.compare_digest(digest(secret), expected)


def state_name(state: str) -> str:
    """The short name a login's cookie and storage key carry: the state's own digest, shortened."""
    return hashlib.sha256(state.encode("ascii", "replace")).hexdigest()[:24]


def set_cookie(response: Response, name: str, value: str, *, max_age: float, path: str) -> None:
    """Set a cookie the LMS's frame keeps: Secure, HttpOnly, SameSite=None (the launch is a cross-site
    POST), Partitioned (kept, per top-level site, where third-party cookies are blocked). Browsers treat
    http://localhost as secure, so tests on loopback keep it too.

    Written by hand: ``http.cookies`` writes ``Partitioned`` only from Python 3.14 (Starlette refuses it
    before). ``name`` and ``value`` are the tool's own URL-safe strings.
    """
    response.headers.append(
        "set-cookie",
        f"{name}={value}; Max-Age={int(max_age)}; Path={path}; Secure; HttpOnly; SameSite=None; Partitioned",
    )

"""Every HTTP request the tool makes for a platform goes through here: the registration POST, OpenID
configurations, JWKS, access tokens, line items, scores and rosters (each NRPS ``next`` page included).

A platform, or whoever fills in a registration or a launch, names these URLs; the tool must not become
their proxy into the university's network (SSRF). So every request:

- is https, unless ``GYMGRADE_LTI_ALLOW_HTTP`` (tests on loopback);
- goes to a public address: the host is resolved here, every address it resolves to is checked (no
  loopback, link-local, private, multicast, reserved or unspecified address unless one of
  ``GYMGRADE_LTI_ALLOWED_NETWORKS`` holds it), and the connection is made to the checked address, not
  resolved again (no DNS-rebinding gap); TLS still verifies the certificate of the URL's host name;
- follows no redirect and uses no proxy from the environment;
- is read streamed and bounded: refused past ``GYMGRADE_LTI_MAX_RESPONSE_BYTES`` (never downloaded whole
  before the check, no compressed encoding) and past ``GYMGRADE_LTI_REQUEST_SECONDS`` in total, not per read;
- on failure, says what was asked and the status, never the answer's body (an internal service's page).

Whether a URL is on a platform's own hosts is :func:`on_hosts`' answer; the callers decide which hosts.
"""

from __future__ import annotations

import ipaddress
import json
import socket
import time
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any
from urllib.parse import urlsplit

import httpcore
import httpx

from api.errors import OutboundRefused, PlatformUnreachable
from api.settings import Settings

Network = ipaddress.IPv4Network | ipaddress.IPv6Network
Address = ipaddress.IPv4Address | ipaddress.IPv6Address


@dataclass(frozen=True)
class OutboundPolicy:
    """What the tool may ask of the network on a platform's behalf."""

    allow_http: bool = False
    allowed_networks: tuple[Network, ...] = ()
    max_bytes: int = 1_000_000
    total_seconds: float = 15.0

    @classmethod
    def of(cls, settings: Settings) -> OutboundPolicy:
        """The policy the settings give."""
        return cls(
            allow_http=settings.lti_allow_http,
            allowed_networks=settings.lti_networks,
            max_bytes=settings.lti_max_response_bytes,
            total_seconds=settings.lti_request_seconds,
        )


def refusal(address: Address, policy: OutboundPolicy) -> str | None:
    """Why the tool may not connect to ``address`` (None: it may): a non-public address outside the
    operator's allowed networks."""
    if any(address in network for network in policy.allowed_networks):
        return None
    if isinstance(address, ipaddress.IPv6Address):
        embedded = _embedded_ipv4(address)
        if embedded is not None:
            return refusal(embedded, policy)
    kinds = [
        ("loopback", address.is_loopback),
        ("link-local", address.is_link_local),
        ("unspecified", address.is_unspecified),
        ("multicast", address.is_multicast),
        ("private", address.is_private),
        ("reserved", address.is_reserved),
        ("not globally routable", not address.is_global),
    ]
    for kind, applies in kinds:
        if applies:
            return (
                f"{address} is a {kind} address; "
                "the tool reaches only public addresses unless the operator allows the network (GYMGRADE_LTI_ALLOWED_NETWORKS)"  # noqa: E501
            )
    return None


NAT64 = (ipaddress.ip_network("64:ff9b::/96"), ipaddress.ip_network("64:ff9b:1::/48"))
"""IPv6 prefixes a NAT64 gateway translates to the IPv4 address in their last 32 bits."""


def _embedded_ipv4(address: ipaddress.IPv6Address) -> ipaddress.IPv4Address | None:
    """The IPv4 address an IPv6 one reaches in the end: mapped (::ffff:a.b.c.d), 6to4 or NAT64."""
    if address.ipv4_mapped is not None:
        return address.ipv4_mapped
    if address.sixtofour is not None:
        return address.sixtofour
    if any(address in network for network in NAT64):
        return ipaddress.IPv4Address(int(address) & 0xFFFFFFFF)
    return None


def checked_address(host: str, port: int, policy: OutboundPolicy) -> str:
    """The address to connect to for ``host``: every address it resolves to must be allowed.

    Raises:
        OutboundRefused: One of the addresses is not allowed.
        PlatformUnreachable: The name does not resolve.
    """
    try:
        found = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)
    except OSError as error:
        raise PlatformUnreachable(f"the host {host!r} does not resolve ({error.strerror or error})") from None
    addresses = list(dict.fromkeys(ipaddress.ip_address(str(entry[4][0]).split("%")[0]) for entry in found))
    if not addresses:
        raise PlatformUnreachable(f"the host {host!r} resolves to no address")
    for address in addresses:
        why = refusal(address, policy)
        if why is not None:
            raise OutboundRefused(f"the tool does not connect to {host!r}: {why}")
    return str(addresses[0])


class _DeadlineStream(httpcore.NetworkStream):
    """A connection that refuses to read or write past its deadline: the request's total time, not a
    time per read (a server dripping a byte a second never resets it)."""

    def __init__(self, stream: httpcore.NetworkStream, deadline: float) -> None:
        self._stream = stream
        self._deadline = deadline

    def _left(self, timeout: float | None) -> float:
        left = self._deadline - time.monotonic()
        if left <= 0:
            raise httpcore.ReadTimeout("the request's total time is over")
        return left if timeout is None else min(timeout, left)

    def read(self, max_bytes: int, timeout: float | None = None) -> bytes:
        return self._stream.read(max_bytes, self._left(timeout))

    def write(self, buffer: bytes, timeout: float | None = None) -> None:
        self._stream.write(buffer, self._left(timeout))

    def close(self) -> None:
        self._stream.close()

    def start_tls(
        self, ssl_context: Any, server_hostname: str | None = None, timeout: float | None = None
    ) -> httpcore.NetworkStream:
        secured = self._stream.start_tls(ssl_context, server_hostname, self._left(timeout))
        return _DeadlineStream(secured, self._deadline)

    def get_extra_info(self, info: str) -> Any:
        return self._stream.get_extra_info(info)


class _CheckedBackend(httpcore.SyncBackend):
    """httpcore's own socket backend, connecting only to the address :func:`checked_address` gave, each
    connection (one per request: no keep-alive) ending at the policy's total time."""

    def __init__(self, policy: OutboundPolicy) -> None:
        self._policy = policy

    def connect_tcp(
        self,
        host: str,
        port: int,
        timeout: float | None = None,
        local_address: str | None = None,
        socket_options: Iterable[Any] | None = None,
    ) -> httpcore.NetworkStream:
        deadline = time.monotonic() + self._policy.total_seconds
        address = checked_address(host, port, self._policy)
        stream = super().connect_tcp(address, port, timeout, local_address, socket_options)
        return _DeadlineStream(stream, deadline)


class _CheckedTransport(httpx.HTTPTransport):
    """httpx's transport over a pool with the checked backend. httpx offers no public way to give its
    pool a network backend, so the pool it made is replaced (pinned by tests/api/lti/test_outbound.py:
    a private address must be refused)."""

    def __init__(self, policy: OutboundPolicy) -> None:
        super().__init__(trust_env=False)
        self._pool = httpcore.ConnectionPool(
            ssl_context=httpx.create_ssl_context(trust_env=False),
            network_backend=_CheckedBackend(policy),
            max_connections=20,
            max_keepalive_connections=0,
        )


@dataclass(frozen=True)
class Answer:
    """A platform's whole answer, read within the policy's bounds."""

    url: str
    status: int
    headers: httpx.Headers
    body: bytes
    next_url: str | None
    """The ``Link: <...>; rel="next"`` URL (NRPS paging), absolute."""

    def json(self, what: str) -> Any:
        """The body as JSON (raises PlatformUnreachable naming ``what`` when it is not)."""
        try:
            return json.loads(self.body)
        except (ValueError, UnicodeDecodeError):
            raise PlatformUnreachable(
                f"{what}: {self.url} answered {self.status} with a body that is not JSON"
            ) from None


class Outbound:
    """The tool's HTTP client for platforms (thread-safe; one per service)."""

    def __init__(self, policy: OutboundPolicy) -> None:
        self.policy = policy
        self._client = httpx.Client(
            transport=_CheckedTransport(policy), trust_env=False, follow_redirects=False
        )

    def checked_url(self, url: str, what: str) -> str:
        """``url`` when its scheme is allowed (https; http too under GYMGRADE_LTI_ALLOW_HTTP) with a host.

        Raises:
            OutboundRefused: Another scheme, or no host.
        """
        parts = urlsplit(url)
        schemes = ("https", "http") if self.policy.allow_http else ("https",)
        if parts.scheme not in schemes or not parts.hostname:
            raise OutboundRefused(
                f"{what}: {url!r} is not an {' or '.join(schemes)} URL; "
                "the tool talks to platforms over https only (GYMGRADE_LTI_ALLOW_HTTP is for tests on loopback)"  # noqa: E501
            )
        return url

    def request(
        self,
        method: str,
        url: str,
        *,
        what: str,
        headers: dict[str, str] | None = None,
        json_body: Any = None,
        form: dict[str, str] | None = None,
    ) -> Answer:
        """Make one request and read its answer whole, within the policy's bounds (any status).

        Args:
            method: GET or POST.
            url: Where to.
            what: What the request is for, as a person reads it ("reading the platform's keys").
            headers: Extra headers.
            json_body: A JSON body to send.
            form: A form body to send.

        Raises:
            OutboundRefused: The URL, its address or the answer's size or time breaks the policy.
            PlatformUnreachable: No answer (connection refused, name unknown, TLS failure).
        """
        self.checked_url(url, what)
        request_headers = {"Accept-Encoding": "identity", **(headers or {})}
        try:
            with self._client.stream(
                method,
                url,
                headers=request_headers,
                json=json_body,
                data=form,
                timeout=httpx.Timeout(self.policy.total_seconds),
            ) as response:
                body = self._read(response, url, what)
                next_url = response.links.get("next", {}).get("url")
        except httpx.TimeoutException:
            raise self._too_slow(url, what) from None
        except httpx.HTTPError as error:
            raise PlatformUnreachable(f"{what}: {url} did not answer ({type(error).__name__})") from None
        if next_url is not None:
            next_url = str(httpx.URL(url).join(next_url))
        return Answer(url, response.status_code, response.headers, body, next_url)

    def _read(self, response: httpx.Response, url: str, what: str) -> bytes:
        limit = self.policy.max_bytes
        declared = response.headers.get("content-length", "")
        if declared.isdigit() and int(declared) > limit:
            raise OutboundRefused(
                f"{what}: {url} announced {int(declared)} bytes; "
                f"the tool reads at most {limit} (GYMGRADE_LTI_MAX_RESPONSE_BYTES)"
            )
        body = bytearray()
        for chunk in response.iter_raw():
            body += chunk
            if len(body) > limit:
                raise OutboundRefused(
                    f"{what}: {url} sent more than {limit} bytes; "
                    f"the tool reads at most {limit} (GYMGRADE_LTI_MAX_RESPONSE_BYTES)"
                )
        return bytes(body)

    def _too_slow(self, url: str, what: str) -> OutboundRefused:
        return OutboundRefused(
            f"{what}: {url} did not answer whole within {self.policy.total_seconds:g} s (GYMGRADE_LTI_REQUEST_SECONDS, the whole request's time)"  # noqa: E501
        )

    def get_json(self, url: str, *, what: str, headers: dict[str, str] | None = None) -> Any:
        """GET a JSON document that must answer 200 (raises PlatformUnreachable or OutboundRefused)."""
        answer = self.request(
            "GET", url, what=what, headers={"Accept": "application/json", **(headers or {})}
        )
        if answer.status != 200:
            raise PlatformUnreachable(
                f"{what}: {url} answered {answer.status}; expected 200 and a JSON document"
            )
        return answer.json(what)

    def close(self) -> None:
        """Close the connections."""
        self._client.close()


def host_of(url: str) -> str:
    """A URL's host name, lower case ('' when it has none)."""
    return (urlsplit(url).hostname or "").lower()


def origin_of(url: str) -> tuple[str, str, int | None]:
    """A URL's origin: (scheme, host, port), the port made explicit for http and https."""
    parts = urlsplit(url)
    try:
        port = parts.port
    except ValueError:
        return (parts.scheme.lower(), host_of(url), -1)
    default = {"https": 443, "http": 80}.get(parts.scheme.lower())
    return (parts.scheme.lower(), host_of(url), port if port is not None else default)


def host_allowed(host: str, patterns: Iterable[str]) -> bool:
    """Whether ``host`` is one of ``patterns`` (exact names, or ``*.example.edu`` for its subdomains)."""
    host = host.lower().rstrip(".")
    for pattern in patterns:
        pattern = pattern.lower().strip().rstrip(".")
        if pattern.startswith("*."):
            if host.endswith(pattern[1:]) and len(host) > len(pattern) - 1:
                return True
        elif pattern and host == pattern:
            return True
    return False


def on_hosts(url: str, origins: Iterable[str], allowed_hosts: Iterable[str]) -> bool:
    """Whether ``url`` has the origin of one of ``origins`` (URLs), or a host the operator allows."""
    if origin_of(url) in {origin_of(other) for other in origins}:
        return True
    return host_allowed(host_of(url), allowed_hosts)

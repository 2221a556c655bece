"""The tool's requests for platforms (api/lti/outbound.py) against real HTTP servers on loopback: which
addresses and schemes it refuses, that it connects to the address it checked, and that an answer is
bounded in bytes and in total time, never read whole before the check."""

from __future__ import annotations

import ipaddress
import socket
import threading
import time
from collections.abc import Iterator
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any

import pytest

from api.errors import OutboundRefused, PlatformUnreachable
from api.lti.outbound import Outbound, OutboundPolicy, host_allowed, on_hosts, refusal

LOOPBACK = (ipaddress.ip_network("127.0.0.0/8"),)
HANG_GUARD_SECONDS = 60.0
"""Only against a hang: a request that the policy does not end would run forever."""


class _Handler(BaseHTTPRequestHandler):
    stop = threading.Event()

    def log_message(self, format: str, *args: Any) -> None:
        """Quiet."""

    def do_GET(self) -> None:
        path = self.path.split("?")[0]
        if path == "/json":
            self._answer(200, b'{"keys": []}', length=True)
        elif path == "/announced-huge":
            self.send_response(200)
            self.send_header("Content-Length", str(50_000_000))
            self.end_headers()
            self.wfile.write(b"x" * 1000)
        elif path == "/endless":
            self.send_response(200)
            self.end_headers()
            self._stream(b"x" * 65536, pause=0.0)
        elif path == "/drip":
            self.send_response(200)
            self.end_headers()
            self._stream(b"x", pause=0.05)
        elif path == "/secret":
            self._answer(500, b"INTERNAL-ADMIN-PAGE token=hunter2", length=True)
        elif path == "/redirect":
            self.send_response(302)
            self.send_header("Location", "http://169.254.169.254/latest/meta-data/")
            self.send_header("Content-Length", "0")
            self.end_headers()
        elif path == "/paged":
            self.send_response(200)
            self.send_header("Link", '</paged?page=2>; rel="next"')
            self.send_header("Content-Length", "2")
            self.end_headers()
            self.wfile.write(b"{}")

    def _answer(self, status: int, body: bytes, *, length: bool) -> None:
        self.send_response(status)
        if length:
            self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def _stream(self, chunk: bytes, *, pause: float) -> None:
        try:
            while not self.stop.is_set():
                self.wfile.write(chunk)
                self.wfile.flush()
                if pause:
                    time.sleep(pause)
        except OSError:  # the tool hung up: what the test waits for
            return


@pytest.fixture(scope="module")
def server() -> Iterator[str]:
    """A plain HTTP server on 127.0.0.1; its base URL."""
    httpd = ThreadingHTTPServer(("127.0.0.1", 0), _Handler)
    httpd.daemon_threads = True
    thread = threading.Thread(target=httpd.serve_forever, args=(0.05,), daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{httpd.server_address[1]}"
    _Handler.stop.set()
    httpd.shutdown()


def _outbound(**changes: Any) -> Outbound:
    policy = {"allow_http": True, "allowed_networks": LOOPBACK, "max_bytes": 100_000, "total_seconds": 2.0}
    return Outbound(OutboundPolicy(**{**policy, **changes}))


def _within_guard(call: Any) -> BaseException | None:
    """Run ``call`` in a thread; the exception it raised (None: it returned), failing the test on a hang."""
    outcome: list[BaseException | None] = []

    def run() -> None:
        try:
            call()
            outcome.append(None)
        except BaseException as error:  # handed to the test
            outcome.append(error)

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    thread.join(HANG_GUARD_SECONDS)
    assert outcome, "the request never ended: the policy bounds neither its bytes nor its time"
    return outcome[0]


def test_an_allowed_network_is_reached(server: str) -> None:
    assert _outbound().get_json(server + "/json", what="reading") == {"keys": []}


@pytest.mark.parametrize("host", ["127.0.0.1", "localhost"], ids=["address", "name-resolving-to-loopback"])
def test_loopback_is_refused_unless_the_operator_allows_it(server: str, host: str) -> None:
    url = server.replace("127.0.0.1", host) + "/json"
    with pytest.raises(OutboundRefused, match=r"is a loopback address; the tool reaches only public"):
        _outbound(allowed_networks=()).get_json(url, what="reading")


@pytest.mark.parametrize(
    ("address", "kind"),
    [
        ("10.1.2.3", "private"),
        ("192.168.0.1", "private"),
        ("172.16.0.1", "private"),
        ("169.254.169.254", "link-local"),
        ("::1", "loopback"),
        ("fe80::1", "link-local"),
        ("::ffff:127.0.0.1", "loopback"),
        ("64:ff9b::a9fe:a9fe", "link-local"),
        ("2002:a00:1::1", "private"),
        ("0.0.0.0", "unspecified"),
        ("100.64.0.1", "not globally routable"),
        ("224.0.0.1", "multicast"),
    ],
)
def test_every_non_public_address_is_refused(address: str, kind: str) -> None:
    why = refusal(ipaddress.ip_address(address), OutboundPolicy())
    assert why is not None and f"is a {kind} address" in why
    assert refusal(ipaddress.ip_address("93.184.215.14"), OutboundPolicy()) is None
    assert refusal(ipaddress.ip_address("2606:4700:4700::1111"), OutboundPolicy()) is None
    assert (
        refusal(
            ipaddress.ip_address("10.1.2.3"),
            OutboundPolicy(allowed_networks=(ipaddress.ip_network("10.0.0.0/8"),)),
        )
        is None
    )


def test_plain_http_is_refused_unless_allowed(server: str) -> None:
    with pytest.raises(
        OutboundRefused, match=r"is not an https URL; the tool talks to platforms over https only"
    ):
        _outbound(allow_http=False).get_json(server + "/json", what="reading")
    with pytest.raises(OutboundRefused, match="is not an https URL"):
        _outbound(allow_http=False).get_json("file:///etc/passwd", what="reading")


def test_a_name_is_resolved_once_every_address_checked_and_the_checked_one_connected(
    server: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """DNS rebinding: the name answers loopback (allowed) when checked, the metadata address afterwards;
    the tool asks once and connects to what it checked. A name with one private address among public
    ones is refused."""
    port = int(server.rsplit(":", 1)[1])
    real = socket.getaddrinfo
    asked: list[str] = []

    def resolver(host: Any, *args: Any, **kwargs: Any) -> Any:
        if host == "rebind.test":
            asked.append(host)
            address = "127.0.0.1" if len(asked) == 1 else "169.254.169.254"
            return [(socket.AF_INET, socket.SOCK_STREAM, 6, "", (address, port))]
        if host == "mixed.test":
            return [
                (socket.AF_INET, socket.SOCK_STREAM, 6, "", ("127.0.0.1", port)),
                (socket.AF_INET, socket.SOCK_STREAM, 6, "", ("10.9.9.9", port)),
            ]
        return real(host, *args, **kwargs)

    monkeypatch.setattr(socket, "getaddrinfo", resolver)
    assert _outbound().get_json(f"http://rebind.test:{port}/json", what="reading") == {"keys": []}
    assert asked == ["rebind.test"]
    with pytest.raises(OutboundRefused, match=r"'mixed.test': 10.9.9.9 is a private address"):
        _outbound().get_json(f"http://mixed.test:{port}/json", what="reading")


def test_an_answer_announcing_too_many_bytes_is_refused_before_reading(server: str) -> None:
    with pytest.raises(OutboundRefused, match=r"announced 50000000 bytes; the tool reads at most 100000"):
        _outbound().get_json(server + "/announced-huge", what="reading")


def test_an_endless_answer_is_cut_past_the_limit(server: str) -> None:
    error = _within_guard(
        lambda: _outbound().get_json(server + "/endless", what="reading the platform's keys")
    )
    assert isinstance(error, OutboundRefused), error
    assert "reading the platform's keys: " in str(error) and "sent more than 100000 bytes" in str(error)


@pytest.mark.slow
def test_a_slow_drip_is_cut_at_the_total_time_not_per_read(server: str) -> None:
    """Each byte comes well within any per-read timeout; only a total time ends the request."""
    error = _within_guard(lambda: _outbound(total_seconds=0.5).get_json(server + "/drip", what="reading"))
    assert isinstance(error, OutboundRefused), error
    assert "did not answer whole within 0.5 s (GYMGRADE_LTI_REQUEST_SECONDS" in str(error)


def test_a_refusal_never_shows_the_answers_body_and_a_redirect_is_not_followed(server: str) -> None:
    outbound = _outbound()
    with pytest.raises(PlatformUnreachable) as refused:
        outbound.get_json(server + "/secret", what="reading")
    assert "answered 500" in str(refused.value) and "INTERNAL" not in str(refused.value)
    assert "hunter2" not in str(refused.value)
    moved = outbound.request("GET", server + "/redirect", what="reading")
    assert moved.status == 302 and moved.body == b""


def test_a_next_link_is_made_absolute(server: str) -> None:
    answer = _outbound().request("GET", server + "/paged", what="reading")
    assert answer.next_url == server + "/paged?page=2"


@pytest.mark.parametrize(
    ("url", "expected"),
    [
        ("https://lms.example.edu/api/lineitems/1", True),
        ("https://lms.example.edu:443/x", True),
        ("https://lms.example.edu:8443/x", False),
        ("http://lms.example.edu/x", False),
        ("https://lms.example.edu.evil.tld/x", False),
        ("https://evil.tld/?https://lms.example.edu", False),
        ("https://school.instructure.com/api/lti/courses/1/line_items", True),
        ("https://instructure.com.evil.tld/", False),
        ("https://evilinstructure.com/", False),
    ],
)
def test_service_urls_are_on_the_platforms_origins_or_hosts_the_operator_allows(
    url: str, expected: bool
) -> None:
    assert on_hosts(url, ["https://lms.example.edu"], ["*.instructure.com"]) is expected


def test_host_patterns() -> None:
    assert host_allowed("a.b.example.edu", ["*.example.edu"])
    assert not host_allowed("example.edu", ["*.example.edu"])
    assert host_allowed("sso.canvaslms.com", ["sso.canvaslms.com"])
    assert not host_allowed("sso.canvaslms.com.evil.tld", ["sso.canvaslms.com"])

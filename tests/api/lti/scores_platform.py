"""A platform's Assignment and Grade Services alone, on loopback, for the publisher's tests: it grants access
tokens, lists and makes line items and takes scores, counting each; a score request waits at a barrier of
``together`` requests, so a publisher sending fewer at once stalls (refused after ``wait_seconds``) and one
sending more is seen (``most_in_flight``)."""

from __future__ import annotations

import json
import threading
from collections import Counter
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any


@dataclass
class ScoresPlatform:
    """What the platform was asked; ``url`` once running."""

    together: int = 1
    wait_seconds: float = 10.0
    url: str = ""
    tokens_granted: int = 0
    line_items_made: int = 0
    scores: list[dict[str, Any]] = field(default_factory=list)
    most_in_flight: int = 0
    _in_flight: int = 0
    _lock: threading.Lock = field(default_factory=threading.Lock)
    _barrier: threading.Barrier | None = None

    def one_at_a_time(self) -> None:
        """Answer each score request alone from now on (no barrier)."""
        with self._lock:
            self._barrier = None

    def sends_by_user(self) -> Counter[str]:
        """How many scores each user was sent."""
        with self._lock:
            return Counter(str(score["userId"]) for score in self.scores)

    def _score(self, body: dict[str, Any]) -> int:
        with self._lock:
            self._in_flight += 1
            self.most_in_flight = max(self.most_in_flight, self._in_flight)
            barrier = self._barrier
        try:
            if barrier is not None:
                barrier.wait(self.wait_seconds)
        except threading.BrokenBarrierError:
            return 503
        finally:
            with self._lock:
                self._in_flight -= 1
        with self._lock:
            self.scores.append(body)
        return 200

    def _answer(self, method: str, path: str, body: dict[str, Any]) -> tuple[int, Any]:
        if method == "POST" and path == "/token":
            with self._lock:
                self.tokens_granted += 1
            return 200, {"access_token": "granted", "token_type": "bearer", "expires_in": 3600}
        if method == "GET" and path.startswith("/lineitems?"):
            return 200, []
        if method == "POST" and path == "/lineitems":
            with self._lock:
                self.line_items_made += 1
                made = self.line_items_made
            return 201, {**body, "id": f"{self.url}/lineitems/{made}"}
        if method == "POST" and path.endswith("/scores"):
            return self._score(body), {}
        return 404, {}

    @contextmanager
    def running(self) -> Iterator[ScoresPlatform]:
        """Serve on a loopback port until the block ends."""
        platform = self
        self._barrier = threading.Barrier(self.together) if self.together > 1 else None

        class Handler(BaseHTTPRequestHandler):
            def _handle(self, method: str) -> None:
                length = int(self.headers.get("Content-Length") or 0)
                raw = self.rfile.read(length) if length else b""
                try:
                    body = json.loads(raw) if raw.startswith(b"{") else {}
                except ValueError:
                    body = {}
                status, answer = platform._answer(method, self.path, body)
                data = json.dumps(answer).encode()
                self.send_response(status)
                self.send_header("Content-Type", "application/json")
                self.send_header("Content-Length", str(len(data)))
                self.end_headers()
                self.wfile.write(data)

            def do_GET(self) -> None:  # http.server's naming
                self._handle("GET")

            def do_POST(self) -> None:
                self._handle("POST")

            def log_message(self, *_args: Any) -> None:
                pass

        server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        server.daemon_threads = True
        self.url = f"http://127.0.0.1:{server.server_address[1]}"
        thread = threading.Thread(target=server.serve_forever, daemon=True)
        thread.start()
        try:
            yield self
        finally:
            if self._barrier is not None:
                self._barrier.abort()
            server.shutdown()
            server.server_close()

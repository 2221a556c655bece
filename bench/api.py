"""Service figures: GET latency under grading load, uploads accepted per second, upload-to-report time.

Starts `gymgrade serve` on loopback ports with the real grader in temporary data directories and prints
the `## API` section of bench/RESULTS.md. Usage: ``python bench/api.py [--clients 50] [--seconds 30]``.
"""

from __future__ import annotations

import argparse
import asyncio
import os
import secrets
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import httpx

ROOT = Path(__file__).resolve().parents[1]
SAMPLE_SOLUTION = ROOT / "submissions" / "classic_complete.py"
INSTRUCTOR_TOKEN = "bench-" + secrets.token_urlsafe(24)
START_TIMEOUT_SECONDS = 60.0
GRADING_TIMEOUT_SECONDS = 1800.0
UPLOAD_CONTENT = b"def random_blackjack(n):\n    return 0.4\n"


@dataclass
class Server:
    """A `gymgrade serve` process."""

    process: subprocess.Popen[bytes]
    url: str
    data_dir: Path

    def stop(self) -> None:
        """Stop the server (SIGTERM, then SIGKILL of its process group)."""
        self.process.terminate()
        try:
            self.process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            os.killpg(self.process.pid, signal.SIGKILL)
            self.process.wait()


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port: int = probe.getsockname()[1]
        return port


def start_server(workers: int, log: Path) -> Server:
    """Start `gymgrade serve` with ``workers`` gradings at once and wait for /healthz."""
    data_dir = Path(tempfile.mkdtemp(prefix="gymgrade-bench-"))
    port = _free_port()
    env = {name: value for name, value in os.environ.items() if not name.startswith("GYMGRADE_")}
    env.update(
        {
            "GYMGRADE_DATA_DIR": str(data_dir),
            "GYMGRADE_INSTRUCTOR_TOKEN": INSTRUCTOR_TOKEN,
            "GYMGRADE_WORKERS": str(workers),
            "GYMGRADE_RATE_LIMIT_PER_MINUTE": "100000",
            "GYMGRADE_POLL_SECONDS": "0.2",
        }
    )
    gymgrade = str(Path(sys.executable).with_name("gymgrade"))
    with log.open("ab") as output:
        process = subprocess.Popen(
            [gymgrade, "serve", "--host", "127.0.0.1", "--port", str(port)],
            env=env,
            stdout=output,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
    server = Server(process, f"http://127.0.0.1:{port}", data_dir)
    deadline = time.monotonic() + START_TIMEOUT_SECONDS
    while time.monotonic() < deadline:
        if process.poll() is not None:
            raise RuntimeError(f"gymgrade serve exited with {process.returncode}; see {log}")
        try:
            if httpx.get(server.url + "/healthz", timeout=1).status_code == 200:
                return server
        except httpx.HTTPError:
            time.sleep(0.1)
    server.stop()
    raise RuntimeError(f"gymgrade serve did not answer within {START_TIMEOUT_SECONDS} s; see {log}")


def create_student(url: str, name: str) -> str:
    """Create a student and return the token."""
    response = httpx.post(
        url + "/students", json={"name": name}, headers={"Authorization": f"Bearer {INSTRUCTOR_TOKEN}"}
    )
    response.raise_for_status()
    token: str = response.json()["token"]
    return token


def upload(url: str, token: str, content: bytes) -> int:
    """Upload a file and return its submission id."""
    response = httpx.post(
        url + "/submissions",
        files={"file": ("opengym.py", content)},
        headers={"Authorization": f"Bearer {token}"},
    )
    response.raise_for_status()
    submission_id: int = response.json()["id"]
    return submission_id


def status(url: str, token: str, submission_id: int) -> dict[str, object]:
    """The submission's JSON view."""
    view: dict[str, object] = httpx.get(
        f"{url}/submissions/{submission_id}", headers={"Authorization": f"Bearer {token}"}, timeout=30
    ).json()
    return view


def wait_for(url: str, token: str, submission_id: int, statuses: set[str]) -> dict[str, object]:
    """Poll until the submission reaches one of ``statuses``."""
    deadline = time.monotonic() + GRADING_TIMEOUT_SECONDS
    while time.monotonic() < deadline:
        view = status(url, token, submission_id)
        if view["status"] in statuses:
            return view
        time.sleep(0.2)
    raise RuntimeError(f"submission {submission_id} did not reach {statuses} in {GRADING_TIMEOUT_SECONDS} s")


def _server_cpu_seconds(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


async def _hammer(
    url: str, token: str, submission_id: int, clients: int, seconds: float, interval: float
) -> list[float]:
    """``clients`` concurrent clients GET one submission for ``seconds``; each waits ``interval`` between
    its requests (0: back to back), starting at evenly spread offsets."""
    latencies: list[float] = []
    stop_at = time.monotonic() + seconds
    limits = httpx.Limits(max_connections=clients, max_keepalive_connections=clients)
    async with httpx.AsyncClient(
        base_url=url, limits=limits, timeout=60, headers={"Authorization": f"Bearer {token}"}
    ) as client:

        async def one_client(offset: float) -> None:
            await asyncio.sleep(offset)
            while time.monotonic() < stop_at:
                started = time.perf_counter()
                response = await client.get(f"/submissions/{submission_id}")
                elapsed = time.perf_counter() - started
                latencies.append(elapsed)
                response.raise_for_status()
                if interval:
                    await asyncio.sleep(max(0.0, interval - elapsed))

        await asyncio.gather(*(one_client(interval * index / clients) for index in range(clients)))
    return latencies


@dataclass(frozen=True)
class Latency:
    """Latency figures of one load phase."""

    requests: int
    p50_ms: float
    p99_ms: float
    max_ms: float
    per_second: float
    server_cpu_ms: float
    gradings_after: str


def measure(
    server: Server,
    token: str,
    submission_id: int,
    clients: int,
    seconds: float,
    interval: float,
    graded: list[int],
) -> Latency:
    """Run one load phase and summarise it."""
    cpu_before = _server_cpu_seconds(server.process.pid)
    latencies = sorted(asyncio.run(_hammer(server.url, token, submission_id, clients, seconds, interval)))
    cpu = _server_cpu_seconds(server.process.pid) - cpu_before
    return Latency(
        requests=len(latencies),
        p50_ms=1000 * statistics.median(latencies),
        p99_ms=1000 * latencies[min(len(latencies) - 1, int(0.99 * len(latencies)))],
        max_ms=1000 * latencies[-1],
        per_second=len(latencies) / seconds,
        server_cpu_ms=1000 * cpu / len(latencies),
        gradings_after=", ".join(str(status(server.url, token, i)["status"]) for i in graded) or "none",
    )


def latency_phases(clients: int, seconds: float, log: Path) -> dict[str, Latency]:
    """GET /submissions/{id} latency: idle, then while two gradings of the sample solution run."""
    server = start_server(workers=2, log=log)
    try:
        token = create_student(server.url, "bench")
        probe = upload(server.url, token, UPLOAD_CONTENT)
        wait_for(server.url, token, probe, {"done", "failed"})
        phases = {"idle, back to back": measure(server, token, probe, clients, seconds, 0.0, [])}
        content = SAMPLE_SOLUTION.read_bytes()
        graded = [upload(server.url, token, content) for _ in range(2)]
        for submission_id in graded:
            wait_for(server.url, token, submission_id, {"running"})
        phases["2 gradings, each client polling once a second"] = measure(
            server, token, graded[0], clients, seconds, 1.0, graded
        )
        phases["2 gradings, back to back"] = measure(server, token, graded[0], clients, seconds, 0.0, graded)
        return phases
    finally:
        server.stop()


def uploads_per_second(count: int, concurrency: int, log: Path) -> float:
    """Uploads accepted (202) per second by a server with no grading workers, from concurrent clients."""
    server = start_server(workers=0, log=log)
    try:
        tokens = [create_student(server.url, f"student-{index}") for index in range(concurrency)]

        async def run() -> float:
            async with httpx.AsyncClient(base_url=server.url, timeout=30) as client:

                async def uploader(token: str, n: int) -> None:
                    for _ in range(n):
                        response = await client.post(
                            "/submissions",
                            files={"file": ("opengym.py", UPLOAD_CONTENT)},
                            headers={"Authorization": f"Bearer {token}"},
                        )
                        if response.status_code != 202:
                            raise RuntimeError(f"upload refused: {response.status_code} {response.text}")

                started = time.perf_counter()
                await asyncio.gather(*(uploader(token, count // concurrency) for token in tokens))
                return (count // concurrency) * concurrency / (time.perf_counter() - started)

        return asyncio.run(run())
    finally:
        server.stop()


def upload_to_report(log: Path) -> tuple[float, float, float]:
    """Seconds from uploading the sample solution to its report on an idle one-worker server."""
    server = start_server(workers=1, log=log)
    try:
        token = create_student(server.url, "bench")
        started = time.perf_counter()
        submission_id = upload(server.url, token, SAMPLE_SOLUTION.read_bytes())
        view = wait_for(server.url, token, submission_id, {"done", "failed"})
        elapsed = time.perf_counter() - started
        report = view.get("report")
        if view["status"] != "done" or not isinstance(report, dict):
            raise RuntimeError(f"the sample solution was not graded: {view.get('error')}")
        return elapsed, float(report["execution_time"]), float(report["score"])
    finally:
        server.stop()


def main() -> int:
    """Measure and print the `## API` section."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--clients", type=int, default=50)
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--uploads", type=int, default=500)
    parser.add_argument("--log", type=Path, default=Path(tempfile.gettempdir()) / "gymgrade-bench-api.log")
    args = parser.parse_args()
    load_before = os.getloadavg()[0]
    phases = latency_phases(args.clients, args.seconds, args.log)
    print(f"latency: {phases}", file=sys.stderr)
    accepted = uploads_per_second(args.uploads, 10, args.log)
    print(f"uploads/s: {accepted:.1f}", file=sys.stderr)
    elapsed, execution_time, score = upload_to_report(args.log)
    print(f"upload to report: {elapsed:.1f} s", file=sys.stderr)
    rows = "\n".join(
        f"| {name} | {p.p50_ms:.1f} ms | {p.p99_ms:.1f} ms | {p.max_ms:.0f} ms "
        f"| {p.requests} ({p.per_second:.0f}/s) | {p.server_cpu_ms:.2f} ms | {p.gradings_after} |"
        for name, p in phases.items()
    )
    print(f"""## API

`python bench/api.py --clients {args.clients} --seconds {args.seconds:g} --uploads {args.uploads}`:
real grader, `gymgrade serve` on loopback (uvicorn with httptools and uvloop), SQLite in WAL mode,
{os.cpu_count()} cores, 1-minute load average {load_before:.1f} when started, {time.strftime("%Y-%m-%d")}.

GET /submissions/{{id}} from {args.clients} concurrent clients for {args.seconds:g} s per phase; the gradings
are two of `submissions/classic_complete.py` at once (GYMGRADE_WORKERS=2, grading processes niced by 10).
Target: p99 under 100 ms while 2 gradings run.

| phase | p50 | p99 | max | requests | server CPU per request | gradings after the phase |
|-------|-----|-----|-----|----------|------------------------|--------------------------|
{rows}

| figure | measured |
|--------|----------|
| uploads accepted (202), 10 concurrent students, no grading | {accepted:.0f} per second |
| upload to report, `submissions/classic_complete.py`, idle server (GYMGRADE_WORKERS=1) | \
{elapsed:.1f} s (the grader's own execution_time {execution_time:.1f} s; score {score:g}) |
""")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Scale-out figures (issue 9): throughput and latency of Celery workers, recovery after a SIGKILL.

Starts a throw-away redis-server, `gymgrade serve` with GYMGRADE_BROKER_URL (SQLite) and `gymgrade worker`
processes with the real grader, then for each split of this machine's cores (processes x gradings at once x
xdist workers per grading) uploads a burst of cheap submissions and measures the time from upload to
report; then kills a worker mid-grading and times the job finishing on the other. Prints the
`## Scale-out (issue 9)` section of bench/RESULTS.md.

Usage: ``python bench/scaleout.py [--burst 50] [--full-cpu]`` (needs redis-server and full isolation).
"""

from __future__ import annotations

import argparse
import ctypes
import importlib.util
import os
import resource
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

import httpx

ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("bench_api", Path(__file__).with_name("api.py"))
if _spec is None or _spec.loader is None:
    raise ImportError("bench/api.py is missing")
bench_api = importlib.util.module_from_spec(_spec)
sys.modules["bench_api"] = bench_api
_spec.loader.exec_module(bench_api)  # the service helpers of bench/api.py (not the `api` package)
INSTRUCTOR_TOKEN: str = bench_api.INSTRUCTOR_TOKEN
START_TIMEOUT_SECONDS: float = bench_api.START_TIMEOUT_SECONDS
_free_port = bench_api._free_port
create_student = bench_api.create_student
upload = bench_api.upload
wait_for = bench_api.wait_for
CHEAP = b"def random_blackjack(n):\n    return 0.4\n"
"""A real grading that runs every check's sandbox start-up but little student code (one call fails)."""
FULL = ROOT / "submissions" / "classic_complete.py"
GYMGRADE = str(Path(sys.executable).with_name("gymgrade"))
_PR_SET_CHILD_SUBREAPER = 36


@dataclass(frozen=True)
class Split:
    """How the cores are used: worker processes, gradings at once in each, xdist workers per grading."""

    processes: int
    gradings: int
    xdist: int

    def __str__(self) -> str:
        return f"{self.processes} process(es) x {self.gradings} grading(s) x {self.xdist} xdist"


class Cluster:
    """redis-server, `gymgrade serve` and workers in one temporary directory."""

    def __init__(self, lease_seconds: float = 60.0, reconcile_seconds: float = 30.0) -> None:
        self.directory = Path(tempfile.mkdtemp(prefix="gymgrade-scaleout-"))
        self.redis_port = _free_port()
        redis_command = ["redis-server", "--port", str(self.redis_port), "--bind", "127.0.0.1", "--save", ""]
        redis_command += ["--dir", str(self.directory)]
        self.redis = subprocess.Popen(redis_command, stdout=subprocess.DEVNULL)
        self.env = {name: value for name, value in os.environ.items() if not name.startswith("GYMGRADE_")}
        self.env.update(
            {
                "GYMGRADE_DATA_DIR": str(self.directory / "data"),
                "GYMGRADE_INSTRUCTOR_TOKEN": INSTRUCTOR_TOKEN,
                "GYMGRADE_BROKER_URL": f"redis://127.0.0.1:{self.redis_port}/0",
                "GYMGRADE_RATE_LIMIT_PER_MINUTE": "100000",
                "GYMGRADE_LEASE_SECONDS": str(lease_seconds),
                "GYMGRADE_RECONCILE_SECONDS": str(reconcile_seconds),
            }
        )
        self.port = _free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        self.server = self._start(["serve", "--host", "127.0.0.1", "--port", str(self.port)], "serve")
        self.workers: list[subprocess.Popen[bytes]] = []
        deadline = time.monotonic() + START_TIMEOUT_SECONDS
        while True:
            try:
                if httpx.get(self.url + "/healthz", timeout=1).status_code == 200:
                    break
            except httpx.HTTPError:
                pass
            if time.monotonic() > deadline:
                raise RuntimeError(f"gymgrade serve did not start; see {self.directory}/serve.log")
            time.sleep(0.1)

    def _start(self, arguments: list[str], name: str, **extra: str) -> subprocess.Popen[bytes]:
        with (self.directory / f"{name}.log").open("ab") as log:
            return subprocess.Popen(
                [GYMGRADE, *arguments],
                env={**self.env, **extra},
                stdout=log,
                stderr=subprocess.STDOUT,
                start_new_session=True,
            )

    def start_workers(self, split: Split) -> None:
        """Start ``split.processes`` workers and wait until each says it is ready."""
        for index in range(split.processes):
            name = f"worker-{len(self.workers)}"
            worker = self._start(
                ["worker", "--workers", str(split.gradings)], name, GYMGRADE_GRADING_WORKERS=str(split.xdist)
            )
            self.workers.append(worker)
            deadline = time.monotonic() + START_TIMEOUT_SECONDS
            while " ready." not in (self.directory / f"{name}.log").read_text(errors="replace"):
                if worker.poll() is not None or time.monotonic() > deadline:
                    raise RuntimeError(f"worker {index} did not start; see {self.directory}/{name}.log")
                time.sleep(0.1)

    def stop_workers(self) -> None:
        """Stop every worker (SIGTERM, then the whole process group)."""
        for worker in self.workers:
            worker.terminate()
        for worker in self.workers:
            try:
                worker.wait(timeout=60)
            except subprocess.TimeoutExpired:
                os.killpg(worker.pid, signal.SIGKILL)
                worker.wait()
        self.workers = []

    def close(self) -> None:
        """Stop everything and delete the directory."""
        self.stop_workers()
        self.server.terminate()
        self.server.wait(timeout=60)
        self.redis.kill()
        self.redis.wait()
        shutil.rmtree(self.directory, ignore_errors=True)


def become_subreaper() -> None:
    """Adopt every orphaned descendant (xdist workers of a SIGKILLed pytest, sandboxes), so that their CPU
    time is counted when they are reaped (Linux prctl PR_SET_CHILD_SUBREAPER)."""
    libc = ctypes.CDLL(None, use_errno=True)
    if libc.prctl(_PR_SET_CHILD_SUBREAPER, 1) != 0:
        raise OSError(ctypes.get_errno(), "prctl(PR_SET_CHILD_SUBREAPER) failed")


def _reaped_cpu_seconds() -> float:
    """CPU of every descendant that ended, after reaping the orphans adopted so far."""
    deadline = time.monotonic() + 5.0
    while time.monotonic() < deadline:
        try:
            pid, _ = os.waitpid(-1, os.WNOHANG)
        except ChildProcessError:
            break
        if pid == 0:
            time.sleep(0.1)
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _seconds(view: dict[str, object], field: str) -> float:
    return datetime.fromisoformat(str(view[field])).timestamp()


def burst(cluster: Cluster, split: Split, count: int) -> dict[str, float]:
    """Upload ``count`` cheap files at once; throughput, latency percentiles and CPU per grading."""
    cpu_before = _reaped_cpu_seconds()
    cluster.start_workers(split)
    token = create_student(cluster.url, f"burst-{time.monotonic_ns()}")
    ids = [upload(cluster.url, token, CHEAP + f"# {index}\n".encode()) for index in range(count)]
    views = [wait_for(cluster.url, token, submission_id, {"done", "failed"}) for submission_id in ids]
    cluster.stop_workers()
    cpu = _reaped_cpu_seconds() - cpu_before
    if any(view["status"] != "done" for view in views):
        raise RuntimeError(f"not every grading succeeded: {[view['error'] for view in views]}")
    latencies = sorted(_seconds(view, "finished_at") - _seconds(view, "created_at") for view in views)
    first = min(_seconds(view, "created_at") for view in views)
    span = max(_seconds(view, "finished_at") for view in views) - first
    return {
        "per_minute": 60 * count / span,
        "p50": statistics.median(latencies),
        "p95": latencies[min(int(0.95 * count), count - 1)],
        "cpu": cpu / count,
    }


def kill_recovery(lease_seconds: float, reconcile_seconds: float) -> float:
    """Seconds from SIGKILL of the worker grading a file to that file's report, on the other worker."""
    cluster = Cluster(lease_seconds=lease_seconds, reconcile_seconds=reconcile_seconds)
    try:
        cluster.start_workers(Split(2, 1, 1))
        token = create_student(cluster.url, "victim")
        submission_id = upload(cluster.url, token, CHEAP)
        wait_for(cluster.url, token, submission_id, {"running"})
        time.sleep(1.0)  # mid-grading
        owner = _lease_owner_pid(cluster, submission_id)
        victim = next(worker for worker in cluster.workers if worker.pid == owner)
        killed = time.time()
        os.kill(victim.pid, signal.SIGKILL)
        victim.wait()
        view = wait_for(cluster.url, token, submission_id, {"done", "failed"})
        if view["status"] != "done" or view["attempts"] != 2:
            raise RuntimeError(f"the killed job ended {view['status']} after {view['attempts']} attempts")
        return _seconds(view, "finished_at") - killed
    finally:
        cluster.close()


def _lease_owner_pid(cluster: Cluster, submission_id: int) -> int:
    import sqlite3

    database = sqlite3.connect(cluster.directory / "data" / "gymgrade.sqlite3")
    try:
        query = "SELECT lease_owner FROM submissions WHERE id = ?"
        (owner,) = database.execute(query, (submission_id,)).fetchone()
    finally:
        database.close()
    return int(str(owner).split(":")[1])


def full_grading_cpu() -> tuple[float, float]:
    """CPU seconds and wall seconds of one full grading of the lab solution (`gymgrade check`)."""
    before = _reaped_cpu_seconds()
    started = time.perf_counter()
    subprocess.run([GYMGRADE, "check", str(FULL), "--json"], capture_output=True, check=False)
    wall = time.perf_counter() - started
    return _reaped_cpu_seconds() - before, wall


def main() -> None:
    """Measure and print the section."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--burst", type=int, default=50)
    parser.add_argument("--full-cpu", action="store_true", help="also time one full grading (projection)")
    args = parser.parse_args()
    become_subreaper()
    cores = len(os.sched_getaffinity(0))
    splits = [Split(1, 1, 1), Split(1, 1, cores), Split(1, cores, 1), Split(cores, 1, 1)]
    results = {}
    cluster = Cluster()
    try:
        for split in splits:
            results[split] = burst(cluster, split, args.burst)
            print(f"{split}: {results[split]}", file=sys.stderr, flush=True)
    finally:
        cluster.close()
    recovery = kill_recovery(lease_seconds=10.0, reconcile_seconds=5.0)
    print(f"kill recovery: {recovery:.1f} s", file=sys.stderr, flush=True)
    load = os.getloadavg()[0]
    when = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    print(
        f"Measured by `python bench/scaleout.py --burst {args.burst}` on {when}, {cores} cores, "
        f"load average {load:.1f} at the end.\n"
    )
    print("| split | throughput (gradings/min) | latency p50 | latency p95 | CPU per grading |")
    print("|---|---|---|---|---|")
    for split, figures in results.items():
        print(
            f"| {split} | {figures['per_minute']:.1f} | {figures['p50']:.1f} s | {figures['p95']:.1f} s "
            f"| {figures['cpu']:.1f} s |"
        )
    one, two = results[splits[0]]["per_minute"], results[splits[3]]["per_minute"]
    print(f"\nRatio {cores} worker processes / 1 (one grading each, no xdist): {two / one:.2f}x.")
    print(
        "SIGKILL of the worker mid-grading to the report from the other worker "
        f"(lease 10 s, reconcile 5 s): {recovery:.1f} s."
    )
    if args.full_cpu:
        cpu, wall = full_grading_cpu()
        print(f"\nOne full grading of classic_complete.py: {cpu:.0f} s CPU, {wall:.0f} s wall.")


if __name__ == "__main__":
    main()

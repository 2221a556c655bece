"""Figures of issue 25: a class of K submissions graded by `gymgrade grade` against the machine's limit.

    python bench/class_throughput.py [--submissions K] [--editions classic,gym026,volume2,rl1]
                                     [--workers N] [--seed 0] [--write]

1. Builds a class of K submissions: the lab-literal solution of each edition (`EDITIONS` below), handed
   out round-robin, every copy with different bytes (a header comment naming the student, blank lines
   doubled or not, trailing blank lines), so no two files hash alike and no report is reused.
2. Grades the class with `gymgrade grade` (full isolation, `--workers N`, one run per edition since a
   batch grades one edition), timing the wall and the CPU of every process of the run (the grader, its
   xdist workers, the sandbox children: a cgroup v1 `cpuacct` group the run starts in, else
   `RUSAGE_CHILDREN` with this process as their subreaper, which misses children killed with their
   parents). `bench/class_calls.py`, loaded in every process of the run through a `sitecustomize` module on
   its PYTHONPATH, logs every call the grader makes.
3. Runs one file's logged calls of each edition plainly and serially in a fresh process (as
   `bench/speed.py` does: `grader.compat.activate()`, import, the same calls with the same arguments; no
   sandbox, no recording, no replay): the plain serial CPU per submission of that edition; then once more
   on the sandbox child's envs (`grader/sandbox/child/envs.py`), which separates the grader's own work
   from what the child's cheaper Taxi and Blackjack give back.
4. Prints the ratio of the class's wall time to the bound K x (plain serial CPU per submission) / cores
   (goal <= 1.1), the grading CPU per submission against the plain one, the machine's load average
   sampled during the run, and the projection for 300 submissions on 2 cores and on 4 cores with Celery.

The 300-submission projection: the drain time of a busy machine is K x (grading CPU per submission) /
cores, so 300 x the measured CPU per submission (this mix of editions) / 2 for one 2-core machine, and / 4
plus one grading's skew for two such machines running `gymgrade worker` (one grading per core); the
section states the assumptions. `--write` replaces the `## Class throughput` section of bench/RESULTS.md.
With the default K = 4 (one file per edition) the grading takes about 5 minutes on an idle 2-core machine
(about 370 s of CPU, and each edition's run waits for its Taxi check), the plain runs about 3 more.
"""

from __future__ import annotations

import argparse
import contextlib
import ctypes
import json
import os
import pickle
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BENCH = Path(__file__).resolve().parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(BENCH))

from class_calls import LOG_VARIABLE, read_calls  # noqa: E402
from cpu_group import CpuGroup  # noqa: E402
from results_section import replace_section  # noqa: E402
from speed import plain_command  # noqa: E402

HEADING = "## Class throughput"
EDITIONS = {
    "classic": ROOT / "submissions" / "classic_complete.py",
    "gym026": ROOT / "submissions" / "gym026_complete.py",
    "volume2": ROOT / "submissions" / "gymnasium_complete.py",
    "rl1": ROOT / "submissions" / "editions" / "rl1_complete.py",
}
"""Each edition's lab-literal solution (every problem passes with the edition's default configuration)."""
PROJECTED_CLASS = 300
CHUNK_SUBMISSIONS = 24  # grader.grading.batch.CHUNK_SUBMISSIONS, repeated to keep this module importable
# alone
_PR_SET_CHILD_SUBREAPER = 36
_CLI = "import sys; from grader.cli import main; sys.exit(main(sys.argv[1:]))"


def varied(source: str, index: int) -> str:
    """The same program with different bytes: a header comment, blank lines doubled or not, a tail."""
    body = source.replace("\n\n\ndef ", "\n\n\n\ndef ") if index % 2 else source
    return f"# student {index:04d} (class throughput bench)\n" + body + "\n" * (index % 3)


@dataclass
class EditionRun:
    """One `gymgrade grade` run of the class's files of one edition."""

    edition: str
    files: int
    wall: float
    cpu: float
    statuses: Counter[str]
    plain_cpu: float = 0.0
    plain_wall: float = 0.0
    same_envs_cpu: float = 0.0
    """The plain run's CPU with the sandbox child's envs (`speed.py --plain-child-envs`)."""
    calls: int = 0
    log: Path | None = None
    logged_file: str = ""


@dataclass
class LoadSampler:
    """The 1-minute load average, sampled every few seconds on a thread while a run lasts."""

    period: float = 5.0
    samples: list[float] = field(default_factory=list)
    _stop: threading.Event = field(default_factory=threading.Event)

    def __enter__(self) -> LoadSampler:
        self.samples.append(os.getloadavg()[0])
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()
        return self

    def __exit__(self, *_: object) -> None:
        self._stop.set()
        self._thread.join()
        self.samples.append(os.getloadavg()[0])

    def _run(self) -> None:
        while not self._stop.wait(self.period):
            self.samples.append(os.getloadavg()[0])

    def summary(self) -> str:
        """Min, median and max of the samples."""
        values = self.samples
        return (
            f"1-minute load average {min(values):.1f} / {statistics.median(values):.1f} / {max(values):.1f} "
            f"(min / median / max of {len(values)} samples)"
        )


def children_cpu() -> float:
    """User + system CPU of every waited-for descendant so far."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def reap_orphans() -> None:
    """Wait for the descendants this subreaper adopted (xdist workers the grader killed, their children), so
    their CPU enters `RUSAGE_CHILDREN`; a live one is waited for (the run is over, it is ending)."""
    while True:
        try:
            pid, _ = os.waitpid(-1, 0)
        except ChildProcessError:
            return
        if pid == 0:
            return


def grade_edition(
    edition: str, folder: Path, out: Path, log: Path, workers: int, seed: int
) -> tuple[float, float, Counter[str]]:
    """`gymgrade grade` of one edition's files: wall, CPU of all its processes, statuses of the problems."""
    environment = dict(os.environ)
    hook = log / "site"  # the session drops PYTEST_PLUGINS; every process imports sitecustomize
    hook.mkdir()
    (hook / "sitecustomize.py").write_text("import class_calls  # noqa: F401\n", encoding="utf-8")
    environment["PYTHONPATH"] = os.pathsep.join(
        filter(None, [str(hook), str(ROOT), str(BENCH), environment.get("PYTHONPATH")])
    )
    environment[LOG_VARIABLE] = str(log)
    command = [sys.executable, "-c", _CLI, "grade", str(folder), "--out", str(out)]
    command += ["--edition", edition, "--seed", str(seed), "--workers", str(workers)]
    group = CpuGroup(edition)
    cpu_before, started = children_cpu(), time.perf_counter()
    done = subprocess.run(
        command, capture_output=True, text=True, env=environment, check=False, preexec_fn=group.join
    )
    wall = time.perf_counter() - started
    reap_orphans()
    grouped = group.seconds()
    cpu = grouped if grouped is not None else children_cpu() - cpu_before
    group.remove()
    if done.returncode not in (0, 1):
        raise SystemExit(f"gymgrade grade failed (exit {done.returncode}): {done.stderr[-3000:]}")
    statuses: Counter[str] = Counter()
    for report_path in sorted(out.glob("*.json")):
        with contextlib.suppress(ValueError, KeyError):
            report = json.loads(report_path.read_text(encoding="utf-8"))
            statuses.update(problem["status"] for problem in report["problems"])
    return wall, cpu, statuses


def plain_cpu(submission: Path, calls_file: Path, *, child_envs: bool = False) -> tuple[float, float]:
    """CPU (import + calls) and wall of the logged calls run plainly in a fresh interpreter
    (`bench/speed.py --plain-child`; with `child_envs`, on the sandbox child's envs)."""
    environment = dict(os.environ)
    environment["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT), environment.get("PYTHONPATH")]))
    command = plain_command(submission, calls_file, child_envs=child_envs)
    started = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True, env=environment, check=False)
    wall = time.perf_counter() - started
    if done.returncode != 0:
        raise SystemExit(
            f"the plain run of {submission.name} failed (exit {done.returncode}): {done.stderr[-3000:]}"
        )
    summary = json.loads(done.stdout.strip().splitlines()[-1])
    return summary["import_cpu"] + summary["calls_cpu"], wall


def row(*cells: object) -> str:
    """A markdown table row."""
    return "| " + " | ".join(str(cell) for cell in cells) + " |"


def section(runs: list[EditionRun], cores: int, workers: int, load: LoadSampler, command: str) -> str:
    """The `## Class throughput` section."""
    total_files = sum(run.files for run in runs)
    wall = sum(run.wall for run in runs)
    grade_cpu = sum(run.cpu for run in runs)
    plain_cpu = sum(run.plain_cpu * run.files for run in runs)
    bound = plain_cpu / cores
    per_plain = plain_cpu / total_files
    per_grade = grade_cpu / total_files
    cpu_ratio = per_grade / per_plain
    per_same_envs = sum(run.same_envs_cpu * run.files for run in runs) / total_files
    chunks = -(-PROJECTED_CLASS // CHUNK_SUBMISSIONS)
    longest = max(run.cpu / run.files for run in runs)
    two_core = PROJECTED_CLASS * per_grade / 2
    two_core_bound = PROJECTED_CLASS * per_plain / 2
    four_core = PROJECTED_CLASS * per_grade / 4 + longest
    four_core_bound = PROJECTED_CLASS * per_plain / 4
    # The run itself keeps `workers` processes busy (a load of about `workers`); beyond that, others ran.
    busy = statistics.median(load.samples) > workers + 0.5
    stamp = datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")
    lines = [
        HEADING,
        "",
        f"`{command}`, {stamp}, {platform.machine()}, {cores} cores, full isolation, `--workers {workers}`. "
        f"Machine load during the run: {load.summary()}."
        + (
            f" **The machine was shared with other jobs (median load above this run's {workers} workers)**: "
            "the wall times and the wall ratio are stretched by them; the CPU figures are not."
            if busy
            else ""
        ),
        "",
        f"A class of {total_files} submissions: the lab-literal solution of each edition, every copy with "
        "different bytes (header comment, blank lines), graded with `gymgrade grade --edition E` (one run "
        "per edition, as a batch grades one edition). Plain: one file's calls of each edition, exactly as "
        "the grader made them (logged by `bench/class_calls.py`), run serially in one fresh process "
        "(`grader.compat.activate()`, import, call; no sandbox, no recording, no replay) on gymnasium's "
        "envs, and again on the sandbox child's envs.",
        "",
        row(
            "edition",
            "files",
            "calls per file",
            "problem statuses",
            "grade wall (s)",
            "grade CPU per file (s)",
            "plain CPU per file (s)",
            "CPU ratio",
            "plain CPU per file, the child's envs (s)",
            "CPU ratio, the child's envs",
        ),
        row("---", "---:", "---:", "---", "---:", "---:", "---:", "---:", "---:", "---:"),
    ]
    for run in runs:
        statuses = ", ".join(f"{count} {status}" for status, count in sorted(run.statuses.items()))
        lines.append(
            row(
                run.edition,
                run.files,
                run.calls,
                statuses,
                f"{run.wall:.1f}",
                f"{run.cpu / run.files:.1f}",
                f"{run.plain_cpu:.1f}",
                f"{run.cpu / run.files / run.plain_cpu:.2f}",
                f"{run.same_envs_cpu:.1f}",
                f"{run.cpu / run.files / run.same_envs_cpu:.2f}",
            )
        )
    lines += [
        row(
            "class",
            total_files,
            "",
            "",
            f"{wall:.1f}",
            f"{per_grade:.1f}",
            f"{per_plain:.1f}",
            f"{cpu_ratio:.2f}",
            f"{per_same_envs:.1f}",
            f"{per_grade / per_same_envs:.2f}",
        ),
        "",
        f"- **Wall / bound: {wall / bound:.2f}** (goal <= 1.1): the class took {wall:.1f} s; the bound "
        f"K x plain CPU per submission / cores = {plain_cpu:.1f} s / {cores} = {bound:.1f} s.",
        f"- **Grading CPU / plain CPU per submission: {cpu_ratio:.2f}** ({per_grade:.1f} s against "
        f"{per_plain:.1f} s), the figure load cannot stretch. The sandbox child deals Taxi and Blackjack "
        "with cheaper twins of gymnasium's classes (`grader/sandbox/child/envs.py`), so the student's calls "
        "cost less in the grading than plainly.",
        f"- Grading CPU / plain CPU on the child's envs: {per_grade / per_same_envs:.2f} ({per_grade:.1f} s "
        f"against {per_same_envs:.1f} s): the grader's own work alone (sandbox start, recording, transfer, "
        "replay, judging, pytest and xdist), with what the cheaper envs give back taken out.",
        f"- Cores busy on average: {grade_cpu / wall:.2f} of {cores} (grading CPU / wall).",
        "",
        f"Projection for {PROJECTED_CLASS} submissions (this mix of editions), from the CPU per submission "
        "measured here:",
        "",
        row("machine", "projected drain (min)", "bound: plain CPU / cores (min)", "ratio"),
        row("---", "---:", "---:", "---:"),
        row(
            "1 x 2 cores, `gymgrade grade`",
            f"{two_core / 60:.1f}",
            f"{two_core_bound / 60:.1f}",
            f"{two_core / two_core_bound:.2f}",
        ),
        row(
            "2 x 2 cores, Celery workers (one grading per core)",
            f"{four_core / 60:.1f}",
            f"{four_core_bound / 60:.1f}",
            f"{four_core / four_core_bound:.2f}",
        ),
        "",
        "Assumptions: every submission costs what its edition's lab-literal file costs here (the class mix "
        "is the same); gradings are CPU-bound and independent, so N cores drain N core-seconds per second "
        f"(2 cores: {PROJECTED_CLASS} x {per_grade:.1f} s / 2; the {chunks} pytest runs of "
        f"{CHUNK_SUBMISSIONS} submissions each sort their problems longest first across the chunk, so a "
        "chunk's tail is its shortest problems, a few seconds each, not counted); with Celery, "
        "`gymgrade worker` runs one grading per core without xdist (`## Scale-out (issue 9)`), each costing "
        "the CPU per submission measured here, plus the last grading's skew (at most one submission, "
        f"{longest:.1f} s of CPU); Redis and PostgreSQL carry a few messages per grading and are not "
        "binding; cores are real cores. The projected ratio equals the CPU ratio: on a machine kept busy, "
        "only the grader's CPU per submission stands between the drain time and the bound.",
        "",
    ]
    return "\n".join(lines)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--submissions", type=int, default=4, help="K, the class size (default 4)")
    parser.add_argument("--editions", default=",".join(EDITIONS))
    parser.add_argument("--workers", type=int, default=len(os.sched_getaffinity(0)))
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--write", action="store_true")
    args = parser.parse_args()
    editions = [name for name in args.editions.split(",") if name]
    unknown = set(editions) - set(EDITIONS)
    if unknown:
        raise SystemExit(f"unknown editions {sorted(unknown)}; expected some of {', '.join(EDITIONS)}")
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0)
    cores = len(os.sched_getaffinity(0))
    runs: list[EditionRun] = []
    with tempfile.TemporaryDirectory(prefix="gymgrade-class-") as scratch:
        root = Path(scratch)
        counts = Counter(editions[index % len(editions)] for index in range(args.submissions))
        with LoadSampler() as load:
            for edition in editions:
                if not counts[edition]:
                    continue
                folder, out, log = root / edition, root / f"{edition}-out", root / f"{edition}-calls"
                for directory in (folder, out, log):
                    directory.mkdir()
                source = EDITIONS[edition].read_text(encoding="utf-8")
                for index in range(counts[edition]):
                    name = f"student{index:04d}_{edition}.py"
                    (folder / name).write_text(varied(source, index), encoding="utf-8")
                print(f"grading {counts[edition]} {edition} file(s) ...", flush=True)
                wall, cpu, statuses = grade_edition(edition, folder, out, log, args.workers, args.seed)
                print(f"   {wall:.1f} s wall, {cpu:.1f} s CPU, {dict(statuses)}", flush=True)
                calls = read_calls(log)
                if not calls:
                    raise SystemExit(f"no call was logged for {edition}: is bench/class_calls.py loaded?")
                first = min(calls)
                runs.append(EditionRun(edition, counts[edition], wall, cpu, statuses))
                runs[-1].calls, runs[-1].log, runs[-1].logged_file = len(calls[first]), log, first
        for run in runs:
            assert run.log is not None
            calls_file = run.log / "plain.calls"
            calls_file.write_bytes(pickle.dumps(read_calls(run.log)[run.logged_file]))
            run.plain_cpu, run.plain_wall = plain_cpu(EDITIONS[run.edition], calls_file)
            run.same_envs_cpu, _ = plain_cpu(EDITIONS[run.edition], calls_file, child_envs=True)
            print(
                f"plain {run.edition}: {run.plain_cpu:.1f} s CPU ({run.plain_wall:.1f} s wall); "
                f"on the child's envs {run.same_envs_cpu:.1f} s CPU",
                flush=True,
            )
    command = " ".join(["python", "bench/class_throughput.py", *sys.argv[1:]])
    text = section(runs, cores, args.workers, load, command)
    print(text)
    if args.write:
        replace_section(HEADING, text)
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Figures of issue 11: grading against running the same student calls plainly, and where the rest goes.

    python bench/speed.py [--submission PATH] [--rounds 3] [--workers N] [--seed 0] [--config PATH]
                          [--only ID,ID...] [--write]

1. Grades the submission (default: the lab-literal `submissions/classic_complete.py`) once in this process,
   serially, problem by problem, with full isolation and timers on the sandbox, the replay and the rest:
   per problem, the child's start and the student's import, the student's own time, the transfer, the
   replay and the judging. The calls the grader made are recorded.
2. Runs exactly those calls plainly and serially in one fresh process (`grader.compat.activate()`, the
   submission imported, each function called with the grader's arguments, compare()'s cells call run as
   Run All runs the cells; no sandbox, no recording, no replay: what an in-process grader such as Otter
   costs at least), alternated with `gymgrade check` of
   the same file on `--workers` workers (default: all cores), `--rounds` times each, in one run. Prints
   the ratio gymgrade / plain (goal <= 1.0) and the grader's overhead as a share of the student's time
   (goal <= 10%), from the report's `timings`.
3. Times the fixed costs: interpreter start, pytest session start, xdist worker start, sandbox child start,
   isolation set-up and student import.
4. Prototype (here only, not in the grader): ONE sandbox child serving every problem of the submission
   (seed, call index and per-call limit reset per problem) against one child per problem: the time
   saved, whether every result stays identical, and a two-problem submission with module-level state
   graded in both orders, which shows that a shared child makes a problem's report depend on which
   problems ran before it in that child (on xdist scheduling).

`--write` replaces the `## Speed (issue 11)` section at the end of bench/RESULTS.md (with `--ab`: the section
`## The grader's own CPU and the plain run (issue 44): FILE, N problems`; `--fixed-problem ID` adds a
session's fixed cost, a check of that cheap problem alone on one worker). `--ab BASELINE_ROOT` runs
only step 2, with the grader of another tree (a worktree of `main`, say) alternated with this one's: an
A/B of a change, e.g. `--ab /work/main --only taxi --rounds 2`, wall and CPU (every process of a run, in a
cgroup v1 `cpuacct` group where available). `--breakdown` runs only step 1 and prints its per-problem table
and the grader process's own CPU.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib.util
import io
import itertools
import json
import os
import pickle
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from datetime import UTC, date, datetime
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from cpu_group import CpuGroup  # noqa: E402
from grading_probe import ProblemCost, SharedChild, grade_serially, graded, leaky_orders  # noqa: E402
from results_section import replace_section  # noqa: E402

HEADING = "## Speed (issue 11)"
AB_HEADING = "## The grader's own CPU and the plain run (issue 44)"
PLAIN_CHILD_ENVS = "plain, the child's envs"
DEFAULT_SUBMISSION = ROOT / "submissions" / "classic_complete.py"
ACCEPTANCE_DIR = ROOT / "grader" / "grading" / "cases"
_PR_SET_CHILD_SUBREAPER = 36
_CLI = "import sys; from grader.cli import main; sys.exit(main(sys.argv[1:]))"

# ---------------------------------------------------------------------------------------------- plain side


def _plain_argument(value: Any) -> Any:
    """A logged argument as the plain run passes it: an `EnvArgument` (made by the sandbox) made here."""
    from grader.sandbox.outcome import EnvArgument

    if isinstance(value, EnvArgument):
        import gymnasium  # its make resolves lab ids here (`_route_lab_ids`)

        return gymnasium.make(value.env_id, max_episode_steps=value.max_episode_steps)
    return value


def plain_child(calls_file: Path, submission: Path, child_envs: bool = False) -> None:
    """Run the recorded calls plainly in this process; print the times as one JSON line on stdout.

    With `child_envs`, every env is dealt by the sandbox child's cheaper class of the same game
    (`grader.sandbox.child.envs.cheaper`), so the run differs from the grading only by the grader's own work.
    """
    import grader.compat
    from grader.sandbox.child.cells import RUN_CELLS

    started, cpu = time.perf_counter(), time.process_time()
    grader.compat.activate()
    _route_lab_ids(child_envs)
    spec = importlib.util.spec_from_file_location("opengym", submission)
    if spec is None or spec.loader is None:
        raise SystemExit(f"cannot import {submission}")
    module = importlib.util.module_from_spec(spec)
    sys.modules["opengym"] = module
    quiet = io.StringIO()
    with contextlib.redirect_stdout(quiet):
        spec.loader.exec_module(module)
    imported, imported_cpu = time.perf_counter() - started, time.process_time() - cpu
    calls: list[tuple[str, tuple[Any, ...], dict[str, Any]]] = pickle.loads(calls_file.read_bytes())
    per_function: dict[str, float] = {}
    calls_started, calls_cpu = time.perf_counter(), time.process_time()
    for function, logged_args, kwargs in calls:
        args = tuple(_plain_argument(value) for value in logged_args)
        began = time.perf_counter()
        with contextlib.redirect_stdout(quiet):
            if function == RUN_CELLS:
                _run_cells_plainly(module, *args, **kwargs)
            else:
                getattr(module, function)(*args, **kwargs)
        per_function[function] = per_function.get(function, 0.0) + time.perf_counter() - began
        quiet.seek(0)
        quiet.truncate()
    summary = {
        "import_seconds": imported,
        "import_cpu": imported_cpu,
        "calls_seconds": time.perf_counter() - calls_started,
        "calls_cpu": time.process_time() - calls_cpu,
        "calls": len(calls),
        "per_function": per_function,
    }
    print(json.dumps(summary))


def _run_cells_plainly(
    module: Any, cells: list[dict[str, Any]], then: str | None = None, bind: dict[str, Any] | None = None
) -> None:
    """The grader's cells call (compare()'s), as Run All runs them: each cell in the module's namespace,
    a script with ``__name__ == "__main__"``; no labelling of tables, no limits. With `bind`, the grader's
    tables are bound as the child binds them and no cell runs where that serves (the default)."""
    from grader.sandbox.child.binding import bind_tables

    namespace = vars(module)
    if bind is not None and isinstance(bind_tables(namespace, cells, bind, then or "compare"), list):
        return
    for entry in cells:
        script, name = bool(entry["script"]), namespace.get("__name__")
        filename = module.__file__ if script else f"<notebook cell {entry['cell']}>"
        if script:
            namespace["__name__"] = "__main__"
        try:
            exec(compile(str(entry["source"]), filename, "exec"), namespace)
        finally:
            namespace["__name__"] = name


def _route_lab_ids(child_envs: bool = False) -> None:
    """Let plain `gymnasium.make("Taxi-v3")` make the env the lab means, as the sandbox's recorder does.

    Gymnasium-API submissions of the later editions keep the lab's ids, which today's gymnasium no longer
    registers; the grader resolves them (`grader.compat.resolve_env_id`), so the plain run does too (once
    per `make`, nothing per step). With `child_envs`, each env made is swapped to the child's class.
    """
    import gymnasium
    import gymnasium.envs.registration

    from grader.compat import register_envs, resolve_env_id
    from grader.sandbox.child import envs

    original = gymnasium.envs.registration.make

    def make(id: Any, *args: Any, **kwargs: Any) -> Any:
        if isinstance(id, str) and ":" not in id and id not in gymnasium.envs.registration.registry:
            target = resolve_env_id(id)
            register_envs()
            env = original(target.gymnasium_id, *args, **target.merged_kwargs(kwargs))
        else:
            env = original(id, *args, **kwargs)
        if child_envs:
            envs.cheaper(env.unwrapped)
        return env

    gymnasium.make = gymnasium.envs.make = gymnasium.envs.registration.make = make


@dataclass
class Run:
    """One timed subprocess: its wall time, the CPU of all its processes (None without a cgroup), output."""

    wall: float
    stdout: str
    returncode: int
    cpu: float | None = None


_run_numbers = itertools.count()


def timed_run(command: Sequence[str], root: Path = ROOT, **extra: str) -> Run:
    """Run a command with a tree's sources (default: this one) first on PYTHONPATH; time it.

    Its CPU is every process's of the run (the grader, its xdist workers, the sandbox children), counted in
    a cgroup v1 `cpuacct` group (`bench/cpu_group.py`; None where that is not available).
    """
    environment = dict(os.environ, **extra)
    environment["PYTHONPATH"] = os.pathsep.join(filter(None, [str(root), environment.get("PYTHONPATH")]))
    group = CpuGroup(f"speed-{next(_run_numbers)}")
    started = time.perf_counter()
    # In the tree's directory: `python -c` puts the working directory first on sys.path, before PYTHONPATH.
    done = subprocess.run(
        list(command),
        capture_output=True,
        text=True,
        env=environment,
        check=False,
        preexec_fn=group.join,
        cwd=root,
    )
    wall = time.perf_counter() - started
    cpu = group.seconds()
    group.remove()
    return Run(wall, done.stdout, done.returncode, cpu)


def plain_command(submission: Path, calls_file: Path, *, child_envs: bool = False) -> list[str]:
    """The command that runs the recorded calls plainly in a fresh interpreter (`plain_child`)."""
    script = str(Path(__file__).resolve())
    command = [sys.executable, script, "--plain-child", str(calls_file), str(submission)]
    return command + (["--plain-child-envs"] if child_envs else [])


def plain_run(submission: Path, calls_file: Path, *, child_envs: bool = False) -> tuple[Run, dict[str, Any]]:
    """The recorded calls run plainly in a fresh interpreter (with the child's envs: `plain_child`)."""
    run = timed_run(plain_command(submission, calls_file, child_envs=child_envs))
    if run.returncode != 0:
        raise SystemExit(f"the plain run failed (exit {run.returncode}): {run.stdout[-2000:]}")
    return run, json.loads(run.stdout.strip().splitlines()[-1])


def gymgrade_run(
    submission: Path, workers: int, seed: int, config: Path | None, only: Sequence[str], root: Path = ROOT
) -> tuple[Run, Any]:
    """`gymgrade check --json` of the submission in a fresh interpreter (the grader of tree `root`)."""
    from grader.report import Report

    command = [sys.executable, "-c", _CLI, "check", str(submission), "--json", "--workers", str(workers)]
    command += ["--seed", str(seed), "--only", ",".join(only), *(["--config", str(config)] if config else [])]
    run = timed_run(command, root)
    report = Report.model_validate_json(run.stdout)
    if run.returncode != 0 or report.grader_errors:
        raise SystemExit(
            f"gymgrade check did not give full marks (exit {run.returncode}): {run.stdout[:3000]}"
        )
    return run, report


# ------------------------------------------------------------------------------------------- fixed costs


def median_wall(command: Sequence[str], repeats: int, **extra: str) -> float:
    """Median wall time of a command."""
    return statistics.median(timed_run(command, **extra).wall for _ in range(repeats))


def session_command(submission: Path, workers: int) -> list[str]:
    """A pytest session of the acceptance tests that starts `workers` xdist workers and runs no test."""
    command = [
        sys.executable,
        "-m",
        "pytest",
        "-p",
        "grader.grading.plugin",
        "-p",
        "xdist.plugin",
        "-p",
        "no:cacheprovider",
    ]
    command += [
        "-q",
        str(ACCEPTANCE_DIR),
        "-c",
        str(ACCEPTANCE_DIR / "pytest.ini"),
        "--rootdir",
        str(ACCEPTANCE_DIR),
    ]
    return [*command, "--submission", str(submission), "-k", "no_such_problem", "-n", str(workers)]


def sandbox_start(submission: Path, repeats: int, *, isolated: bool = True) -> float:
    """Median seconds from a new `Sandbox` to its `functions` (child started, submission imported).

    Args:
        submission: What the child imports.
        repeats: How many children to start.
        isolated: False starts the child with every isolation layer off (to time the layers' set-up).
    """
    from grader.lab.assignment import load_config
    from grader.sandbox import IsolationPolicy, probe_isolation
    from grader.sandbox.isolation.registry import LAYERS
    from grader.sandbox.runner import Sandbox

    limits = load_config().sandbox.to_limits(60.0)
    policy = IsolationPolicy.REQUIRE_FULL if isolated else IsolationPolicy.ALLOW_FALLBACK
    isolation = probe_isolation(frozenset() if isolated else frozenset(layer.name for layer in LAYERS))
    times = []
    for index in range(repeats):
        started = time.perf_counter()
        with Sandbox(submission, seed=index, limits=limits, policy=policy, isolation=isolation) as sandbox:
            if not sandbox.functions and submission.read_text().strip():
                raise SystemExit(f"{submission} did not import in the sandbox")
            times.append(time.perf_counter() - started)
    return statistics.median(times)


# ------------------------------------------------------------------------------------------------ report


@dataclass
class Figures:
    """Everything the section reports."""

    submission: Path
    workers: int
    rounds: int
    costs: list[ProblemCost]
    plain: list[tuple[Run, dict[str, Any]]]
    gymgrade: list[tuple[Run, Any]]
    interpreter: float
    session: float
    session_workers: float
    empty_start: float
    bare_start: float
    submission_start: float
    shared_costs: list[ProblemCost]
    shared_identical: bool
    leaky_orders: dict[str, str]
    load: str
    problems: list[str]
    command: str
    busy: bool = False
    skipped: list[str] = field(default_factory=list)


def longest_first(durations: Sequence[float], workers: int) -> float:
    """Makespan of handing durations out longest first to the first free worker."""
    finish = [0.0] * workers
    for duration in sorted(durations, reverse=True):
        finish[finish.index(min(finish))] += duration
    return max(finish)


def shared_makespan(costs: Sequence[ProblemCost], workers: int) -> float:
    """Longest-first makespan when each worker starts (and tears down) one child for all its problems.

    Projected from the one-child-per-problem costs, so load drifting between two runs cannot enter it.
    """
    busy, fixed = [0.0] * workers, [0.0] * workers
    for cost in sorted(costs, key=lambda cost: cost.wall, reverse=True):
        worker = min(range(workers), key=lambda index: busy[index] + fixed[index])
        busy[worker] += cost.wall - cost.start - cost.close
        fixed[worker] = max(fixed[worker], cost.start + cost.close)
    return max(done + start for done, start in zip(busy, fixed, strict=True))


def row(*cells: object) -> str:
    """A markdown table row."""
    return "| " + " | ".join(str(cell) for cell in cells) + " |"


def seconds(values: Sequence[float]) -> str:
    """Each value, to a tenth of a second."""
    return ", ".join(f"{value:.1f}" for value in values)


def cost_row(label: str, status: str, costs: Sequence[ProblemCost]) -> str:
    """One row of the per-problem table (summed over `costs`)."""
    parts = ("wall", "start", "student", "transfer", "replay", "judge_rest", "close")
    sums = [f"{sum(getattr(cost, part) for cost in costs):.2f}" for part in parts]
    return row(label, status, sum(cost.calls for cost in costs), *sums)


def section(figures: Figures) -> str:
    """The `## Speed (issue 11)` section of bench/RESULTS.md: gymgrade against plain, then the rest."""
    median = statistics.median
    plain_walls = [run.wall for run, _ in figures.plain]
    plain_calls = median([summary["calls_seconds"] for _, summary in figures.plain])
    plain_cpu = median([summary["calls_cpu"] for _, summary in figures.plain])
    grade_walls = [run.wall for run, _ in figures.gymgrade]
    reports = [report for _, report in figures.gymgrade]
    student = median([report.timings.student_seconds for report in reports])
    inside = median([report.timings.overhead_seconds for report in reports])
    elapsed = median([report.timings.elapsed_seconds for report in reports])
    ratio = median(grade_walls) / median(plain_walls)
    name = figures.submission.name
    statuses = ", ".join(f"{result.id} {result.status}" for result in reports[-1].problems)
    workers = figures.workers
    lines = [
        HEADING,
        "",
        f"`{figures.command}`, {date.today()}, "
        f"{platform.machine()}, {os.cpu_count()} cores, full isolation ({figures.load}). Submission "
        f"`{name}` (the lab-literal solution), default assignment configuration: {statuses}.",
        "",
        *(
            [
                f"The machine was busy with other jobs ({figures.load} on {os.cpu_count()} cores): every "
                "wall time below is stretched by them; compare figures within this run, and re-run on an "
                "idle machine to check the goals.",
                "",
            ]
            if figures.busy
            else []
        ),
        "### gymgrade against the same calls run plainly",
        "",
        f"Plain: the {figures.plain[0][1]['calls']} calls `gymgrade check` makes, with its arguments, run "
        "serially in one fresh process (`grader.compat.activate()`, import, call; no sandbox, no recording, "
        f"no replay). gymgrade: `gymgrade check --json --workers {workers}` of the same file, in a fresh "
        f"process. Alternated A/B, B/A, ...; rounds: {figures.rounds}.",
        "",
        row("run", "wall (s), each", "median wall (s)", "student calls (s)"),
        row("---", "---", "---:", "---:"),
        row(
            "plain, 1 process",
            seconds(plain_walls),
            f"{median(plain_walls):.1f}",
            f"{plain_calls:.1f}",
        ),
        row(
            f"gymgrade check, {workers} workers",
            seconds(grade_walls),
            f"{median(grade_walls):.1f}",
            f"{student:.1f}",
        ),
        "",
        f"- **Ratio gymgrade / plain: {ratio:.2f}** (median wall over median wall; goal <= 1.0).",
        f"- **Grader overhead as a share of student time: {inside / student:.0%}** (the report's `timings`: "
        f"overhead {inside:.1f} s / student {student:.1f} s, medians; goal <= 10%). The same calls "
        f"plainly: {plain_calls:.1f} s, of which {plain_cpu:.1f} s CPU (other jobs took the rest).",
        f"- Student time inside the sandbox {student:.1f} s against {plain_calls:.1f} s for the same calls "
        "plainly: the recorder (every reset and step logged) counts as student time in the report.",
        f"- The report's `elapsed_seconds` (call to report): {elapsed:.1f} s; the rest of the wall is the "
        "CLI's interpreter start and imports.",
    ]
    if figures.skipped:
        lines.append(
            f"- Not run, as no verdict needs them: {', '.join(figures.skipped)} (before issue 11, "
            "find_qvalues alone was half the student CPU of this submission: 24.1 s of 48.4 s, `## Grading`)."
        )
    return "\n".join([*lines, *fixed_lines(figures), *shared_lines(figures)])


def fixed_lines(figures: Figures) -> list[str]:
    """The fixed costs, and where each problem's time went."""
    workers, name = figures.workers, figures.submission.name
    lines = [
        "",
        "### Fixed costs",
        "",
        row("cost", "seconds"),
        row("---", "---:"),
        row("interpreter start (`python -c pass`)", f"{figures.interpreter:.2f}"),
        row(
            "interpreter + pytest session start (acceptance tests collected, none run)",
            f"{figures.session:.2f}",
        ),
        row(
            f"xdist worker start ({workers} workers, their collection included)",
            f"{max(figures.session_workers - figures.session, 0):.2f}",
        ),
        row(
            "sandbox child start, no isolation layer (an empty submission imported)",
            f"{figures.bare_start:.2f}",
        ),
        row(
            "isolation set-up (cgroup, bubblewrap, seccomp, privileges, rlimits, Landlock)",
            f"{max(figures.empty_start - figures.bare_start, 0):.2f}",
        ),
        row(
            f"student import (`{name}`: numpy, the gym shim, the module)",
            f"{max(figures.submission_start - figures.empty_start, 0):.2f}",
        ),
        "",
        "Per problem, graded serially in one process (`run_problem`, timers around the sandbox, the replay "
        "and the teardown; seconds):",
        "",
    ]
    return lines + cost_table(figures.costs)


def cost_table(costs: Sequence[ProblemCost]) -> list[str]:
    """The per-problem table: where each problem's serial grading time went, and the sum."""
    header = ["problem", "status", "calls", "wall", "child start + import", "student", "transfer", "replay"]
    lines = [row(*header, "judge + rest", "teardown"), row("---", "---", *["---:"] * 8)]
    lines += [cost_row(cost.problem, cost.status, [cost]) for cost in costs]
    lines.append(cost_row("all", "", costs))
    return lines


def breakdown_main(args: argparse.Namespace, submission: Path, problems: Sequence[str], config: Any) -> int:
    """`--breakdown`: only step 1's per-problem table, and the CPU of this (the grader's) process."""
    load_before = os.getloadavg()[0]
    cpu_before = time.process_time()
    costs, _, _ = grade_serially(submission, problems, config, args.seed)
    cpu = time.process_time() - cpu_before
    print(
        f"`{submission.name}`, load average {load_before:.1f} before, {os.getloadavg()[0]:.1f} after",
        flush=True,
    )
    print("\n".join(cost_table(costs)))
    print(
        f"\nThe grader's own process: {cpu:.2f} s of CPU (frames decoded, replay, judging; the children's "
        "start, the student's calls and the recording are not in it)."
    )
    return 0


def shared_lines(figures: Figures) -> list[str]:
    """One sandbox child for all problems against one per problem, and the decision."""
    workers, name, shared = figures.workers, figures.submission.name, figures.shared_costs
    lines = [
        "",
        "### One sandbox child per worker for all problems, or one per problem",
        "",
        "Prototype (bench only): the same problems graded serially through ONE child (seed stream, call "
        "index and per-call limit reset per problem), right after one child per problem (above). The "
        "serial walls of the two runs also differ by whatever load changed between them; the makespan of "
        "one child per worker is projected from the first run's costs (one start and teardown per worker).",
        "",
        row("", "serial wall (s)", "child starts + teardowns (s)", f"longest-first on {workers} workers (s)"),
        row("---", "---:", "---:", "---:"),
        row(
            "one child per problem",
            f"{sum(cost.wall for cost in figures.costs):.2f}",
            f"{sum(cost.start + cost.close for cost in figures.costs):.2f}",
            f"{longest_first([cost.wall for cost in figures.costs], workers):.2f}",
        ),
        row(
            "one child for all",
            f"{sum(cost.wall for cost in shared):.2f}",
            f"{sum(cost.start + cost.close for cost in shared):.2f}",
            f"{shared_makespan(figures.costs, workers):.2f} (projected)",
        ),
        "",
        "- Every result identical (status, score, feedback, measurements, output): "
        f"**{'yes' if figures.shared_identical else 'no'}** for `{name}`.",
        "- A submission with module-level state (a list its functions append to and print, as a notebook "
        "keeps a global env or Q-table): `car` graded through one shared child after `cartpole`, and first:",
        "",
        row("order in the shared child", "car's output (first line)"),
        row("---", "---"),
    ]
    lines += [row(order, f"`{output}`") for order, output in figures.leaky_orders.items()]
    per_problem_span = longest_first([cost.wall for cost in figures.costs], workers)
    shared_span = shared_makespan(figures.costs, workers)
    saved = sum(cost.start + cost.close for cost in figures.costs) - sum(
        cost.start + cost.close for cost in shared
    )
    lines += [
        "",
        "With one child per problem, car's output is the same whatever ran before it.",
        "",
        f"**Decision: one child per problem stays.** A shared child saves {saved:.1f} s of child starts "
        f"and teardowns here ({saved / sum(cost.wall for cost in figures.costs):.1%} of the serial time), "
        f"but on {workers} workers the grading waits for its longest problem, whose own child start "
        f"remains: the longest-first makespan goes from {per_problem_span:.1f} s to {shared_span:.1f} s. "
        "Against it: (1) which problems "
        "share a child would depend on xdist's scheduling, and a child's module-level state (a global env, "
        "Q-table, cache or list; the call seeds are reset per call, Python objects are not) flows into the "
        "next problem's calls, so the same bytes and seed could give a different report (the table above); "
        "(2) the child's life-long CPU limit, its memory growth and its process count would be shared, so "
        "one problem's consumption could end another's calls with `memory_limit` or `killed`; (3) after a "
        "timeout or crash the child restarts anyway, mid-submission. Instead, a problem no verdict needs "
        "starts no child at all (find_qvalues, `skipped`).",
        "",
    ]
    return lines


# -------------------------------------------------------------------------------------------------- A/B


def ab_lines(
    baseline: Path,
    grades: dict[str, list[tuple[Run, Any]]],
    plain: list[tuple[Run, dict[str, Any]]],
    load: str,
    plain_child_envs: Sequence[tuple[Run, dict[str, Any]]] = (),
) -> list[str]:
    """The A/B table: the same check graded by a baseline tree's grader and this tree's, and plainly.

    `plain_child_envs`, the plain run with the sandbox child's envs, separates the grader's own work from
    what the child's cheaper envs give back: "this tree" against it is the grader's cost alone.
    """
    median = statistics.median
    order = "baseline, this tree, plain" + (f", {PLAIN_CHILD_ENVS}" if plain_child_envs else "")
    lines = [
        f"A/B against `{baseline}` ({load}); alternated {order}, then reversed:",
        "",
        row(
            "run",
            "wall (s), each",
            "median wall (s)",
            "CPU (s), each",
            "median CPU (s)",
            "student (s)",
            "grader overhead (s)",
        ),
        row("---", "---", "---:", "---", "---:", "---:", "---:"),
    ]
    for label, runs in grades.items():
        reports = [report for _, report in runs]
        lines.append(
            row(
                label,
                seconds([run.wall for run, _ in runs]),
                f"{median([run.wall for run, _ in runs]):.1f}",
                seconds([run.cpu for run, _ in runs if run.cpu is not None]),
                _cpu_text(_median_cpu([run for run, _ in runs])),
                f"{median([report.timings.student_seconds for report in reports]):.1f}",
                f"{median([report.timings.overhead_seconds for report in reports]):.1f}",
            )
        )
    for label, runs_of_plain in (("plain, 1 process", plain), (PLAIN_CHILD_ENVS, plain_child_envs)):
        if runs_of_plain:
            lines.append(
                row(
                    label,
                    seconds([run.wall for run, _ in runs_of_plain]),
                    f"{median([run.wall for run, _ in runs_of_plain]):.1f}",
                    seconds([run.cpu for run, _ in runs_of_plain if run.cpu is not None]),
                    _cpu_text(_median_cpu([run for run, _ in runs_of_plain])),
                    f"{median([summary['calls_seconds'] for _, summary in runs_of_plain]):.1f}",
                    "",
                )
            )
    lines.append("")
    for label, runs in grades.items():
        wall_ratio, cpu_ratio = _ratios([run for run, _ in runs], [run for run, _ in plain])
        lines.append(f"- {label}: wall / plain {wall_ratio:.2f}, CPU / plain CPU {cpu_ratio} (goal <= 1.0).")
    if plain_child_envs and "this tree" in grades:
        this_tree = [run for run, _ in grades["this tree"]]
        wall_ratio, cpu_ratio = _ratios(this_tree, [run for run, _ in plain_child_envs])
        lines.append(
            f"- this tree against {PLAIN_CHILD_ENVS} (the grader's own work alone): wall {wall_ratio:.2f}, "
            f"CPU {cpu_ratio}."
        )
    return lines


def _ratios(runs: Sequence[Run], against: Sequence[Run]) -> tuple[float, str]:
    """Median wall of `runs` over that of `against`, and the same for CPU (text: n/a without a cgroup)."""
    wall = statistics.median(run.wall for run in runs) / statistics.median(run.wall for run in against)
    cpu, against_cpu = _median_cpu(runs), _median_cpu(against)
    return wall, f"{cpu / against_cpu:.2f}" if cpu is not None and against_cpu else "n/a (no cgroup)"


def _median_cpu(runs: Sequence[Run]) -> float | None:
    values = [run.cpu for run in runs if run.cpu is not None]
    return statistics.median(values) if values else None


def _cpu_text(cpu: float | None) -> str:
    return "n/a" if cpu is None else f"{cpu:.1f}"


def ab_main(args: argparse.Namespace, submission: Path, problems: Sequence[str], config: Any) -> int:
    """`--ab BASELINE`: only the comparison of step 2, with a second grader (another worktree) alternated."""
    load_before = os.getloadavg()[0]
    print("1. recording the calls (one serial grading) ...", flush=True)
    _, _, calls = grade_serially(submission, problems, config, args.seed)
    labels = {"baseline": args.ab.resolve(), "this tree": ROOT}
    grades: dict[str, list[tuple[Run, Any]]] = {label: [] for label in labels}
    plain: list[tuple[Run, dict[str, Any]]] = []
    plain_child_envs: list[tuple[Run, dict[str, Any]]] = []
    loads: list[float] = []
    with tempfile.TemporaryDirectory(prefix="gymgrade-speed-") as scratch:
        calls_file = Path(scratch) / "calls.pickle"
        calls_file.write_bytes(pickle.dumps(calls))
        for round_index in range(args.rounds):
            order = ["baseline", "this tree", "plain", PLAIN_CHILD_ENVS]
            for kind in order if round_index % 2 == 0 else order[::-1]:
                if kind == "plain":
                    plain.append(plain_run(submission, calls_file))
                    run = plain[-1][0]
                elif kind == PLAIN_CHILD_ENVS:
                    plain_child_envs.append(plain_run(submission, calls_file, child_envs=True))
                    run = plain_child_envs[-1][0]
                else:
                    grades[kind].append(
                        gymgrade_run(submission, args.workers, args.seed, args.config, problems, labels[kind])
                    )
                    run = grades[kind][-1][0]
                loads.append(os.getloadavg()[0])
                print(f"2. {kind}: {run.wall:.1f} s wall", flush=True)
    load = (
        f"load average {load_before:.1f} before, {os.getloadavg()[0]:.1f} after, "
        f"after each run min {min(loads):.1f}, median {statistics.median(loads):.1f}, max {max(loads):.1f}"
    )
    lines = ab_lines(labels["baseline"], grades, plain, load, plain_child_envs)
    lines += share_lines(grades, plain, plain_child_envs)
    if args.fixed_problem:
        lines += fixed_cost_lines(args, submission, labels)
    print("\n".join(lines))
    if args.write:
        heading = f"{AB_HEADING}: {submission.name}, {len(problems)} problems"
        command = " ".join(["python", "bench/speed.py", *sys.argv[1:]])
        stamp = datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")
        replace_section(heading, "\n".join([heading, "", f"`{command}`, {stamp}.", "", *lines, ""]))
    return 0


def fixed_cost_lines(args: argparse.Namespace, submission: Path, labels: dict[str, Path]) -> list[str]:
    """A session's fixed cost for each tree: `gymgrade check --only ID --workers 1` of a problem that costs
    almost nothing (its CPU is the CLI, the pytest session, one xdist worker and one sandbox child),
    alternated, `--rounds` times each."""
    cpu: dict[str, list[float]] = {label: [] for label in labels}
    for round_index in range(max(args.rounds, 2)):
        order = list(labels) if round_index % 2 == 0 else list(labels)[::-1]
        for label in order:
            run, _ = gymgrade_run(submission, 1, args.seed, args.config, [args.fixed_problem], labels[label])
            if run.cpu is not None:
                cpu[label].append(run.cpu)
            print(f"3. fixed cost, {label}: {run.cpu} s CPU", flush=True)
    medians = ", ".join(
        f"{label} {statistics.median(values):.2f} s ({seconds(values)})"
        for label, values in cpu.items()
        if values
    )
    return [
        f"- A session's fixed cost (`gymgrade check --only {args.fixed_problem} --workers 1`: the CLI, "
        f"pytest, one xdist worker, one sandbox child; CPU, median (each)): {medians or 'n/a (no cgroup)'}."
    ]


def share_lines(
    grades: dict[str, list[tuple[Run, Any]]],
    plain: Sequence[tuple[Run, dict[str, Any]]],
    plain_child_envs: Sequence[tuple[Run, dict[str, Any]]],
) -> list[str]:
    """The issue's two figures for each grader: wall against the plain run, and its own CPU as a share of the
    student's (grading CPU less the plain run's on the child's envs, over the latter)."""
    lines = []
    student_cpu = _median_cpu([run for run, _ in plain_child_envs])
    for label, runs in grades.items():
        wall, _ = _ratios([run for run, _ in runs], [run for run, _ in plain])
        cpu = _median_cpu([run for run, _ in runs])
        share = "n/a" if cpu is None or not student_cpu else f"{(cpu - student_cpu) / student_cpu:.0%}"
        lines.append(
            f"- **{label}: {wall:.2f}x the plain run's wall** (goal <= 1.0), **the grader's own CPU "
            f"{share} of the student's** (goal <= 25%)."
        )
    return lines


# -------------------------------------------------------------------------------------------------- main


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--submission", type=Path, default=DEFAULT_SUBMISSION)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--workers", type=int, default=len(os.sched_getaffinity(0)))
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--config", type=Path, default=None)
    parser.add_argument("--only", default=None, metavar="ID[,ID...]", help="grade only these problems")
    parser.add_argument("--write", action="store_true")
    parser.add_argument(
        "--ab",
        type=Path,
        default=None,
        metavar="BASELINE_ROOT",
        help="only compare this tree's grader with another tree's (a worktree of main) and the plain run",
    )
    parser.add_argument(
        "--breakdown", action="store_true", help="only the per-problem table of one serial grading (step 1)"
    )
    parser.add_argument(
        "--fixed-problem",
        default=None,
        metavar="ID",
        help="with --ab: also a session's fixed cost, a check of only this (cheap) problem on one worker",
    )
    parser.add_argument(
        "--plain-child", nargs=2, type=Path, metavar=("CALLS", "SUBMISSION"), help=argparse.SUPPRESS
    )
    parser.add_argument("--plain-child-envs", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.plain_child:
        calls_file, submission = args.plain_child
        plain_child(calls_file, submission, child_envs=args.plain_child_envs)
        return 0

    from grader.grading.plan import GradingPlan
    from grader.lab.assignment import load_config

    submission = args.submission.resolve()
    if args.config is not None:
        args.config = args.config.resolve()
    config = load_config(args.config)
    only = [name for name in args.only.split(",") if name] if args.only else None
    plan = GradingPlan.load(args.config, only)
    if args.ab is not None:
        return ab_main(args, submission, plan.problems, config)
    if args.breakdown:
        return breakdown_main(args, submission, plan.problems, config)
    load_before = os.getloadavg()[0]

    print("1. grading serially, instrumented: one child per problem, then one child for all ...", flush=True)
    costs, results, calls = grade_serially(submission, plan.problems, config, args.seed)
    skipped = [result.id for result in results if result.status == "skipped"]
    for cost in costs:
        print(f"   {cost}", flush=True)
    shared = SharedChild()
    try:
        shared_costs, shared_results, _ = grade_serially(submission, plan.problems, config, args.seed, shared)
    finally:
        shared.close()
    identical = [graded(a) for a in results] == [graded(b) for b in shared_results]
    print(f"   shared child: {sum(cost.wall for cost in shared_costs):.1f} s; identical: {identical}")

    with tempfile.TemporaryDirectory(prefix="gymgrade-speed-") as scratch:
        calls_file = Path(scratch) / "calls.pickle"
        calls_file.write_bytes(pickle.dumps(calls))
        plain: list[tuple[Run, dict[str, Any]]] = []
        graded_runs: list[tuple[Run, Any]] = []
        for round_index in range(args.rounds):
            order = ("plain", "gymgrade") if round_index % 2 == 0 else ("gymgrade", "plain")
            for kind in order:
                if kind == "plain":
                    plain.append(plain_run(submission, calls_file))
                    print(f"2. plain: {plain[-1][0].wall:.1f} s wall", flush=True)
                else:
                    graded_runs.append(
                        gymgrade_run(submission, args.workers, args.seed, args.config, plan.problems)
                    )
                    run = graded_runs[-1][0]
                    print(f"2. gymgrade: {run.wall:.1f} s wall", flush=True)

        print("3. fixed costs ...", flush=True)
        empty = Path(scratch) / "empty.py"
        empty.write_text("", encoding="utf-8")
        no_autoload = {"PYTEST_DISABLE_PLUGIN_AUTOLOAD": "1", "PYTHONDONTWRITEBYTECODE": "1"}
        interpreter = median_wall([sys.executable, "-c", "pass"], 5)
        session = median_wall(session_command(submission, 0), 3, **no_autoload)
        session_workers = median_wall(session_command(submission, args.workers), 3, **no_autoload)
        empty_start = sandbox_start(empty, 5)
        bare_start = sandbox_start(empty, 5, isolated=False)
        submission_start = sandbox_start(submission, 5)

        print("4. module-level state through one shared child ...", flush=True)
        orders = leaky_orders(Path(scratch), config, args.seed)

    load = f"load average {load_before:.1f} before, {os.getloadavg()[0]:.1f} after"
    figures = Figures(
        submission=submission,
        workers=args.workers,
        rounds=args.rounds,
        costs=costs,
        plain=plain,
        gymgrade=graded_runs,
        interpreter=interpreter,
        session=session,
        session_workers=session_workers,
        empty_start=empty_start,
        bare_start=bare_start,
        submission_start=submission_start,
        shared_costs=shared_costs,
        shared_identical=identical,
        leaky_orders=orders,
        load=load,
        problems=list(plan.problems),
        command=" ".join(["python", "bench/speed.py", *sys.argv[1:]]),
        busy=load_before > len(os.sched_getaffinity(0)),
        skipped=skipped,
    )
    text = section(figures)
    print(text)
    if args.write:
        replace_section(HEADING, text)
    return 0


if __name__ == "__main__":
    sys.exit(main())

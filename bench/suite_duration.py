"""Time the README's test command (everything, as .ci/run runs it) against issue 44's 20-minute target.

Runs the command `.ci/run` holds (`bash scripts/setup.sh && scripts/run python3 -m pytest -m ""`) under
`CI=true`, or with `-- ARGS` only its pytest part with ARGS appended (a directory, `-n 0` for the old
one-process run), and records the wall time, pytest's summary (the test count), the CPU time of everything
it waited for, the cores and the load average: sampled every 10 s during the run, since on a shared machine
the wall time follows the load (an idle 2-core machine has a load of about 2 while the suite runs).
`--write` replaces the `## Full test run (issue 44)` section of bench/RESULTS.md; `--log FILE` keeps the
whole output (`PYTEST_ADDOPTS=--durations=50` adds pytest's slowest tests to it without changing the command).

    python bench/suite_duration.py --write          # the README's command, as .ci/run runs it
    python bench/suite_duration.py -- -n 2 tests/grader/sandbox  # one directory, scheduled as the full run
    python bench/suite_duration.py -- -n 0 tests/grader/sandbox  # the same in one process (as before)
"""

from __future__ import annotations

import argparse
import os
import re
import resource
import shlex
import subprocess
import threading
import time
from datetime import UTC, datetime
from pathlib import Path

from results_section import replace_section

ROOT = Path(__file__).resolve().parents[1]
HEADING = "## Full test run (issue 44)"
SUMMARY = re.compile(r"^=* ?(\d+ (passed|failed).*) in [\d.]+s.*$")


def readme_command() -> str:
    """The README's test command: the last line of .ci/run, which runs exactly that."""
    return (ROOT / ".ci" / "run").read_text(encoding="utf-8").strip().splitlines()[-1]


def cores() -> int:
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


def measure(command: str) -> dict[str, object]:
    """Run `command` in bash once; its wall time, CPU time, load samples and pytest's summary line."""
    loads = [os.getloadavg()[0]]
    done = threading.Event()

    def sample() -> None:
        while not done.wait(10):
            loads.append(os.getloadavg()[0])

    sampler = threading.Thread(target=sample, daemon=True)
    sampler.start()
    started = time.perf_counter()
    run = subprocess.run(
        ["bash", "-c", command], cwd=ROOT, env={**os.environ, "CI": "true"},
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    wall = time.perf_counter() - started
    done.set()
    sampler.join()
    loads.append(os.getloadavg()[0])
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    summaries = [match.group(1) for line in run.stdout.splitlines() if (match := SUMMARY.match(line))]
    return {
        "command": command,
        "exit": run.returncode,
        "wall": wall,
        "cpu": usage.ru_utime + usage.ru_stime,
        "loads": loads,
        "summary": summaries[-1] if summaries else run.stdout[-300:].strip(),
        "output": run.stdout + run.stderr,
    }


def section(result: dict[str, object]) -> str:
    loads: list[float] = result["loads"]  # type: ignore[assignment]
    wall, cpu = float(result["wall"]), float(result["cpu"])  # type: ignore[arg-type]
    mean = sum(loads) / len(loads)
    return (
        f"{HEADING}\n"
        f"`python bench/suite_duration.py` ({datetime.now(UTC):%Y-%m-%d %H:%M} UTC, {cores()} cores; load "
        f"average {loads[0]:.1f} before, {mean:.1f} mean over the run (every 10 s), {loads[-1]:.1f} after; "
        f"an idle 2-core machine shows about 2 while the suite runs). Target: at most 20 min on 2 idle "
        f"cores.\n\n"
        f"| command | result | wall | CPU (all processes) |\n|---|---|---|---|\n"
        f"| `{result['command']}` | exit {result['exit']}: {result['summary']} | **{wall / 60:.1f} min** "
        f"({wall:.0f} s) | {cpu:.0f} s |\n"
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help=f"replace {HEADING!r} in bench/RESULTS.md")
    parser.add_argument("--log", type=Path, help="write the run's whole output to this file")
    parser.add_argument("pytest_args", nargs="*", help="after --: run only pytest -m '' with these arguments")
    arguments = parser.parse_args()
    command = readme_command()
    if arguments.pytest_args:
        command = 'scripts/run python3 -m pytest -m "" ' + shlex.join(arguments.pytest_args)
    result = measure(command)
    text = section(result)
    output = str(result["output"])
    print("\n".join(output.splitlines()[-40:]))
    if arguments.log:
        arguments.log.write_text(output, encoding="utf-8")
    print(text)
    if arguments.write:
        replace_section(HEADING, text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""Time the test suite's default run (a bare `python3 -m pytest`) or its full run (`-m ""`, as .ci/run).

Prints the wall time, the CPU time of pytest and every process it waited for (its xdist workers, the
gradings' sessions and sandbox children), and the load average before and after: on a shared machine the
wall time follows the load, while CPU time / cores is what an idle machine of that many cores would need at
best. `--write` replaces the `## Test suite (issue 34)` section of bench/RESULTS.md with the figures.

    python bench/suite.py                 # the default run (on xdist, -n auto: the machine's cores)
    python bench/suite.py -- -n 0         # the default run in one process
    python bench/suite.py --all           # everything, in one process (as .ci/run)
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import time
from datetime import UTC, datetime
from pathlib import Path

from results_section import replace_section

ROOT = Path(__file__).resolve().parents[1]
HEADING = "## Test suite (issue 34)"


def measure(extra: list[str], everything: bool) -> dict[str, object]:
    """Run the suite once; its wall time, its children's CPU time, the load around it and pytest's summary."""
    selection = ["-m", ""] if everything else []
    argv = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *selection, *extra]
    load_before = os.getloadavg()[0]
    started = time.perf_counter()
    done = subprocess.run(argv, cwd=ROOT, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - started
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    lines = reversed(done.stdout.splitlines())
    summary = next((line for line in lines if " in " in line), done.stdout[-300:])
    return {
        "command": " ".join(["python3 -m pytest", *(['-m ""'] if everything else []), *extra]),
        "exit": done.returncode,
        "wall": wall,
        "cpu": usage.ru_utime + usage.ru_stime,
        "load": (load_before, os.getloadavg()[0]),
        "summary": summary.strip("= "),
        "tail": "\n".join(done.stdout.splitlines()[-60:]),  # the --durations list, when asked for
    }


def section(result: dict[str, object]) -> str:
    load_before, load_after = result["load"]  # type: ignore[misc]
    cpu = float(result["cpu"])  # type: ignore[arg-type]
    return (
        f"{HEADING}\n\n"
        f"`python bench/suite.py` ({datetime.now(UTC):%Y-%m-%d %H:%M} UTC, 2-core container shared with "
        f"other jobs, load average {load_before:.1f} before and {load_after:.1f} after):\n\n"
        f"- `{result['command']}`: exit {result['exit']}, {result['summary']}\n"
        f"- wall time {float(result['wall']):.0f} s (follows the load); CPU time of pytest and everything it "
        f"waited for {cpu:.0f} s, so at best {cpu / 2:.0f} s on two idle cores\n"
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--all", action="store_true", help='run everything (-m ""), as .ci/run does')
    parser.add_argument("--write", action="store_true", help=f"replace {HEADING!r} in bench/RESULTS.md")
    parser.add_argument("pytest_args", nargs="*", help="passed to pytest after --, e.g. -- -n 2")
    arguments = parser.parse_args()
    result = measure(arguments.pytest_args, arguments.all)
    text = section(result)
    print(result["tail"])
    print(text)
    if arguments.write:
        replace_section(HEADING, text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

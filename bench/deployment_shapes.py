"""The bundled honest solution graded 20 times in each deployment shape, beside a grading on the host.

    python bench/deployment_shapes.py [--runs 20] [--write]

Shapes (built as `tests/grader/sandbox/deployment_shapes.py` builds them for the suite, no Docker): a PID
namespace sharing the host's cgroups, a Docker-default container, and Gradescope's autograder (the bundle's
`run_autograder` as root in that container). Each run grades `random_blackjack` of
`submissions/classic_complete.py` on seed 1 (`check --format json`; Gradescope: `results.json`). A report
is lost when the grader exits non-zero, writes no report, or the problem's status is not the plain Linux
run's (`passed`). Meanwhile the host grades the same file's first two problems in a loop, and those reports
are counted the same way (before issue 46, a check in a PID namespace SIGKILLed the host's children).
`--write` replaces the `## Deployment shapes (issue 46)` section of bench/RESULTS.md.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import textwrap
import threading
import time
from datetime import date
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from results_section import replace_section  # noqa: E402

from tests.grader.sandbox.deployment_shapes import (  # noqa: E402
    DOCKER_DEFAULT,
    GRADESCOPE,
    GYMGRADE,
    HONEST,
    PID_NAMESPACE,
    gradescope_root,
    run_autograder_argv,
    run_in,
)

HEADING = "## Deployment shapes (issue 46)"
CHECK = [*GYMGRADE, "check", str(HONEST), "--only", "random_blackjack", "--seed", "1", "--format", "json"]
HOST_CHECK = [
    *GYMGRADE,
    "check",
    str(HONEST),
    "--only",
    "random_blackjack,blackjack",
    "--seed",
    "1",
    "--json",
]


def _check_delivered(shape: tuple[str, ...]) -> tuple[bool, str]:
    run = run_in(shape, CHECK)
    try:
        problems = json.loads(run.stdout)["problems"]
    except (json.JSONDecodeError, KeyError):
        return False, f"exit {run.returncode}, no report"
    return run.returncode == 0 and [p["status"] for p in problems] == ["passed"], f"exit {run.returncode}"


def _gradescope_delivered() -> tuple[bool, str]:
    with tempfile.TemporaryDirectory(prefix="bench-gradescope-") as directory:
        root = gradescope_root(Path(directory), HONEST.read_text(encoding="utf-8"))
        run = run_in(GRADESCOPE, run_autograder_argv(root))
        try:
            results = json.loads((root / "results" / "results.json").read_text(encoding="utf-8"))
        except (OSError, json.JSONDecodeError):
            return False, f"exit {run.returncode}, no results.json"
    statuses = [test["status"] for test in results["tests"] if test["name"].startswith("Problem 1")]
    return run.returncode == 0 and statuses == ["passed"], f"exit {run.returncode}"


SHAPES = {
    "PID namespace sharing the host's cgroups": lambda: _check_delivered(PID_NAMESPACE),
    "Docker-default container (check)": lambda: _check_delivered(DOCKER_DEFAULT),
    "Gradescope (run_autograder in that container)": _gradescope_delivered,
}


class HostGrading(threading.Thread):
    """Grades on the host in a loop until stopped; counts the reports it got and lost."""

    def __init__(self) -> None:
        super().__init__(daemon=True)
        self.stop = threading.Event()
        self.delivered = 0
        self.lost: list[str] = []

    def run(self) -> None:
        while not self.stop.is_set():
            run = subprocess.run(HOST_CHECK, cwd=ROOT, capture_output=True, text=True, check=False)
            try:
                statuses = [p["status"] for p in json.loads(run.stdout)["problems"]]
            except (json.JSONDecodeError, KeyError):
                statuses = []
            if run.returncode == 0 and statuses == ["passed", "passed"]:
                self.delivered += 1
            else:
                self.lost.append(f"exit {run.returncode}: {statuses}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=20)
    parser.add_argument("--write", action="store_true")
    args = parser.parse_args()
    load_before = os.getloadavg()[0]
    host = HostGrading()
    host.start()
    rows = []
    for shape, run_once in SHAPES.items():
        started = time.perf_counter()
        outcomes = [run_once() for _ in range(args.runs)]
        seconds = (time.perf_counter() - started) / args.runs
        lost = [detail for delivered, detail in outcomes if not delivered]
        rows.append((shape, args.runs, len(lost), seconds))
        print(f"{shape}: {args.runs} runs, {len(lost)} lost {lost[:3]}, {seconds:.1f} s per run", flush=True)
    host.stop.set()
    host.join()
    print(f"host grading beside them: {host.delivered} delivered, {len(host.lost)} lost {host.lost[:3]}")
    lines = [
        HEADING,
        "",
        textwrap.fill(
            f"`python bench/deployment_shapes.py --runs {args.runs}` on {date.today().isoformat()} "
            f"(2 shared cores, load {load_before:.1f} at the start): the honest solution's "
            "`random_blackjack`, seed 1, in each shape, while the host grades two problems of it in a loop. "
            "Lost: no report, a non-zero exit, or a status other than the plain run's `passed`. "
            "Before issue 46 (commit d2db536) a check in a PID namespace beside a live host job exited 137 "
            "with no report, and its sweep "
            "SIGKILLed the host job's processes.",
            110,
        ),
        "",
        "| shape | runs | lost reports | s per run |",
        "|---|---|---|---|",
        *(f"| {shape} | {runs} | {lost} | {seconds:.1f} |" for shape, runs, lost, seconds in rows),
        f"| host grading beside them | {host.delivered + len(host.lost)} | {len(host.lost)} | |",
        "",
    ]
    if args.write:
        replace_section(HEADING, "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()

"""Wall time of `gymgrade check`, this tree against a baseline tree, alternated A/B in one run.

    python bench/session.py --baseline /path/to/old/checkout [--fixed-pairs 6] [--full-pairs 2]

Every measurement is a fresh process, `python -c PROBE FILE WORKERS` with ``PYTHONPATH`` set to one tree
(the probe calls `grader.grading.grade.grade_submission` the way `gymgrade check` does: the practice seed,
``ALLOW_FALLBACK``, all enabled problems) and prints, from its own clock: the import of the grader, the first
and last result, and the return of the call; the bench adds the process's wall time. Runs alternate
baseline / this tree so that load from other jobs hits both alike; the figures are medians of the pairs.

* fixed cost: a file whose every function is missing (each check is a sandbox start and an import), on the
  machine's cores and on one worker;
* the lab-literal solution `submissions/classic_complete.py` on the machine's cores.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LAB_SOLUTION = ROOT / "submissions" / "classic_complete.py"
TRIVIAL = "import math\n"
PROBE = """
import json, sys, time
started = time.perf_counter()
from pathlib import Path
from grader.grading.grade import grade_submission
from grader.sandbox import IsolationPolicy
imported = time.perf_counter()
arrivals = []
report = grade_submission(
    Path(sys.argv[1]), workers=int(sys.argv[2]) or None, policy=IsolationPolicy.ALLOW_FALLBACK,
    on_progress=lambda result: arrivals.append(time.perf_counter()),
)
returned = time.perf_counter()
print(json.dumps({
    "import": imported - started, "first": arrivals[0] - imported, "last": arrivals[-1] - imported,
    "returned": returned - imported, "errors": report.grader_errors,
}))
"""


@dataclass(frozen=True)
class Run:
    """One probe process: its wall time and the probe's own figures (seconds)."""

    wall: float
    figures: dict[str, float]


def probe(tree: Path, submission: Path, workers: int) -> Run:
    """Grade ``submission`` in a fresh process importing the grader from ``tree``."""
    environment = {**os.environ, "PYTHONPATH": str(tree)}
    started = time.perf_counter()
    with tempfile.TemporaryDirectory() as cwd:
        completed = subprocess.run(
            [sys.executable, "-c", PROBE, str(submission), str(workers)],
            capture_output=True,
            text=True,
            cwd=cwd,
            env=environment,
            check=True,
        )
    wall = time.perf_counter() - started
    figures = json.loads(completed.stdout.strip().splitlines()[-1])
    if figures.pop("errors"):
        raise RuntimeError(f"{tree}: the grading reported grader errors: {completed.stdout}")
    return Run(wall, figures)


def alternate(baseline: Path, submission: Path, workers: int, pairs: int) -> list[tuple[Run, Run]]:
    """``pairs`` (baseline, this tree) measurements, alternating which of the two goes first."""
    measured = []
    for index in range(pairs):
        if index % 2:
            after = probe(ROOT, submission, workers)
            before = probe(baseline, submission, workers)
        else:
            before = probe(baseline, submission, workers)
            after = probe(ROOT, submission, workers)
        measured.append((before, after))
        print(f"  pair {index + 1}: before {before.wall:.2f} s, after {after.wall:.2f} s", flush=True)
    return measured


def table(title: str, measured: list[tuple[Run, Run]]) -> str:
    """Medians of the pairs, before / after / paired difference, per figure."""
    rows = [f"{title} ({len(measured)} pairs, medians)", "", "| figure | before | after | after - before |"]
    rows.append("|---|---|---|---|")
    names = {
        "wall": "process wall time",
        "import": "import of the grader",
        "first": "call to first result",
        "last": "call to last result",
        "returned": "call to return",
    }
    for key, name in names.items():
        before = [_figure(pair[0], key) for pair in measured]
        after = [_figure(pair[1], key) for pair in measured]
        difference = statistics.median(a - b for a, b in zip(after, before, strict=True))
        rows.append(
            f"| {name} | {statistics.median(before):.2f} s | {statistics.median(after):.2f} s | "
            f"{difference:+.2f} s |"
        )
    tails = [
        (_figure(b, "returned") - _figure(b, "last"), _figure(a, "returned") - _figure(a, "last"))
        for b, a in measured
    ]
    rows.append(
        f"| last result to return | {statistics.median(t[0] for t in tails):.2f} s | "
        f"{statistics.median(t[1] for t in tails):.2f} s | |"
    )
    return "\n".join(rows)


def _figure(run: Run, key: str) -> float:
    return run.wall if key == "wall" else run.figures[key]


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument(
        "--baseline", type=Path, required=True, help="A checkout of the code to compare with."
    )
    parser.add_argument(
        "--fixed-pairs", type=int, default=6, help="Pairs for the fixed cost (per worker count)."
    )
    parser.add_argument("--full-pairs", type=int, default=2, help="Pairs for the lab-literal solution.")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as directory:
        trivial = Path(directory) / "opengym.py"
        trivial.write_text(TRIVIAL)
        sections = []
        for workers, label in ((0, "the machine's cores"), (1, "one worker")):
            print(f"fixed cost, {label}:", flush=True)
            measured = alternate(args.baseline, trivial, workers, args.fixed_pairs)
            sections.append(table(f"Fixed cost: every function missing, {label}", measured))
        print("lab-literal solution:", flush=True)
        measured = alternate(args.baseline, LAB_SOLUTION, 0, args.full_pairs)
        sections.append(table("submissions/classic_complete.py, the machine's cores", measured))
    print(f"\nbaseline {args.baseline}, this tree {ROOT}, load average {os.getloadavg()[0]:.1f} at the end\n")
    print("\n\n".join(sections))


if __name__ == "__main__":
    main()

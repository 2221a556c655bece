"""Sandbox child start and student-module import times, for the interpreter running this script.

    python bench/interpreters.py [--runs N]                 # pyenv / any interpreter with gymgrade
    scripts/run python3 bench/interpreters.py [--runs N]    # Debian's python3 through the project .venv

Each run starts a fresh child in the strongest sandbox available (`Sandbox.functions`: the child starts and
imports a file of one empty function), then times, inside that child, the first import of each of the
course's student modules (`tqdm.auto`, `matplotlib.pyplot`, `scipy.stats`, `pandas`, `IPython.display`),
in that order (what one module shares with an earlier one is counted for the earlier; numpy and gymnasium
are imported by the harness before the submission, so they are part of the child's start).
Prints medians and maxima as a Markdown table for bench/RESULTS.md, `## Interpreter layouts`.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from grader.sandbox import Call, IsolationPolicy, OutcomeStatus, Sandbox, probe_isolation
from grader.sandbox.isolation.filesystem import python_paths

MODULES = ("tqdm.auto", "matplotlib.pyplot", "scipy.stats", "pandas", "IPython.display")
SOURCE = """
import importlib
import time


def nothing():
    return None


def import_times(names):
    times = {}
    for name in names:
        started = time.perf_counter()
        importlib.import_module(name)
        times[name] = time.perf_counter() - started
    return times
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5)
    runs = parser.parse_args().runs
    isolation = probe_isolation()
    starts: list[float] = []
    imports: dict[str, list[float]] = {name: [] for name in MODULES}
    with tempfile.TemporaryDirectory() as directory:
        submission = Path(directory) / "opengym.py"
        submission.write_text(SOURCE)
        for _ in range(runs):
            with Sandbox(
                submission, seed=0, policy=IsolationPolicy.ALLOW_FALLBACK, isolation=isolation
            ) as box:
                started = time.perf_counter()
                box.functions  # noqa: B018 -- starts the child and imports the file
                starts.append(time.perf_counter() - started)
                outcome = box.call(Call("import_times", (list(MODULES),), record_episodes=False))
                if outcome.status is not OutcomeStatus.OK or not isinstance(outcome.value, dict):
                    raise SystemExit(f"the import run failed: {outcome.status}: {outcome.message}")
                for name in MODULES:
                    imports[name].append(float(outcome.value[name]))
    paths = python_paths()
    load = os.getloadavg()[0]
    print(f"interpreter {paths.executable} (prefix {sys.prefix}); {runs} runs; load average {load:.1f}")
    print("full isolation" if isolation.full else f"missing: {[layer.name for layer in isolation.missing]}")
    print("| measured | median s | max s |\n|---|---|---|")
    print(f"| child start (empty file) | {statistics.median(starts):.3f} | {max(starts):.3f} |")
    for name in MODULES:
        median, worst = statistics.median(imports[name]), max(imports[name])
        print(f"| `import {name}` in the child | {median:.3f} | {worst:.3f} |")


if __name__ == "__main__":
    main()

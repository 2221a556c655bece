"""Editions (issue 23): calibrate sarsa0 (edition rl1, problem 7) with the real check, students simulated.

Every honest learner of `grader.testing.sarsa.HONEST` is regraded `--regrades` times and every typical
mistake of `MISTAKES` `--mistake-regrades` times, in-process (`grader.testing.simulation`), with rl1's
default configuration (two calls: N=50 with epsilon 0.2, N=20 with decay=True). Each regrade uses its own
seed, so the episodes, the exploration and the table differ every time. The figures: how often an honest
learner fails (the behaviour test's false-fail probability is 1e-6 per call, so expected 0), how often each
mistake is caught and named, the steps an honest learner takes per call, and the judge's time.

    python bench/editions_calibration.py      # 200 regrades per honest learner, 50 per mistake
    python bench/editions_calibration.py --regrades 25 --mistake-regrades 10 --workers 2
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor
from functools import cache
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from grader.checks.sarsa import SarsaConfig
from grader.config import load_config
from grader.editions.rl1 import RL1
from grader.testing import sarsa as students
from grader.testing.simulation import simulate_calls


@cache
def _settings() -> SarsaConfig:
    settings = load_config(RL1.default_config).problems["sarsa0"]
    assert isinstance(settings, SarsaConfig)
    return settings


def regrade(kind: str, name: str, seed: int) -> tuple[str, str, str, bool, int, float]:
    """(kind, name, status, the diagnosis named, steps played, judge seconds) of one regrade."""
    problem = RL1.registry.problem("sarsa0")
    settings = _settings()
    if kind == "honest":
        function, words = students.HONEST[name], "every update of your table is SARSA(0)'s"
    else:
        function, words = students.MISTAKES[name]
    functions = {"sarsa0": function, "epsilon_decay": students.epsilon_decay}
    records = simulate_calls(problem.check.plan(settings, {}), functions, seed)
    steps = sum(len(log.actions) for record in records for log in record.outcome.episodes)
    started = time.perf_counter()
    verdict = problem.check.judge(settings, records)
    return kind, name, verdict.status, words in verdict.feedback, steps, time.perf_counter() - started


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--regrades", type=int, default=200)
    parser.add_argument("--mistake-regrades", type=int, default=50)
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--only", default="", help="comma-separated student names (default: all)")
    parser.add_argument(
        "--first-seed", type=int, default=0, help="seed of the first regrade (to extend a run)"
    )
    arguments = parser.parse_args()
    chosen = set(filter(None, arguments.only.split(",")))
    honest = [name for name in students.HONEST if not chosen or name in chosen]
    mistakes = [name for name in students.MISTAKES if not chosen or name in chosen]
    first = arguments.first_seed
    jobs = [("honest", name, first + seed) for name in honest for seed in range(arguments.regrades)]
    jobs += [
        ("mistake", name, 10_000 + first + seed)
        for name in mistakes
        for seed in range(arguments.mistake_regrades)
    ]
    _settings()  # read once, before the workers fork
    started = time.perf_counter()
    with ProcessPoolExecutor(arguments.workers) as pool:
        results = list(pool.map(regrade, *zip(*jobs, strict=True), chunksize=4))
    print(
        f"sarsa0 calibration: {len(jobs)} regrades in {time.perf_counter() - started:.0f} s "
        f"({arguments.workers} workers)"
    )
    print("| student | regrades | verdicts | named | steps per regrade (median, max) | judge s (median) |")
    print("|---|---|---|---|---|---|")
    for kind, names in (("honest", honest), ("mistake", mistakes)):
        for name in names:
            rows = [row for row in results if row[0] == kind and row[1] == name]
            statuses = Counter(row[2] for row in rows)
            named = sum(row[3] for row in rows)
            steps = [row[4] for row in rows]
            seconds = statistics.median(row[5] for row in rows)
            verdicts = ", ".join(f"{count} {status}" for status, count in statuses.most_common())
            print(
                f"| {kind}: {name} | {len(rows)} | {verdicts} | {named} | "
                f"{statistics.median(steps):.0f}, {max(steps)} | {seconds:.2f} |"
            )


if __name__ == "__main__":
    main()

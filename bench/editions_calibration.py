"""Calibration of the current edition's (rl1) problems: the reference never falsely failed, every typical
mistake caught and named.

A registry of per-problem calibrations (`CALIBRATIONS`): each names the edition and problem, the honest
students (regraded `--regrades` times each on fresh seeds) and the typical mistakes (each regraded
`--mistake-regrades` times; "caught" means status `failed` AND the feedback names the mistake: it contains
the mistake's diagnosis). Students are simulated in-process (`grader.simulated_students.*`) and judged by the
real check with the edition's default configuration; Taxi episodes are real gymnasium episodes.

Another problem's calibration is one more `Calibration` in `CALIBRATIONS`.

    python bench/editions_calibration.py                      # every problem, 200 honest / 50 per mistake
    python bench/editions_calibration.py --only taxi --budget-minutes 10
    python bench/editions_calibration.py --only sarsa0 --student float32_table --regrades 50

With `--budget-minutes`, each problem's mistakes run first (50 of each), then the honest regrades until
the budget of that problem is spent; the counts printed are the ones actually run.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections import Counter
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from grader.lab.assignment import load_config
from grader.lab.editions import edition_of
from grader.simulated_students import epsilon_decay as epsilon_students
from grader.simulated_students import sarsa as sarsa_students
from grader.simulated_students import taxi_tables as taxi_students
from grader.simulated_students.simulation import simulate_calls

SEED_BASE = 23_000_000
"""Regrade k of a calibration uses seed SEED_BASE + k (fresh: no other bench uses these)."""


@dataclass(frozen=True)
class Calibration:
    """One problem's calibration.

    Attributes:
        edition: The edition whose pack declares the problem.
        problem: The problem id.
        honest: Honest students by name (each must pass every regrade).
        mistakes: Typical mistakes by name: the student and the words its feedback must contain.
        others: The student's other functions its calls need (sarsa0's `epsilon_decay`, say).
    """

    edition: str
    problem: str
    honest: Mapping[str, Callable[..., Any]]
    mistakes: Mapping[str, tuple[Callable[..., Any], str]]
    others: Mapping[str, Callable[..., Any]] = field(default_factory=dict)


CALIBRATIONS: dict[str, Calibration] = {
    "epsilon_decay": Calibration("rl1", "epsilon_decay", epsilon_students.HONEST, epsilon_students.MISTAKES),
    "taxi": Calibration("rl1", "taxi", {"greedy_1000": taxi_students.honest}, taxi_students.MISTAKES),
    "sarsa0": Calibration(
        "rl1",
        "sarsa0",
        sarsa_students.HONEST,
        sarsa_students.MISTAKES,
        others={"epsilon_decay": sarsa_students.epsilon_decay},
    ),
}
"""Every calibrated problem of the later editions, by a name `--only` takes."""


@dataclass
class Tally:
    """What a student's regrades gave."""

    runs: int = 0
    statuses: Counter[str] | None = None
    named: int = 0
    seconds: float = 0.0

    def line(self) -> str:
        each = self.seconds / max(self.runs, 1)
        return f"{self.runs} regrades, {dict(self.statuses or {})}, named {self.named}, {each:.2f} s each"


def regrade(calibration: Calibration, student: Callable[..., Any], seeds: range, words: str | None) -> Tally:
    """Grade one simulated student on each seed with the real check; count statuses and named diagnoses."""
    edition = edition_of(calibration.edition)
    problem = edition.registry.problem(calibration.problem)
    settings = problem.settings(load_config(edition.default_config))
    calls = problem.check.plan(settings, {}, 0)
    tally = Tally(statuses=Counter())
    started = time.perf_counter()
    for seed in seeds:
        records = simulate_calls(calls, {**calibration.others, calibration.problem: student}, seed)
        verdict = problem.check.judge(settings, records)
        assert tally.statuses is not None
        tally.statuses[verdict.status] += 1
        tally.runs += 1
        if words is not None and verdict.status == "failed" and words in verdict.feedback:
            tally.named += 1
    tally.seconds = time.perf_counter() - started
    return tally


def calibrate(
    name: str,
    regrades: int,
    mistake_regrades: int,
    budget_seconds: float | None,
    caps: Mapping[str, int] | None = None,
    parts: tuple[str, ...] = ("mistakes", "honest"),
    first_seed: int = SEED_BASE,
    students: frozenset[str] = frozenset(),
) -> bool:
    """Run one calibration and print it; True when no honest regrade failed and every mistake was named.

    `caps` lowers the regrades of named mistakes (a slow one under a loaded machine); `students`, when not
    empty, keeps only the honest students and mistakes it names; the printed counts say what ran.
    """
    calibration = CALIBRATIONS[name]
    chosen = students or frozenset(calibration.mistakes) | frozenset(calibration.honest)
    started, cpu = time.perf_counter(), time.process_time()
    ok = True
    print(f"## {calibration.edition} {calibration.problem}")
    for student, (function, words) in calibration.mistakes.items() if "mistakes" in parts else ():
        if student not in chosen:
            continue
        count = min(mistake_regrades, (caps or {}).get(student, mistake_regrades))
        tally = regrade(calibration, function, range(first_seed, first_seed + count), words)
        ok &= tally.named == tally.runs == count
        print(f"  mistake {student:<22} {tally.line()}")
    for student, function in calibration.honest.items() if "honest" in parts else ():
        if student not in chosen:
            continue
        done = Tally(statuses=Counter())
        seed = first_seed
        while done.runs < regrades:
            if budget_seconds is not None and time.perf_counter() - started > budget_seconds:
                break
            chunk = regrade(calibration, function, range(seed, seed + min(10, regrades - done.runs)), None)
            seed += chunk.runs
            done.runs += chunk.runs
            done.seconds += chunk.seconds
            assert done.statuses is not None and chunk.statuses is not None
            done.statuses.update(chunk.statuses)
        assert done.statuses is not None
        ok &= done.statuses["passed"] == done.runs
        print(f"  honest  {student:<22} {done.line()}")
    wall, used = time.perf_counter() - started, time.process_time() - cpu
    print(f"  ({wall:.0f} s wall, {used:.0f} s CPU for {name}; seeds from {first_seed})")
    return ok


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", choices=tuple(CALIBRATIONS), action="append", default=None)
    parser.add_argument("--regrades", type=int, default=200, help="regrades per honest student")
    parser.add_argument("--mistake-regrades", type=int, default=50, help="regrades per mistake")
    parser.add_argument(
        "--budget-minutes", type=float, default=None, help="per problem: stop the honest regrades after this"
    )
    parser.add_argument(
        "--cap", action="append", default=[], metavar="MISTAKE=N", help="fewer regrades of one mistake"
    )
    parser.add_argument(
        "--part", choices=("mistakes", "honest"), default=None, help="run only this part (default: both)"
    )
    parser.add_argument(
        "--first-seed", type=int, default=SEED_BASE, help="continue a run: the seed of the first regrade"
    )
    parser.add_argument(
        "--student", action="append", default=[], metavar="NAME", help="only this honest student or mistake"
    )
    args = parser.parse_args()
    parts = ("mistakes", "honest") if args.part is None else (args.part,)
    budget = None if args.budget_minutes is None else 60 * args.budget_minutes
    caps = {name: int(count) for name, _, count in (cap.partition("=") for cap in args.cap)}
    results = [
        calibrate(
            name,
            args.regrades,
            args.mistake_regrades,
            budget,
            caps,
            parts,
            args.first_seed,
            frozenset(args.student),
        )
        for name in args.only or CALIBRATIONS
    ]
    print("all calibrations held" if all(results) else "SOME CALIBRATION FAILED")
    return 0 if all(results) else 1


if __name__ == "__main__":
    sys.exit(main())

"""Editions (issue 23): calibrate epsilon_decay, time it in the real sandbox, time edition detection.

1. Calibration, in-process with the real check (`grader.simulated_students.epsilon_decay` students run by
   `grader.simulated_students.simulation`): every honest way of writing the decay regraded `--regrades` times
   (with the optional exponential part off and on), every typical mistake `--mistake-regrades` times. The
   function is pure and the grid fixed, so every regrade gives the same verdict: the figures show that nothing
   in the verdict depends on the seed, and that the tolerance admits honest rounding and no mistake.
2. The real sandbox: the edition's samples graded on epsilon_decay only (`grade_files`, one session).
3. Detection: `detect_edition` on each edition's template and reference, and on a 1 MB source.

    python bench/editions.py                     # 200 regrades per honest student, 50 per mistake
    python bench/editions.py --regrades 20 --no-sandbox
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from grader.grading.grade import grade_files
from grader.grading.plan import GradingPlan
from grader.lab.assignment import load_config
from grader.lab.checks.epsilon_decay import EpsilonDecayConfig
from grader.lab.editions import EDITIONS
from grader.lab.editions.detection import detect_edition
from grader.lab.editions.rl1 import RL1
from grader.sandbox import IsolationPolicy
from grader.simulated_students import epsilon_decay as students
from grader.simulated_students import taxi_tables
from grader.simulated_students.simulation import simulate_calls

SAMPLES = Path(__file__).resolve().parents[1] / "submissions" / "editions"


def _settings(**updates: Any) -> EpsilonDecayConfig:
    settings = load_config(RL1.default_config).problems["epsilon_decay"]
    assert isinstance(settings, EpsilonDecayConfig)
    return settings.model_copy(update=updates)


def _statuses(function: Any, regrades: int, **updates: Any) -> Counter[str]:
    problem = RL1.registry.problem("epsilon_decay")
    settings = _settings(**updates)
    found: Counter[str] = Counter()
    for seed in range(regrades):
        records = simulate_calls(problem.check.plan(settings, {}, 0), {"epsilon_decay": function}, seed)
        found[problem.check.judge(settings, records).status] += 1
    return found


def calibrate(regrades: int, mistake_regrades: int) -> None:
    print(
        f"epsilon_decay calibration: {regrades} regrades per honest student, {mistake_regrades} per mistake"
    )
    for name, function in students.HONEST.items():
        print(f"  honest {name:<22} linear only: {dict(_statuses(function, regrades))}")
    print(
        f"  honest {'formula':<22} with exp:    {dict(_statuses(students.honest, regrades, grade_exp=True))}"
    )
    for name, (function, _) in students.MISTAKES.items():
        print(f"  mistake {name:<21} {dict(_statuses(function, mistake_regrades))}")
    print(
        f"  mistake {'exp_off_by_one':<21} with exp: {dict(_statuses(students.exp_off_by_one, mistake_regrades, grade_exp=True))}"  # noqa: E501
    )


def calibrate_taxi(regrades: int, mistake_regrades: int) -> None:
    """The two-table taxi: honest greedy play on fresh seeds, and each mistake (in-process, real check)."""
    problem = RL1.registry.problem("taxi")
    settings = load_config(RL1.default_config).problems["taxi"]
    calls = problem.check.plan(settings, {}, 0)

    def statuses(function: Any, count: int) -> Counter[str]:
        found: Counter[str] = Counter()
        for seed in range(count):
            records = simulate_calls(calls, {"taxi": function}, 1_000_003 * seed + 7)
            found[problem.check.judge(settings, records).status] += 1
        return found

    started = time.perf_counter()
    honest = statuses(taxi_tables.honest, regrades)
    elapsed = time.perf_counter() - started
    each = elapsed / max(regrades, 1)
    print(f"taxi(q_table, q_table_decay): honest {dict(honest)} in {regrades} regrades ({each:.2f} s each)")
    for name, (function, _) in taxi_tables.MISTAKES.items():
        print(f"  mistake {name:<21} {dict(statuses(function, mistake_regrades))}")


def sandbox() -> None:
    paths = [*sorted(SAMPLES.glob("epsilon_decay_*.py")), RL1.reference, RL1.template]
    plan = GradingPlan.load(RL1.default_config, ["epsilon_decay"])
    started = time.perf_counter()
    reports = grade_files(paths, plan, seed=1, workers=2, policy=IsolationPolicy.ALLOW_FALLBACK)
    elapsed = time.perf_counter() - started
    print(
        f"real sandbox: {len(paths)} files graded on epsilon_decay in {elapsed:.1f} s (one session, 2 workers)"  # noqa: E501
    )
    for path, report in zip(paths, reports, strict=True):
        (result,) = report.problems
        print(f"  {path.name:<36} {result.status:<8} {result.timings.wall_seconds:.2f} s wall")


def detection() -> None:
    print("detection (statically, in the parent):")
    for edition in EDITIONS.values():
        for path in (edition.template, edition.reference):
            started = time.perf_counter()
            found = detect_edition(path)
            print(
                f"  {edition.name:<8} {path.name:<28} -> {found.edition.name:<8} {1000 * (time.perf_counter() - started):.1f} ms"  # noqa: E501
            )
    with tempfile.TemporaryDirectory() as directory:
        large = Path(directory) / "opengym.py"
        body = RL1.reference.read_text(encoding="utf-8")
        large.write_text(body + "\n# padding\n" * ((1_000_000 - len(body)) // 11), encoding="utf-8")
        times = []
        for _ in range(5):
            started = time.perf_counter()
            detect_edition(large)
            times.append(time.perf_counter() - started)
        print(
            f"  a {large.stat().st_size:,}-byte source: median {1000 * statistics.median(times):.1f} ms of 5"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--regrades", type=int, default=200)
    parser.add_argument("--mistake-regrades", type=int, default=50)
    parser.add_argument("--taxi-regrades", type=int, default=200)
    parser.add_argument("--no-sandbox", action="store_true")
    parser.add_argument("--only-taxi", action="store_true")
    args = parser.parse_args()
    if args.only_taxi:
        calibrate_taxi(args.taxi_regrades, args.mistake_regrades)
        return
    calibrate(args.regrades, args.mistake_regrades)
    calibrate_taxi(args.taxi_regrades, args.mistake_regrades)
    detection()
    if not args.no_sandbox:
        sandbox()


if __name__ == "__main__":
    main()

"""Calibrate the checks: regrade the reference and every typical mistake many times with fresh seeds.

Every regrade runs the problem's planned calls in-process (`grader.simulated_students.simulation`: gymnasium
envs, episodes logged like the sandbox logs them, judged as played) and judges them with the real check.
Prints, per check, the reference's false-fail rate and each mistake's detection rate, and the CartPole rule
analysis (the velocity policy's length distribution; pass probability of worse policies).

    python bench/calibrate.py            # full: 1000 regrades per cheap problem, see --help
    python bench/calibrate.py --quick    # a smoke run in about a minute
"""

from __future__ import annotations

import argparse
import dataclasses
import gc
import json
import math
import multiprocessing
import random
import sys
import time
import zlib
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from grader.lab.assignment import load_config
from grader.lab.checks.base import ProblemId, Status
from grader.lab.checks.cartpole import CartpoleConfig
from grader.lab.checks.taxi import TaxiConfig
from grader.lab.problems import PROBLEMS
from grader.lab.settings import ProblemConfig
from grader.lab.stats import normal_cdf
from grader.simulated_students.behaviours import MISTAKES, REFERENCE, velocity_policy
from grader.simulated_students.simulation import StudentFunction, function_infos, simulate_calls

CHEAP: tuple[ProblemId, ...] = ("random_blackjack", "blackjack", "cartpole", "car")


@dataclass(frozen=True)
class Job:
    """One regrade of one behaviour."""

    behaviour: str
    problem: ProblemId
    expected: Status
    feedback: str
    seed: int
    index: int


@dataclass(frozen=True)
class Result:
    """What one regrade produced."""

    behaviour: str
    problem: ProblemId
    expected: Status
    status: Status
    matched: bool
    feedback: str
    seconds: float


def _behaviours() -> dict[str, tuple[ProblemId, dict[str, StudentFunction], Status, str]]:
    table: dict[str, tuple[ProblemId, dict[str, StudentFunction], Status, str]] = {
        f"reference:{problem}": (problem, functions, "passed", "") for problem, functions in REFERENCE.items()
    }
    for mistake in MISTAKES:
        table[mistake.name] = (mistake.problem, mistake.functions, mistake.status, mistake.feedback)
    return table


_CONFIG: dict[ProblemId, ProblemConfig] = {}


def _init_worker(taxi_episodes: int | None) -> None:
    # A regrade builds millions of small objects; the cyclic GC rescanning them makes judging 4x slower.
    gc.disable()
    config = load_config()
    _CONFIG.update(config.problems)
    if taxi_episodes is not None:
        taxi = config.problems["taxi"]
        assert isinstance(taxi, TaxiConfig)
        _CONFIG["taxi"] = taxi.model_copy(update={"episodes_per_scenario": taxi_episodes})


def run_job(job: Job) -> Result:
    """Simulate and judge one regrade."""
    problem, functions, _, _ = _behaviours()[job.behaviour]
    config = _CONFIG[problem]
    if isinstance(config, TaxiConfig):
        functions = {
            name: partial(function, episodes=config.episodes_per_scenario)
            for name, function in functions.items()
        }
    check = PROBLEMS.problem(problem).check
    started = time.perf_counter()
    calls = check.plan(config, function_infos(functions), 0)
    records = simulate_calls(calls, functions, job.seed, fast=problem in ("random_blackjack", "blackjack"))
    verdict = check.judge(config, records)
    matched = verdict.status == job.expected and job.feedback in verdict.feedback
    del records
    gc.collect()
    return Result(
        job.behaviour,
        problem,
        job.expected,
        verdict.status,
        matched,
        verdict.feedback,
        time.perf_counter() - started,
    )


def _seed(name: str, index: int) -> int:
    return zlib.crc32(name.encode()) * 1_000_003 + index


def plan_jobs(
    problems: Sequence[ProblemId], regrades: int, taxi_regrades: int, mistake_regrades: int, start: int = 0
) -> list[Job]:
    """Regrades of the reference (per problem) and of each mistake behaviour, numbered from `start`."""
    jobs = []
    for name, (problem, _, status, feedback) in _behaviours().items():
        if problem not in problems:
            continue
        if name.startswith("reference:"):
            count = taxi_regrades if problem == "taxi" else regrades
        else:
            count = min(mistake_regrades, taxi_regrades) if problem == "taxi" else mistake_regrades
        indices = range(start, start + count)
        jobs += [Job(name, problem, status, feedback, _seed(name, index), index) for index in indices]
    # Round-robin over behaviours (Taxi first: its regrades are the longest), so a partial run covers all.
    return sorted(jobs, key=lambda job: (job.problem != "taxi", job.index, job.behaviour))


def calibration_table(results: Sequence[Result]) -> str:
    """Markdown: per behaviour, regrades, expected status, how often it was given, seconds per regrade."""
    by_name: dict[str, list[Result]] = {}
    for result in results:
        by_name.setdefault(result.behaviour, []).append(result)
    lines = [
        "| check | behaviour | expected | regrades | as expected | rate | other outcomes | s/regrade |",
        "|---|---|---|---:|---:|---:|---|---:|",
    ]
    for name, group in sorted(
        by_name.items(), key=lambda item: (item[1][0].problem, not item[0].startswith("ref"))
    ):
        matched = sum(result.matched for result in group)
        others = Counter(result.status for result in group if not result.matched)
        other_text = ", ".join(f"{status} x{count}" for status, count in others.items()) or "-"
        label = "reference (false-fail rate = 1 - rate)" if name.startswith("reference:") else name
        seconds = sum(result.seconds for result in group) / len(group)
        lines.append(
            f"| {group[0].problem} | {label} | {group[0].expected} | {len(group)} | {matched} | "
            f"{matched / len(group):.3f} | {other_text} | {seconds:.2f} |"
        )
    return "\n".join(lines)


def _lengths(policy: Callable[[Any, random.Random], int], episodes: int, seed: int) -> np.ndarray:
    env = gymnasium.make("CartPole-v0", disable_env_checker=True)
    chooser = random.Random(seed)
    lengths = np.empty(episodes, dtype=np.int64)
    observation, _ = env.reset(seed=seed)
    for index in range(episodes):
        if index:
            observation, _ = env.reset()
        steps, done = 0, False
        while not done:
            observation, _, terminated, truncated, _ = env.step(policy(observation, chooser))
            steps, done = steps + 1, terminated or truncated
        lengths[index] = steps
    return lengths


def _noisy(epsilon: float) -> Callable[[Any, random.Random], int]:
    def policy(observation: Any, chooser: random.Random) -> int:
        return chooser.randrange(2) if chooser.random() < epsilon else velocity_policy(observation)

    return policy


CARTPOLE_POLICIES: dict[str, Callable[[Any, random.Random], int]] = {
    "velocity (the lab's policy)": lambda observation, _chooser: velocity_policy(observation),
    "velocity, 25% random actions": _noisy(0.25),
    "velocity, 50% random actions": _noisy(0.5),
    "pole angle only": lambda observation, _chooser: 1 if observation[2] > 0 else 0,
    "random actions": lambda _observation, chooser: chooser.randrange(2),
}


def cartpole_rule_table(config: CartpoleConfig, episodes: int) -> str:
    """Markdown: each policy's episode-length distribution and the probability the 100-call rule passes it."""
    lines = [
        f"Rule: {config.calls} calls, mean >= {config.min_mean_steps:g} and every run >= {config.min_steps}; "
        f"{episodes} simulated episodes per policy.",
        "",
        "| policy | mean | sd | min | P(run < min_steps) (95% upper) | P(mean < bar) (normal) | pass "
        "probability |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    for index, (name, policy) in enumerate(CARTPOLE_POLICIES.items()):
        lengths = _lengths(policy, episodes, seed=10_000 + index)
        short = int((lengths < config.min_steps).sum())
        # Clopper-Pearson-style one-sided 95% upper bound on P(run < min_steps); 3/N when none was seen.
        upper = (
            1 - 0.05 ** (1 / episodes)
            if short == 0
            else min(1.0, (short + 2 * math.sqrt(short) + 2) / episodes)
        )
        mean, sd = float(lengths.mean()), float(lengths.std(ddof=1))
        low_mean = (
            normal_cdf((config.min_mean_steps - mean) / (sd / math.sqrt(config.calls)))
            if sd > 0
            else float(mean < config.min_mean_steps)
        )
        batches = lengths[: episodes - episodes % config.calls].reshape(-1, config.calls)
        passing = float(
            (
                (batches.mean(axis=1) >= config.min_mean_steps) & (batches.min(axis=1) >= config.min_steps)
            ).mean()
        )
        lines.append(
            f"| {name} | {mean:.1f} | {sd:.1f} | {int(lengths.min())} | {short}/{episodes} (<= {upper:.1e}) "
            "| "
            f"{low_mean:.1e} | {passing:.3f} of {len(batches)} batches |"
        )
    lines.append("")
    lines.append(
        "False-fail probability of the rule for the lab's policy <= "
        "1 - (1 - upper)^calls + P(mean < bar) (first row)."
    )
    return "\n".join(lines)


def _length_from(env: Any, state: np.ndarray, policy: Callable[[Any], int]) -> tuple[int, bool]:
    env.reset(seed=0)
    env.unwrapped.state = state.copy()
    observation = np.array(state, dtype=np.float32)
    steps, terminated, truncated = 0, False, False
    while not (terminated or truncated):
        observation, _, terminated, truncated, _ = env.step(policy(observation))
        steps += 1
    return steps, terminated


def worst_start_table(grid: int, refinements: int) -> str:
    """Markdown: the reference policies' worst episodes over their whole (deterministic) start boxes.

    Both games are deterministic once started: CartPole starts uniformly in [-0.05, 0.05]^4, MountainCar
    at a position uniform in [-0.6, -0.4] at rest. The worst start bounds every run the rule can see.
    """
    chooser = np.random.default_rng(2026)
    cartpole = gymnasium.make("CartPole-v0", disable_env_checker=True)
    axis = np.linspace(-0.05, 0.05, grid)
    starts = np.array(np.meshgrid(axis, axis, axis, axis)).reshape(4, -1).T
    lengths = [(_length_from(cartpole, start, velocity_policy)[0], tuple(start)) for start in starts]
    worst = sorted(lengths)[:5]
    for _ in range(refinements):
        _, centre = worst[int(chooser.integers(len(worst)))]
        start = np.clip(np.array(centre) + chooser.normal(0, 0.1 / grid, 4), -0.05, 0.05)
        worst = sorted([*worst, (_length_from(cartpole, start, velocity_policy)[0], tuple(start))])[:5]
    car = gymnasium.make("MountainCar-v0", disable_env_checker=True)
    car_runs = [
        _length_from(car, np.array([position, 0.0]), lambda o: 2 if o[1] >= 0 else 0)
        for position in np.linspace(-0.6, -0.4, 2001)
    ]
    return "\n".join(
        [
            "| policy | start states tried | shortest / longest episode | every run reached the goal |",
            "|---|---:|---:|---|",
            f"| CartPole velocity policy | {len(starts)} grid + {refinements} local | shortest {worst[0][0]} "
            "| - |",
            f"| MountainCar velocity policy | 2001 positions | longest {max(n for n, _ in car_runs)} | "
            f"{all(done for _, done in car_runs)} |",
        ]
    )


def _mode(arguments: argparse.Namespace) -> str:
    counts = (
        arguments.regrades,
        arguments.taxi_regrades,
        arguments.mistake_regrades,
        arguments.cartpole_episodes,
    )
    if arguments.quick:
        return "quick"
    return "full" if all(count is None for count in counts) and arguments.start == 0 else "custom"


def _chosen(value: int | None, default: int) -> int:
    return default if value is None else value


def main(argv: Sequence[str] | None = None) -> int:
    """Run the calibration and print its tables."""
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--quick", action="store_true", help="a smoke run: few regrades, short Taxi runs")
    parser.add_argument("--only", default=",".join((*CHEAP, "taxi")), help="comma-separated problem ids")
    parser.add_argument("--regrades", type=int, help="reference regrades per cheap problem (full: 1000)")
    parser.add_argument("--taxi-regrades", type=int, help="reference regrades of Taxi (full: 10)")
    parser.add_argument("--mistake-regrades", type=int, help="regrades per mistake behaviour (full: 50)")
    parser.add_argument(
        "--cartpole-episodes", type=int, help="episodes per policy for the rule analysis (full: 20000)"
    )
    parser.add_argument("--start", type=int, default=0, help="first regrade index (seeds differ per index)")
    parser.add_argument(
        "--no-rules", action="store_true", help="skip the CartPole rule and worst-start analyses"
    )
    parser.add_argument("--workers", type=int, default=multiprocessing.cpu_count())
    parser.add_argument(
        "--log", help="also append every regrade's result to this JSON-lines file as it finishes"
    )
    parser.add_argument(
        "--table-from", help="print the tables from a --log file (e.g. of an interrupted run)"
    )
    arguments = parser.parse_args(argv)
    quick = arguments.quick
    regrades = _chosen(arguments.regrades, 10 if quick else 1000)
    taxi_regrades = _chosen(arguments.taxi_regrades, 1 if quick else 10)
    mistake_regrades = _chosen(arguments.mistake_regrades, 3 if quick else 50)
    cartpole_episodes = _chosen(arguments.cartpole_episodes, 2000 if quick else 20_000)
    taxi_episodes = 1000 if quick else None
    problems = [problem for problem in arguments.only.split(",") if problem]
    unknown = [problem for problem in problems if problem not in PROBLEMS.ids]
    if unknown:
        parser.error(f"unknown problem ids {unknown}; expected some of {list(PROBLEMS.ids)}")
    jobs = plan_jobs(problems, regrades, taxi_regrades, mistake_regrades, arguments.start)  # type: ignore[arg-type]
    if arguments.table_from:
        results = [
            Result(**json.loads(line)) for line in Path(arguments.table_from).read_text().splitlines() if line
        ]
        print(f"## Calibration (from {arguments.table_from}: {len(results)} regrades)\n")
    else:
        started = time.perf_counter()
        results = []
        log = Path(arguments.log) if arguments.log else None
        if log:
            log.write_text("", encoding="utf-8")
        with multiprocessing.Pool(arguments.workers, _init_worker, (taxi_episodes,)) as pool:
            for result in pool.imap_unordered(run_job, jobs, chunksize=1):
                results.append(result)
                if log:
                    with log.open("a", encoding="utf-8") as stream:
                        stream.write(json.dumps(dataclasses.asdict(result)) + "\n")
        elapsed = time.perf_counter() - started
        print(
            f"## Calibration ({_mode(arguments)} mode: {len(results)} regrades in {elapsed:.0f} s, "
            f"{arguments.workers} workers{', Taxi with 1000 episodes per scenario' if quick else ''})\n"
        )
    print(calibration_table(results))
    unexpected = [result for result in results if not result.matched]
    for result in unexpected[:10]:
        print(f"\nUNEXPECTED {result.behaviour} -> {result.status}: {result.feedback}")
    if "cartpole" in problems and not arguments.no_rules and not arguments.table_from:
        cartpole = load_config().problems["cartpole"]
        assert isinstance(cartpole, CartpoleConfig)
        print("\n### CartPole rule\n")
        print(cartpole_rule_table(cartpole, cartpole_episodes))
        print("\n### Worst start states\n")
        print(worst_start_table(grid=5 if quick else 9, refinements=200 if quick else 2000))
    return 1 if unexpected else 0


if __name__ == "__main__":
    raise SystemExit(main())

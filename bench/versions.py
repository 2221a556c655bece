"""Every version of the lab (issue 14): the v1 oracles' calibration and the compat layer's API detection.

Prints Markdown for `bench/RESULTS.md` (## Every version of the lab):

1. the exact `sab=True` Blackjack oracles against Monte Carlo games of gymnasium's own `Blackjack-v1`;
2. how v1 games would fare against the v0 oracles (why each game gets its own);
3. the velocity policy's episode lengths in CartPole-v1 and the lab's bar's false-fail probability;
4. regrades of the v1 references and of the new mistakes through the real checks (as bench/calibrate.py);
5. per sample submission: the API it is written for (verdicts.toml) and the API grader.compat detects.

    python bench/versions.py            # full: about 15 minutes on 2 cores
    python bench/versions.py --quick    # a smoke run
"""

from __future__ import annotations

import argparse
import math
import multiprocessing
import sys
import time
import tomllib
from collections.abc import Sequence
from pathlib import Path

import gymnasium
import numpy as np
from scipy import stats

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from calibrate import Job, Result, _init_worker, _seed, calibration_table, run_job

from grader.compat.detection import detect_api
from grader.lab.assignment import load_config
from grader.lab.stats import binomial_acceptance
from grader.simulated_students.behaviours import MISTAKES, velocity_policy
from reference.oracles import random_policy_outcome, threshold_policy_outcome

SUBMISSIONS = Path(__file__).resolve().parents[1] / "submissions"
THRESHOLDS = (12, 13, 14, 20)
NEW_BEHAVIOURS = (
    "random_blackjack_v1",
    "blackjack_v1",
    "cartpole_v1",
    "cartpole_random_step_first",
    "car_random_step_first",
    "cartpole_counted_from_one",
    "taxi_ignores_truncated",
)
REFERENCES = ("random_blackjack_v1", "blackjack_v1", "cartpole_v1")


def _win_rate(games: int, seed: int, threshold: int | None) -> float:
    env = gymnasium.make("Blackjack-v1", sab=True, disable_env_checker=True).unwrapped
    chooser = np.random.default_rng(seed + 1)
    wins = 0
    for game in range(games):
        observation, _ = env.reset() if game else env.reset(seed=seed)
        terminated, reward = False, 0.0
        while not terminated:
            hit = int(chooser.integers(2)) if threshold is None else int(observation[0] <= threshold)
            observation, reward, terminated, _, _ = env.step(hit)
        wins += reward > 0
    return wins / games


def oracle_table(games: int) -> str:
    """Exact sab=True win probabilities next to Monte Carlo games of gymnasium's Blackjack-v1."""
    lines = [
        f"| policy | exact win (sab=True) | Monte Carlo ({games:,} games) | z | exact win (sab=False) |",
        "|---|---:|---:|---:|---:|",
    ]
    policies: list[tuple[str, int | None]] = [("random", None)] + [
        (f"draw while <= {n}", n) for n in THRESHOLDS
    ]
    for index, (name, threshold) in enumerate(policies):
        if threshold is None:
            exact, classic = random_policy_outcome(sab=True).win, random_policy_outcome().win
        else:
            exact = threshold_policy_outcome(threshold, sab=True).win
            classic = threshold_policy_outcome(threshold).win
        measured = _win_rate(games, 1000 + index, threshold)
        z = (measured - exact) / math.sqrt(exact * (1 - exact) / games)
        lines.append(f"| {name} | {exact:.6f} | {measured:.6f} | {z:+.2f} | {classic:.6f} |")
    return "\n".join(lines)


def cross_oracle_table(games: int, alpha: float) -> str:
    """Probability that 10 000 games of one rule set pass the other rule set's exact acceptance interval."""
    lines = [
        "| policy | v1 games pass the v0 interval | v0 games pass the v1 interval |",
        "|---|---:|---:|",
    ]
    for name, v0, v1 in [("random", random_policy_outcome().win, random_policy_outcome(sab=True).win)] + [
        (f"draw while <= {n}", threshold_policy_outcome(n).win, threshold_policy_outcome(n, sab=True).win)
        for n in THRESHOLDS
    ]:
        cells = []
        for played, judged in ((v1, v0), (v0, v1)):
            interval = binomial_acceptance(games, judged, alpha)
            cells.append(
                stats.binom.cdf(interval.high, games, played)
                - stats.binom.cdf(interval.low - 1, games, played)
            )
        lines.append(f"| {name} | {cells[0]:.4f} | {cells[1]:.4f} |")
    return "\n".join(lines)


def cartpole_v1_table(episodes: int, min_mean: float, min_steps: int, calls: int) -> str:
    """The velocity policy's episode lengths in CartPole-v1 and the bar's false-fail probability."""
    env = gymnasium.make("CartPole-v1", disable_env_checker=True)
    lengths = np.empty(episodes, dtype=np.int64)
    for index in range(episodes):
        observation, _ = env.reset(seed=index)
        steps, done = 0, False
        while not done:
            observation, _, terminated, truncated, _ = env.step(velocity_policy(observation))
            steps, done = steps + 1, terminated or truncated
        lengths[index] = steps
    mean, sd = float(lengths.mean()), float(lengths.std(ddof=1))
    below = stats.norm.cdf((min_mean - mean) / (sd / math.sqrt(calls)))
    return (
        f"CartPole-v1, velocity policy, {episodes:,} episodes (seeds 0..{episodes - 1}): mean {mean:.1f}, "
        f"sd {sd:.1f}, shortest {int(lengths.min())}, longest {int(lengths.max())}, "
        f"{float((lengths > 200).mean()):.1%} longer than 200 steps, {float((lengths == 500).mean()):.1%} "
        f"reach the 500-step limit, {int((lengths < min_steps).sum())} shorter than {min_steps}. The mean of "
        f"{calls} runs falls below {min_mean:g} with probability {below:.1e} (normal approximation)."
    )


def regrade_table(regrades: int, mistake_regrades: int, workers: int) -> str:
    """Regrades of the v1 references and the new mistakes through the real checks."""
    behaviours = {mistake.name: mistake for mistake in MISTAKES}
    jobs = []
    for name in NEW_BEHAVIOURS:
        mistake = behaviours[name]
        count = regrades if name in REFERENCES else mistake_regrades
        if name == "blackjack_v1":
            count = max(regrades // 2, 1)  # four 10 000-game calls per regrade
        jobs += [
            Job(name, mistake.problem, mistake.status, mistake.feedback, _seed(name, index), index)
            for index in range(count)
        ]
    with multiprocessing.Pool(workers, initializer=_init_worker, initargs=(None,)) as pool:
        results: list[Result] = pool.map(run_job, jobs, chunksize=1)
    return calibration_table(results)


def api_table() -> str:
    """Per sample: the API it is written for and what the compat layer detects (module and functions)."""
    samples = tomllib.loads((SUBMISSIONS / "verdicts.toml").read_text(encoding="utf-8"))["sample"]
    lines = [
        "| sample | written for | detected (module) | functions | as intended |",
        "|---|---|---|---|---|",
    ]
    agree = 0
    for sample in samples:
        detection = detect_api((SUBMISSIONS / sample["file"]).read_text(encoding="utf-8"))
        module = detection.module
        found = "mixed" if module.conflict else (module.api.value if module.api else "none (classic served)")
        decided = [
            scope.decision.api.value if scope.decision.api else "both (error)" for scope in detection.scopes
        ]
        if decided and len(set(decided)) == 1:
            functions = f"all {len(decided)}: {decided[0]}"
        else:
            functions = ", ".join(
                f"{scope.name}: {api}" for scope, api in zip(detection.scopes, decided, strict=True)
            )
        intended = sample["api"]
        # gymnasium code never goes through the `gym` shim; its 5-value unpacking reads as gym 0.26.
        expected = {"gymnasium": "gym026", "mixed": "mixed"}.get(intended, intended)
        matched = found == expected or (found.startswith("none") and intended == "classic")
        agree += matched
        lines.append(
            f"| {sample['file']} | {intended} | {found} | {functions or '-'} | {'yes' if matched else 'NO'} |"
        )
    lines.append(f"\n{agree} of {len(samples)} samples detected as intended.")
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    """Print the tables."""
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--quick", action="store_true", help="a smoke run: few games and regrades")
    parser.add_argument("--workers", type=int, default=multiprocessing.cpu_count())
    parser.add_argument("--games", type=int, default=200_000, help="Monte Carlo games per Blackjack policy")
    parser.add_argument("--episodes", type=int, default=20_000, help="CartPole-v1 episodes of the policy")
    parser.add_argument(
        "--regrades", type=int, default=100, help="regrades per v1 reference (Blackjack: half)"
    )
    parser.add_argument("--mistake-regrades", type=int, default=10, help="regrades per new mistake")
    arguments = parser.parse_args(argv)
    quick = arguments.quick
    config = load_config()
    cartpole = config.problems["cartpole"]
    started = time.perf_counter()
    print("### Sab=True oracles against gymnasium's Blackjack-v1\n")
    print(oracle_table(5_000 if quick else arguments.games))
    print("\n### v0 and v1 oracles side by side (exact pass probabilities, 10 000 games, alpha 1e-6)\n")
    print(cross_oracle_table(10_000, 1e-6))
    print("\n### CartPole-v1 and the lab's bar\n")
    print(
        cartpole_v1_table(
            500 if quick else arguments.episodes, cartpole.min_mean_steps, cartpole.min_steps, cartpole.calls
        )
    )  # type: ignore[attr-defined]
    print("\n### Regrades through the real checks\n")
    regrades, mistake_regrades = (2, 1) if quick else (arguments.regrades, arguments.mistake_regrades)
    print(regrade_table(regrades, mistake_regrades, arguments.workers))
    print("\n### API detection per sample\n")
    print(api_table())
    print(f"\n(measured in {time.perf_counter() - started:.0f} s with {arguments.workers} workers)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

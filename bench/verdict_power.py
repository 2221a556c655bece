"""The power of the statistical verdicts against students whose only fault is statistical (issue 34).

The tests in tests/grader/lab/checks/ that reach the accept/reject decisions of `random_blackjack`,
`blackjack` and `taxi` use these students; this script measures what their docstrings state:

* a Blackjack game dealt from a low deck (ace to five only, each 1/5), judged as played: the decisions,
  the counts and the returned rate are all right and only the win count is off (the game is not the
  lab's, which the check's message names as the cause besides chance). The win probability on that
  deck is exact (`reference.oracles.blackjack` with its card law replaced), so the
  detection probability is the exact binomial tail outside the check's acceptance interval;
* taxi() that trains its own table and ends with the detour table (`reference.oracles.taxi`: an extra
  wall's optimal routes, consistent greedy play, 5.757 per episode): exact mean and variance, normal tail
  above the trained floor;
* Taxi's random scenario with a sampler that plays a fresh shuffle of the six actions in turn (uniform
  action counts, so the chi-square test passes, but not independent draws): its mean and standard
  deviation are measured over many episodes, and the detection probability is the normal tail outside
  the z-test's tolerance.

    python bench/verdict_power.py            # prints the table
    python bench/verdict_power.py --write    # and records it in bench/RESULTS.md
"""

from __future__ import annotations

import argparse
import math
import random
import sys
import warnings
from pathlib import Path

import gymnasium

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench.results_section import replace_section
from grader.compat import resolve_env_id
from grader.lab.assignment import load_config
from grader.lab.stats import binomial_acceptance, binomial_log_pmf, mean_tolerance
from reference.oracles import blackjack as blackjack_oracle
from reference.oracles import (
    greedy_policy_return,
    optimal_return,
    random_policy_outcome,
    random_policy_return,
    threshold_policy_outcome,
)
from reference.oracles.taxi import detour_q_table

_SETTINGS = load_config().problems
ALPHA = _SETTINGS["taxi"].mean_alpha  # type: ignore[attr-defined]
RANDOM_GAMES = 2000
THRESHOLD_GAMES = 1000
THRESHOLDS = (12, 13, 14, 20)
TAXI_EPISODES = 1000
TAXI_MEASURED = 20_000
TRAINED_SLACK = _SETTINGS["taxi"].trained_slack  # type: ignore[attr-defined]
HEADING = "## Power of the statistical verdicts (issue 34)"


def _inside(trials: int, probability: float, low: int, high: int) -> float:
    return math.fsum(math.exp(binomial_log_pmf(k, trials, probability)) for k in range(low, high + 1))


def _blackjack_rows() -> list[str]:
    honest = {"random": random_policy_outcome().win} | {
        n: threshold_policy_outcome(n).win for n in THRESHOLDS
    }
    # The low deck: ace..5 with probability 1/5 each (the oracle reads this table).
    blackjack_oracle.CARD_PROBABILITIES.update({card: (1 if card <= 5 else 0) / 5 for card in range(1, 11)})
    for function in vars(blackjack_oracle).values():
        if hasattr(function, "cache_clear"):
            function.cache_clear()
    short = {"random": random_policy_outcome().win} | {n: threshold_policy_outcome(n).win for n in THRESHOLDS}
    rows = []
    for key, exact in honest.items():
        games = RANDOM_GAMES if key == "random" else THRESHOLD_GAMES
        acceptance = binomial_acceptance(games, exact, ALPHA)
        label = "random_blackjack" if key == "random" else f"blackjack({key})"
        rows.append(
            f"| {label} | win count of {games} games, exact binomial | {exact:.4f} | {acceptance.low}..{acceptance.high} "  # noqa: E501
            f"| {acceptance.false_fail:.1e} | low deck: {short[key]:.4f} | {_inside(games, short[key], acceptance.low, acceptance.high):.1e} |"  # noqa: E501
        )
    return rows


def _shuffled_turns_return(episodes: int, seed: int) -> tuple[float, float]:
    target = resolve_env_id("Taxi-v3")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        env = gymnasium.make(target.gymnasium_id, disable_env_checker=True, **target.merged_kwargs({}))
    rng = random.Random(seed)
    totals = []
    for episode in range(episodes):
        env.reset(seed=seed + episode)
        turn: list[int] = []
        total, done = 0.0, False
        while not done:
            if not turn:
                turn = list(range(6))
                rng.shuffle(turn)
            _, reward, terminated, truncated, _ = env.step(turn.pop())
            total, done = total + float(reward), terminated or truncated
        totals.append(total)
    mean = math.fsum(totals) / episodes
    variance = math.fsum((total - mean) ** 2 for total in totals) / (episodes - 1)
    return mean, math.sqrt(variance)


def _taxi_row() -> str:
    exact = random_policy_return()
    test = mean_tolerance(exact.mean, exact.variance, TAXI_EPISODES, ALPHA)
    mean, deviation = _shuffled_turns_return(TAXI_MEASURED, seed=340_000)
    spread = deviation / math.sqrt(TAXI_EPISODES)
    z_low = (exact.mean - test.half_width - mean) / spread
    z_high = (exact.mean + test.half_width - mean) / spread
    miss = _normal_cdf(z_high) - _normal_cdf(z_low)
    return (
        f"| taxi random mean | mean total reward of {TAXI_EPISODES} episodes, z-test | {exact.mean:.2f} | "
        f"± {test.half_width:.2f} | {ALPHA:.0e} | shuffled turns: {mean:.2f} (sd {deviation:.1f}, {TAXI_MEASURED} episodes) | {miss:.1e} |"  # noqa: E501
    )


def _trained_floor_row() -> str:
    optimal = optimal_return()
    test = mean_tolerance(optimal.mean, optimal.variance, TAXI_EPISODES, ALPHA)
    floor = optimal.mean - test.half_width - TRAINED_SLACK
    detour = greedy_policy_return(detour_q_table(0.6))
    miss = _normal_cdf(-(floor - detour.mean) / math.sqrt(detour.variance / TAXI_EPISODES))
    # The floor is one-sided: an optimal table falls below it with probability at most alpha / 2.
    return (
        f"| taxi() trained table | mean total reward of {TAXI_EPISODES} greedy episodes, one-sided floor | {optimal.mean:.3f} | "  # noqa: E501
        f">= {floor:.3f} (z-test tolerance + slack {TRAINED_SLACK}) | {ALPHA / 2:.0e} | detour table: {detour.mean:.3f} (exact, sd {math.sqrt(detour.variance):.2f}) | {miss:.1e} |"  # noqa: E501
    )


def _normal_cdf(z: float) -> float:
    return 0.5 * math.erfc(-z / math.sqrt(2.0))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help="record the table in bench/RESULTS.md")
    arguments = parser.parse_args()
    for name in ("random_blackjack", "blackjack"):
        assert _SETTINGS[name].win_rate_alpha == ALPHA  # type: ignore[attr-defined]
    lines = [
        HEADING,
        "",
        "Measured by `python bench/verdict_power.py`: each statistical verdict against a student whose only "
        "fault is statistical, at the sample sizes of the tests in tests/grader/lab/checks/ (alpha = 1e-6 as "
        "configured). Blackjack: exact win probabilities (the low deck's from the oracle with its card law "
        "replaced), exact binomial tails. Taxi: the shuffled-turns sampler's mean and deviation measured, "
        "the detour table's exact; normal tails (0.0e+00: below the smallest double).",
        "",
        "| decision | statistic, sample | exact expectation | accepted | false-fail | faulty student | miss (1 - detection) |",  # noqa: E501
        "|---|---|---|---|---|---|---|",
        *_blackjack_rows(),
        _taxi_row(),
        _trained_floor_row(),
    ]
    text = "\n".join(lines)
    print(text)
    if arguments.write:
        replace_section(HEADING, text + "\n")


if __name__ == "__main__":
    main()

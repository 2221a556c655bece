"""False-fail and detection rates of the second lab's played verdicts (issue 35): run_simulation, frozen_lake.

run_simulation: every decision is exact (each returned value against its own replayed episode), so an honest
function cannot fail; what is measured is which grader case reveals each typical mistake, for certain: the
deterministic cases' episodes are fixed, so a mistake that differs there is caught at every seed.

frozen_lake: the only statistical decision is each policy's replayed mean (M episodes, up to the time limit
played) against its exact finite-horizon mean (`reference.oracles.mdp.return_moments(steps=limit)`), with
Bernstein's inequality at false-fail probability alpha = 1e-6 (`grader.lab.rl2.checks.frozen_lake`). Each
simulated check draws M episodes of the optimal policy from the lake's own table (numpy), under the limits
students meet (gym.make's 100 steps on FrozenLake-v1, whatever the map, and 200 on FrozenLake8x8-v1), and
counts checks failed by honest play and by the one cheat the exact checks cannot see: dealing a second game
when the first would be lost (a copy of the env's generator shows it), which leaves every action the
policy's and every mean the replay's.

    python bench/rl2_verdicts.py            # 20 000 checks per row, about a minute
    python bench/rl2_verdicts.py --write    # and replace this bench's section of bench/RESULTS.md
"""

# ruff: noqa: E501

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import numpy.typing as npt

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from grader.lab.rl2.checks.frozen_lake import bernstein_half_width
from grader.lab.rl2.checks.run_simulation import CASES, MISTAKES, discounted_return
from reference.oracles.mdp import optimal_solution, return_moments
from reference.oracles.mdps import frozen_lake

HEADING = "## Second lab: the played verdicts' false-fail and detection rates (issue 35)"
ALPHA = 1e-6
LIMITS = (("4x4", 100), ("8x8", 100), ("8x8", 200))


def _case_rewards() -> dict[str, list[float]]:
    """The rewards of each deterministic case's one episode (fixed whatever the seed)."""
    return {
        "still4 (6 steps, the goal)": [0.0] * 5 + [1.0],
        "still8 (14 steps, the goal)": [0.0] * 13 + [1.0],
        "Taxi (e.g. 12 steps: -1 each, 20 at the drop-off)": [-1.0] * 11 + [20.0],
    }


def run_simulation_rows() -> list[str]:
    """Per mistake, the deterministic cases on which it differs from the honest return (caught for certain)."""
    betas = {"still4 (6 steps, the goal)": 0.8, "still8 (14 steps, the goal)": 0.9}
    taxi = next(case.beta for case in CASES if case.key.startswith("taxi"))
    rows = []
    for cause, mistaken in MISTAKES:
        caught = []
        for name, rewards in _case_rewards().items():
            beta = betas.get(name, taxi)
            honest = discounted_return(rewards, beta)
            if abs(mistaken(rewards, beta) - honest) > 1e-6:
                caught.append(f"{name}: {mistaken(rewards, beta):.6g} vs {honest:.6g}")
        rows.append(f"| {cause.split(':')[0]} | {'; '.join(caught) or 'none'} |")
    return rows


def _episodes(
    mdp_name: str, policy: npt.NDArray[np.int64], count: int, limit: int, choice: np.random.Generator
) -> npt.NDArray[np.float64]:
    """The returns (0 or 1) of `count` episodes from state 0 cut at `limit` steps, all at once.

    Each move of the slippery lake has three outcomes, one third each (gymnasium's side slips are
    0.33333333333333337, a difference of 4e-17 that no simulation here can see): the outcome is the third
    a uniform draw falls in.
    """
    lake = frozen_lake(mdp_name, slippery=True)
    # Terminal states hold one outcome (a self-loop): listed three times, as any third leads there.
    moves = [lake.table[s][policy[s]] * (3 // len(lake.table[s][policy[s]])) for s in range(lake.n_states)]
    outcomes = np.array([[next_state for _, next_state, _, _ in move] for move in moves])
    rewards = np.array([[reward for _, _, reward, _ in move] for move in moves])
    ends = np.array([[done for _, _, _, done in move] for move in moves])
    state = np.zeros(count, dtype=np.int64)
    returns = np.zeros(count)
    running = np.ones(count, dtype=bool)
    for _ in range(limit):
        which = np.minimum((choice.random(count) * 3).astype(np.int64), 2)
        returns += np.where(running, rewards[state, which], 0.0)
        finished = ends[state, which]
        state = np.where(running, outcomes[state, which], state)
        running &= ~finished
        if not running.any():
            break
    return returns


def _returns(
    mdp_name: str, limit: int, count: int, peek: bool, choice: np.random.Generator
) -> npt.NDArray[np.float64]:
    lake = frozen_lake(mdp_name, slippery=True)
    policy = optimal_solution(lake, 1.0).policy
    first = _episodes(mdp_name, policy, count, limit, choice)
    if not peek:
        return first
    # The cheat sees whether the game dealt is won (within the limit here) and otherwise plays a second deal.
    second = _episodes(mdp_name, policy, count, limit, choice)
    return np.where(first > 0, first, second)


def frozen_lake_rows(checks: int, seed: int) -> list[str]:
    rows = []
    choice = np.random.default_rng(seed)
    for mdp_name, limit in LIMITS:
        lake = frozen_lake(mdp_name, slippery=True)
        policy = optimal_solution(lake, 1.0).policy
        moments = return_moments(lake, policy, 1.0, steps=limit)
        mu, variance = float(moments.mean[0]), float(moments.variance[0])
        for episodes in (100, 1000):
            half = bernstein_half_width(variance, episodes, ALPHA)
            failed = {False: 0, True: 0}
            for peek in (False, True):
                done = 0
                while done < checks:
                    size = min(max(1, 200_000 // episodes), checks - done)
                    returns = _returns(mdp_name, limit, size * episodes, peek, choice)
                    means = returns.reshape(size, episodes).mean(axis=1)
                    failed[peek] += int(np.sum(np.abs(means - mu) > half))
                    done += size
            peeked = 1 - (1 - mu) ** 2
            rows.append(
                f"| {mdp_name}, {limit}-step limit | {episodes} | {mu:.4f} | {half:.4f} | "
                f"{failed[False]}/{checks} | {peeked:.4f} | {failed[True]}/{checks} |"
            )
    return rows


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--checks", type=int, default=20_000)
    parser.add_argument("--seed", type=int, default=35)
    parser.add_argument("--write", action="store_true")
    args = parser.parse_args()
    start = time.perf_counter()
    lines = [
        HEADING,
        "",
        "`python bench/rl2_verdicts.py` (grader/lab/rl2/checks/). **run_simulation** decides exactly: each",
        "returned value against `sum beta**k * r_k` of its own replayed episode (tolerance 1e-10), so an honest",
        "function fails with probability 0. Each typical mistake differs from the honest return on the",
        "deterministic cases, whose episodes are fixed, so it is caught at every seed (`beta *= beta` has two",
        "readings, both named; on FrozenLake the last reward only and a discount never applied coincide, Taxi",
        "tells them apart):",
        "",
        "| mistake | deterministic cases that reveal it (mistaken vs honest return) |",
        "|---|---|",
        *run_simulation_rows(),
        "",
        "**frozen_lake**: the exact checks (every action the returned policy's, each mean the replay's, the",
        "policies by exact value, the value functions against exact DP) cannot fail an honest file. Its one",
        "statistical test: each policy's replayed mean (M episodes, up to the time limit played) against its",
        f"exact finite-horizon mean, Bernstein's inequality at alpha = {ALPHA:g} (returns in [0, 1]); 4 tests",
        f"per grading. Over {args.checks} simulated checks per row (seed {args.seed}), the optimal policy:",
        "",
        "| lake and limit | M | exact mean | half-width | honest failed | mean with a second deal | "
        "cheat failed |",
        "|---|---|---|---|---|---|---|",
        *frozen_lake_rows(args.checks, args.seed),
        "",
        "Reading: no honest check failed (Bernstein bounds the rate by 1e-6 per test whatever the skew of a",
        "0/1 return). The cheat (a second deal whenever the first game would be lost) is caught for certain at",
        "the lab's M = 1 000 and mostly missed at the default M = 100 (the configuration's `episodes`): the",
        "exact checks carry frozen_lake's verdict, and the mean test is a backstop against a selection of",
        "games that FrozenLake's single start leaves to the generator; raise `episodes` to 1 000 to make it",
        "bite (about 30 s more per grading, measured through the sandbox: 41 s against 12 s). The test in",
        "tests/grader/lab/rl2/test_frozen_lake.py plays the cheat",
        "through the sandbox at M = 1 000 (0.740 raised to about 0.86 on 4x4: the cheat's look-ahead ignores",
        "the limit, so fewer of its second deals are won within it than here).",
        "",
        f"Took {time.perf_counter() - start:.0f} s.",
        "",
    ]
    text = "\n".join(lines)
    print(text)
    if args.write:
        from bench.results_section import replace_section

        replace_section(HEADING, text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

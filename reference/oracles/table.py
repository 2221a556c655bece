"""The oracle table: every exact figure the lab's problems are judged against, as data and as text."""

from __future__ import annotations

from dataclasses import asdict, dataclass

from reference.oracles.blackjack import (
    LARGEST_THRESHOLD,
    Outcome,
    random_policy_outcome,
    threshold_policy_outcome,
)
from reference.oracles.guessing_game import GuessCounts, midpoint_guess_counts
from reference.oracles.taxi import (
    TIME_LIMIT,
    ReturnMoments,
    greedy_policy_return,
    optimal_q_table,
    optimal_return,
    random_policy_return,
)

TIE_TOLERANCE = 1e-12
"""Win probabilities closer than this count as equally good thresholds."""


@dataclass(frozen=True)
class OracleTable:
    """Exact expectations for the lab's Blackjack and Taxi problems and the optional GuessingGame.

    Attributes:
        blackjack_random: outcome of the random player (Problem 1).
        blackjack_thresholds: outcome of "hit while the sum is <= n", indexed by n = 0..21 (Problem 2).
        best_thresholds: the n with the highest win probability (several if tied).
        taxi_max_steps: the time limit the Taxi returns are computed for.
        taxi_random: return of the random policy (Problem 5).
        taxi_optimal: best achievable return within the time limit.
        taxi_gamma: discount factor of `taxi_greedy_optimal_q`.
        taxi_greedy_optimal_q: return of acting greedily on the optimal Q-table for `taxi_gamma`.
        guessing_game_midpoint: guesses per game of the midpoint search from [-1000, 1000].
    """

    blackjack_random: Outcome
    blackjack_thresholds: tuple[Outcome, ...]
    best_thresholds: tuple[int, ...]
    taxi_max_steps: int
    taxi_random: ReturnMoments
    taxi_optimal: ReturnMoments
    taxi_gamma: float
    taxi_greedy_optimal_q: ReturnMoments
    guessing_game_midpoint: GuessCounts


def build_oracle_table(*, gamma: float = 0.6, max_steps: int = TIME_LIMIT) -> OracleTable:
    """Compute the oracle table (well under a second).

    Args:
        gamma: discount factor of the optimal Q-table whose greedy return is reported.
        max_steps: Taxi's time limit.

    Returns:
        The table.
    """
    thresholds = tuple(threshold_policy_outcome(n) for n in range(LARGEST_THRESHOLD + 1))
    best_win = max(outcome.win for outcome in thresholds)
    return OracleTable(
        blackjack_random=random_policy_outcome(),
        blackjack_thresholds=thresholds,
        best_thresholds=tuple(
            n for n, outcome in enumerate(thresholds) if outcome.win >= best_win - TIE_TOLERANCE
        ),
        taxi_max_steps=max_steps,
        taxi_random=random_policy_return(max_steps),
        taxi_optimal=optimal_return(max_steps),
        taxi_gamma=gamma,
        taxi_greedy_optimal_q=greedy_policy_return(optimal_q_table(gamma), max_steps),
        guessing_game_midpoint=midpoint_guess_counts(),
    )


def table_as_json_data(table: OracleTable) -> dict[str, object]:
    """The table as JSON-ready data; outcomes carry their expected reward, returns their std."""

    def outcome(value: Outcome) -> dict[str, float]:
        return {**asdict(value), "expected_reward": value.expected_reward}

    def moments(value: ReturnMoments) -> dict[str, float]:
        return {**asdict(value), "std": value.std}

    return {
        "blackjack": {
            "game": "Blackjack-v1 natural=False sab=False (the lab's Blackjack-v0)",
            "random_policy": outcome(table.blackjack_random),
            "threshold_policy": [
                {"n": n, **outcome(value)} for n, value in enumerate(table.blackjack_thresholds)
            ],
            "best_thresholds": list(table.best_thresholds),
        },
        "taxi": {
            "game": "Taxi-v4 (the lab's Taxi-v3)",
            "max_steps": table.taxi_max_steps,
            "random_policy": moments(table.taxi_random),
            "optimal_policy": moments(table.taxi_optimal),
            "greedy_optimal_q": {"gamma": table.taxi_gamma, **moments(table.taxi_greedy_optimal_q)},
        },
        "guessing_game": {
            "game": "GuessingGame-v0 (registered by gymgrade), midpoint search from [-1000, 1000]",
            "guess_count_probabilities": {
                str(count): p for count, p in enumerate(table.guessing_game_midpoint.probabilities, 1)
            },
            "mean": table.guessing_game_midpoint.mean,
            "std": table.guessing_game_midpoint.variance**0.5,
        },
    }


def format_oracle_table(table: OracleTable) -> str:
    """The table as aligned plain text for a terminal or a Markdown code block."""
    random_outcome, guesses = table.blackjack_random, table.guessing_game_midpoint
    lines = [
        "Blackjack (Blackjack-v1, natural=False, sab=False): exact probabilities per game",
        f"  random policy: win {random_outcome.win:.4f}  draw {random_outcome.draw:.4f}  "
        f"loss {random_outcome.loss:.4f}",
        "  hit while sum <= n:",
        "     n    win    draw   loss   E[reward]",
    ]
    for n, outcome in enumerate(table.blackjack_thresholds):
        best = "  <- best" if n in table.best_thresholds else ""
        probabilities = f"{outcome.win:.4f} {outcome.draw:.4f} {outcome.loss:.4f}"
        lines.append(f"    {n:2d}  {probabilities}  {outcome.expected_reward:+.4f}{best}")
    lines += [
        f"Taxi (Taxi-v4), total reward within {table.taxi_max_steps} steps: mean (std)",
        f"  random policy:            {table.taxi_random.mean:9.4f} ({table.taxi_random.std:.4f})",
        f"  optimal policy:           {table.taxi_optimal.mean:9.4f} ({table.taxi_optimal.std:.4f})",
        f"  greedy on Q* (gamma={table.taxi_gamma:g}): {table.taxi_greedy_optimal_q.mean:9.4f} "
        f"({table.taxi_greedy_optimal_q.std:.4f})",
        "GuessingGame (GuessingGame-v0), midpoint search from [-1000, 1000]: guesses per game",
        "  " + "  ".join(f"{k}: {p:.6g}" for k, p in enumerate(guesses.probabilities, 1)),
        f"  mean {guesses.mean:.6f} (std {guesses.variance**0.5:.4f})",
    ]
    return "\n".join(lines)

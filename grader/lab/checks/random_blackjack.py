"""Problem 1: `random_blackjack(n)` plays n games with random actions and returns the win rate."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from pydantic import Field

from grader.lab.checks.base import CallRecord, Verdict, judged_when_all_returned, paused_gc
from grader.lab.checks.blackjack_games import GAME_STEPS, count_games, hits_by_sum
from grader.lab.checks.integrity import (
    games_budget,
    noting_post_terminal_steps,
    played_episodes,
    played_games_problem,
)
from grader.lab.checks.values import as_number, chance_text, describe, rate_mismatch_cause, read_rate
from grader.lab.settings import PlayedProblemConfig, Probability
from grader.lab.stats import binomial_acceptance, grouped_binomial_fit, mean_tolerance
from grader.sandbox.outcome import Call, FunctionInfo
from reference.oracles import random_policy_outcome

if TYPE_CHECKING:
    from grader.sandbox.outcome import PlainValue


class RandomBlackjackConfig(PlayedProblemConfig):
    """The settings of `random_blackjack(n)`."""

    games: int = Field(ge=100, description="The n passed to random_blackjack(n): games the student plays.")
    win_rate_alpha: Probability = Field(
        description="False-fail probability of the exact two-sided binomial test of the win count against the exact random-policy win probability."  # noqa: E501
    )
    action_alpha: Probability = Field(
        description="False-fail probability of EACH of the two random-action tests (hit frequency = 1/2; "
        "actions independent of the player's sum)."
    )


@dataclass(frozen=True)
class RandomBlackjackCheck:
    """random_blackjack(n): n completed games, random actions, and the exact random-policy win rate."""

    def plan(
        self, settings: RandomBlackjackConfig, functions: Mapping[str, FunctionInfo], seed: int
    ) -> list[Call]:
        """One call, random_blackjack(games)."""
        games = settings.games
        return [Call("random_blackjack", (games,), budget=games_budget(games, GAME_STEPS))]

    @paused_gc
    @noting_post_terminal_steps
    @judged_when_all_returned
    def judge(self, settings: RandomBlackjackConfig, records: Sequence[CallRecord]) -> Verdict:
        """Judge the call against its replayed games and the exact random-policy win probability."""
        call = f"random_blackjack({settings.games})"
        returned = as_number(records[0].outcome.value)
        if returned is None:
            return _fail(
                f"{call} returned {describe(records[0].outcome.value)}; expected the win rate as a number."
            )
        episodes = played_episodes(records)
        rules = settings.game_rules()
        problem = played_games_problem(records, episodes, rules, across_calls=False)
        if problem:
            return _fail(f"{call}: {problem}.")
        game = rules.played_game(episode.log for episode in episodes)
        if isinstance(game, str):
            return _fail(f"{call}: {game}.")
        counts = count_games(episodes)
        measurements: dict[str, PlainValue] = {
            "returned": returned,
            "games_replayed": counts.games,
            "wins": counts.wins,
            "draws": counts.draws,
            "replayed_win_fraction": counts.win_fraction,
            "game": game.name,
        }
        if counts.games != settings.games:
            return _fail(
                f"{call} must play {settings.games} games; the replay shows {counts.games}. "
                f"Play exactly n games (one reset per game).",
                measurements,
            )
        scale = read_rate(returned, counts)
        measurements["read_as"] = scale
        if scale is None:
            return _fail(
                f"{call} returned {returned:.6g}, but the {counts.games} replayed games won {counts.wins} ({counts.win_fraction:.4f}); "  # noqa: E501
                f"{rate_mismatch_cause(returned, counts)}.",
                measurements,
            )
        randomness = _random_action_problem(episodes, settings, measurements)
        if randomness:
            return _fail(f"{call}: {randomness}", measurements)
        exact = random_policy_outcome(sab=game.sab).win
        acceptance = binomial_acceptance(counts.games, exact, settings.win_rate_alpha)
        measurements |= {
            "exact_win_probability": exact,
            "accepted_wins_low": acceptance.low,
            "accepted_wins_high": acceptance.high,
            "false_fail_probability": acceptance.false_fail,
        }
        expected = f"a random player wins {exact:.4f} of games of {game.description}, so {counts.games} games win between {acceptance.low} and {acceptance.high} times"  # noqa: E501
        if not acceptance.accepts(counts.wins):
            return _fail(
                f"{call}: {expected}; your replayed games won {counts.wins}. "
                f"The games are real, so this is either {chance_text(acceptance.false_fail)} or not the lab's game: "  # noqa: E501
                "regrade once.",
                measurements,
            )
        note = (
            " (read as a percentage: the lab says 'percentage', a fraction is fine too)"
            if scale == "percentage"
            else ""
        )
        return Verdict(
            "passed",
            1.0,
            f"{call} returned {returned:.6g}{note}: "
            f"{counts.wins} wins in {counts.games} random games, and {expected}.",
            measurements,
        )


def _random_action_problem(
    episodes: Sequence[Any], settings: RandomBlackjackConfig, measurements: dict[str, PlainValue]
) -> str | None:
    groups = hits_by_sum(episodes)
    hits = sum(group_hits for group_hits, _ in groups.values())
    decisions = sum(group_decisions for _, group_decisions in groups.values())
    frequency = mean_tolerance(0.5, 0.25, decisions, settings.action_alpha)
    hit_share = hits / decisions
    by_sum = grouped_binomial_fit(list(groups.values()), 0.5)
    measurements |= {
        "decisions": decisions,
        "hit_fraction": hit_share,
        "hit_fraction_tolerance": frequency.half_width,
        "independence_statistic": by_sum.statistic,
        "independence_degrees_of_freedom": by_sum.degrees_of_freedom,
        "independence_p_value": by_sum.p_value,
    }
    if not frequency.accepts(hit_share):
        return (
            f"random actions draw a card in half of all decisions (0.5 ± {frequency.half_width:.3f} over {decisions} decisions); "  # noqa: E501
            f"yours drew in {hit_share:.3f}. "
            "Choose each action with env.action_space.sample() (or a fair coin), not a fixed or biased choice."  # noqa: E501
        )
    if by_sum.p_value < settings.action_alpha:
        shares = ", ".join(
            f"{label}: {group_hits / group_decisions:.2f}"
            for label, (group_hits, group_decisions) in groups.items()
        )
        return (
            f"random actions draw half the time whatever the hand, but your share of draws depends on the player's sum ({shares}; chi-square p = {by_sum.p_value:.1e}): "  # noqa: E501
            "the actions follow a strategy. Choose each action with env.action_space.sample()."
        )
    return None


def _fail(feedback: str, measurements: dict[str, PlainValue] | None = None) -> Verdict:
    return Verdict("failed", 0.0, feedback, measurements or {})

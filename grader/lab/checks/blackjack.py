"""Problem 2: `blackjack(n)` draws while the player's sum is <= n and returns the win rate of 10000 games."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cache
from typing import TYPE_CHECKING, Annotated, NamedTuple

from pydantic import Field, field_validator

from grader.lab.checks.base import CallRecord, Verdict, judged_when_all_returned, paused_gc
from grader.lab.checks.blackjack_games import GAME_STEPS, HIT, count_games, player_sum
from grader.lab.checks.integrity import (
    Episode,
    episodes_per_call,
    games_budget,
    integrity_problem,
    noting_post_terminal_steps,
    played_episodes,
    repeated_seed_problem,
)
from grader.lab.checks.values import as_number, chance_text, describe, rate_mismatch_cause, read_rate
from grader.lab.games import Game
from grader.lab.settings import PlayedProblemConfig, Probability
from grader.lab.stats import binomial_acceptance
from grader.sandbox.outcome import Call, FunctionInfo
from reference.oracles import threshold_policy_outcome

if TYPE_CHECKING:
    from grader.sandbox.outcome import PlainValue

THRESHOLDS = range(22)


@cache
def exact_curve(*, sab: bool = False) -> dict[int, float]:
    """Exact win probability of "draw while sum <= n" for n = 0..21 (`sab`: Sutton and Barto's rules)."""
    return {n: threshold_policy_outcome(n, sab=sab).win for n in THRESHOLDS}


def exact_best_n(*, sab: bool = False) -> int:
    """The n with the highest exact win probability (the smallest one on ties)."""
    curve = exact_curve(sab=sab)
    return max(curve, key=lambda n: (curve[n], -n))


class BlackjackConfig(PlayedProblemConfig):
    """The settings of `blackjack(n)`."""

    thresholds: list[Annotated[int, Field(ge=0, le=21)]] = Field(
        min_length=1, description="The values of n blackjack(n) is called with, one call each."
    )
    games_per_call: int = Field(
        ge=1, description="Games each call must play (the lab says 10000); 0 is not allowed."
    )
    win_rate_alpha: Probability = Field(
        description="False-fail probability of the exact two-sided binomial test of EACH call's win count against the exact threshold-policy win probability."  # noqa: E501
    )

    @field_validator("thresholds")
    @classmethod
    def _distinct(cls, thresholds: list[int]) -> list[int]:
        if len(set(thresholds)) != len(thresholds):
            raise ValueError(f"expected distinct values of n, found {thresholds}")
        return thresholds


class _Decision(NamedTuple):
    game: int
    step: int
    total: int
    hit: bool


def _decisions(episodes: Sequence[Episode]) -> list[_Decision]:
    return [
        _Decision(game, step, player_sum(observation), int(action) == HIT)
        for game, episode in enumerate(episodes)
        for step, (observation, action) in enumerate(episode.decisions())
    ]


def _follows(decisions: Sequence[_Decision], n: int) -> bool:
    return all(decision.hit == (decision.total <= n) for decision in decisions)


def policy_deviation(decisions: Sequence[_Decision], n: int) -> str | None:
    """Name how the replayed decisions deviate from "draw while sum <= n", or None if they never do."""
    wrong = [decision for decision in decisions if decision.hit != (decision.total <= n)]
    if not wrong:
        return None
    rule = f"'draw while the sum is <= {n}'"
    if n > 0 and _follows(decisions, n - 1):
        stood = sum(1 for decision in wrong if decision.total == n)
        return (
            f"your games stood on a sum of exactly {n} in {stood} hands, so they follow 'draw while the sum is < {n}': "  # noqa: E501
            "check `<` versus `<=`"
        )
    if n < 21 and _follows(decisions, n + 1):
        return (
            f"your games drew on a sum of {n + 1} in {len(wrong)} hands, so they follow 'draw while the sum is <= {n + 1}': "  # noqa: E501
            "the threshold is off by one"
        )
    if all(decision.step == 0 for decision in wrong):
        if all(decision.hit for decision in wrong):
            habit = "drew a card before looking at the dealt hand"
        elif not any(decision.hit for decision in wrong):
            habit = "stood before looking at the dealt hand"
        else:
            habit = (
                "decided with a stale hand (e.g. the previous game's sum) instead of the one reset() dealt"
            )
        return (
            f"in {len(wrong)} games the first decision {habit}; every later decision followed {rule}. "
            f"Read the player's sum from the observation reset() returns before the first decision"
        )
    other = next((m for m in THRESHOLDS if _follows(decisions, m)), None)
    if other is not None:
        return (
            f"your games follow 'draw while the sum is <= {other}' whatever n is: "
            "use the parameter n, not a fixed number"
        )
    example = wrong[0]
    did = "drew" if example.hit else "stood"
    return f"{len(wrong)} of {len(decisions)} decisions broke {rule} (e.g. game {example.game + 1}, decision {example.step + 1}: sum {example.total}, you {did})"  # noqa: E501


@dataclass(frozen=True)
class BlackjackCheck:
    """blackjack(n) for several n: the threshold rule in every replayed decision, exact win rates."""

    def plan(self, settings: BlackjackConfig, functions: Mapping[str, FunctionInfo], seed: int) -> list[Call]:
        """One call blackjack(n) per configured n."""
        budget = games_budget(settings.games_per_call, GAME_STEPS)
        return [Call("blackjack", (n,), budget=budget) for n in settings.thresholds]

    @paused_gc
    @noting_post_terminal_steps
    @judged_when_all_returned
    def judge(self, settings: BlackjackConfig, records: Sequence[CallRecord]) -> Verdict:
        """Judge every call's rule, game count, returned rate and exact win probability."""
        episodes = played_episodes(records)
        rules = settings.game_rules()
        problem = integrity_problem(records, episodes, rules)
        if problem:
            return Verdict("failed", 0.0, f"blackjack: {problem}.", {})
        game = rules.played_game(episode.log for episode in episodes)
        if isinstance(game, str):
            return Verdict("failed", 0.0, f"blackjack: {game}.", {})
        curve = exact_curve(sab=game.sab)
        best = exact_best_n(sab=game.sab)
        measurements: dict[str, PlainValue] = {
            "game": game.name,
            "exact_curve": {str(n): p for n, p in curve.items()},
            "exact_best_n": best,
            "exact_best_win_probability": curve[best],
        }
        student_curve: dict[str, PlainValue] = {}
        measurements["curve"] = student_curve
        passed_lines = []
        first_failure: str | None = None
        grouped = episodes_per_call(records, episodes)
        # Every call is judged, even after a failure, so the report shows the student's whole curve.
        for n, record, call_episodes in zip(settings.thresholds, records, grouped, strict=True):
            failure, line = self._judge_call(settings, game, n, record, call_episodes, student_curve)
            if failure:
                first_failure = first_failure or failure
            else:
                passed_lines.append(line)
        if first_failure:
            return Verdict("failed", 0.0, first_failure, measurements)
        peak = max(student_curve, key=lambda n: float(student_curve[n] or 0.0))  # type: ignore[arg-type]
        return Verdict(
            "passed",
            1.0,
            f"Every replayed decision followed 'draw while the sum is <= n' and every win rate is within the tolerance of the exact one in {game.description} ({'; '.join(passed_lines)}). "  # noqa: E501
            f"The exact best n is {best} (wins {curve[best]:.4f}); "
            f"among the n tried, your rates peak at n = {peak}.",
            measurements,
        )

    @staticmethod
    def _judge_call(
        settings: BlackjackConfig,
        game: Game,
        n: int,
        record: CallRecord,
        episodes: list[Episode],
        curve: dict[str, PlainValue],
    ) -> tuple[str | None, str]:
        call = f"blackjack({n})"
        returned = as_number(record.outcome.value)
        if returned is None:
            return f"{call} returned {describe(record.outcome.value)}; expected the win rate as a number.", ""
        problem = repeated_seed_problem(episodes, across_calls=False)
        if problem:
            return f"{call}: {problem}.", ""
        counts = count_games(episodes)
        if counts.games != settings.games_per_call:
            return (
                f"{call} must play {settings.games_per_call} games (the lab's number); "
                f"the replay shows {counts.games}. "
                f"Play exactly {settings.games_per_call} games, one reset per game.",
                "",
            )
        scale = read_rate(returned, counts)
        if scale is None:
            return (
                f"{call} returned {returned:.6g}, but its {counts.games} replayed games won {counts.wins} ({counts.win_fraction:.4f}); "  # noqa: E501
                f"{rate_mismatch_cause(returned, counts)}.",
                "",
            )
        curve[str(n)] = counts.win_fraction
        deviation = policy_deviation(_decisions(episodes), n)
        exact = exact_curve(sab=game.sab)[n]
        acceptance = binomial_acceptance(counts.games, exact, settings.win_rate_alpha)
        expected = f"a player drawing on sums <= {n} wins {exact:.4f} of games ({acceptance.low}..{acceptance.high} of {counts.games})"  # noqa: E501
        if deviation:
            return f"{call} returned {returned:.6g}; {expected}. {deviation[0].upper()}{deviation[1:]}.", ""
        if not acceptance.accepts(counts.wins):
            return (
                f"{call}: {expected}; your replayed games won {counts.wins}. "
                f"The decisions followed the rule, so this is {chance_text(acceptance.false_fail)} or not the lab's game: "  # noqa: E501
                "regrade once.",
                "",
            )
        percentage = " as a percentage" if scale == "percentage" else ""
        return None, f"n = {n}: {counts.win_fraction:.4f}{percentage}, exact {exact:.4f}"

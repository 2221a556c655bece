"""Optional problem: `guessing_game()` bisects to GuessingGame-v0's target and returns its guesses."""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cache
from typing import Any

import numpy as np
from pydantic import Field

from grader.compat.envs.guessing_game import GUESS_EQUAL, GUESS_TOO_HIGH, GUESS_TOO_LOW
from grader.lab.checks.base import CallRecord, Verdict, paused_gc
from grader.lab.checks.integrity import Episode, played_episodes
from grader.lab.checks.lengths import LengthRuns, judge_lengths, one_game_calls
from grader.lab.checks.values import chance_text
from grader.lab.settings import PlayedProblemConfig, Probability
from grader.lab.stats import central_interval
from grader.sandbox.outcome import Call, FunctionInfo, PlainValue
from reference.oracles.guessing_game import TARGET_HIGH, TARGET_LOW, TOLERANCE, midpoint_guess_counts

EPISODE_STEPS = 400
"""Guesses recorded per game: GuessingGame-v0 ends at 200; room for guesses after the end to be diagnosed."""
MIDPOINT_SLACK = float(TOLERANCE)
"""How far a guess may lie from the exact midpoint and still count as one: the game's own tolerance (10).

Integer midpoints (`(low + high) // 2`), ends moved one past the guess (`low = guess + 1`) or by the
tolerance (`low = guess + 10`) stay within 5 of the midpoint of the interval the observations leave."""
GUESS_SPACE = 10_000
"""The guess space is [-10000, 10000] (`env.action_space`), wider than the targets' [-1000, 1000)."""


class GuessingGameConfig(PlayedProblemConfig):
    """The settings of `guessing_game()`, the lab's midpoint search; every field has a default (optional)."""

    call_seconds: float = Field(default=30.0, gt=0.0, description="Wall-clock limit of ONE call.")
    expected_seconds: float = Field(default=3.0, ge=0.0, description="Typical total time of the calls.")
    calls: int = Field(
        default=100, ge=1, le=1_000, description="How many times guessing_game() is called (one game each)."
    )
    count_alpha: Probability = Field(
        default=1e-6,
        description="False-fail probability of the exact two-sided test of the total number of guesses against the exact distribution of the midpoint search's guess count.",  # noqa: E501
    )


@dataclass(frozen=True)
class TotalAcceptance:
    """The totals of guesses over `games` midpoint-search games a correct solution may produce.

    Attributes:
        games: Number of games summed.
        low: Smallest accepted total.
        high: Largest accepted total.
        false_fail: Exact P(total < low) + P(total > high) for the midpoint search.
    """

    games: int
    low: int
    high: int
    false_fail: float

    def accepts(self, total: int) -> bool:
        """Whether a total lies in the acceptance interval."""
        return self.low <= total <= self.high


@cache
def total_acceptance(games: int, alpha: float) -> TotalAcceptance:
    """The narrowest central interval of totals whose two tails each hold at most alpha / 2.

    The distribution of the total is the `games`-fold convolution of the exact guess-count distribution
    (`reference.oracles.guessing_game`), by repeated squaring with `numpy.convolve`: scipy has no n-fold
    sum of an arbitrary discrete law, so the tails are summed here.

    Args:
        games: Number of games (1 .. 1000; the exact convolution takes 20 ms at 1000).
        alpha: Largest acceptable false-fail probability, in (0, 1).

    Raises:
        ValueError: An argument is out of range.
    """
    if not 1 <= games <= 1_000 or not 0.0 < alpha < 1.0:
        raise ValueError(f"expected 1 <= games <= 1000 and alpha in (0, 1); found {games}, {alpha}")
    single = np.array((0.0, *midpoint_guess_counts().probabilities))
    total, power, remaining = np.array([1.0]), single, games
    while remaining:
        if remaining & 1:
            total = np.convolve(total, power)
        remaining >>= 1
        if remaining:
            power = np.convolve(power, power)
    return TotalAcceptance(games, *central_interval(np.clip(total, 0.0, None).tolist(), alpha))


def _guess_value(action: Any) -> float | None:
    """A logged guess as a number: a number, or a one-element list or array (the forms the env takes)."""
    if isinstance(action, np.ndarray) and action.size == 1:
        action = action.reshape(-1)[0]
    elif isinstance(action, list) and len(action) == 1:
        action = action[0]
    if isinstance(action, bool | np.bool_) or not isinstance(action, int | float | np.integer | np.floating):
        return None
    return float(action)


@dataclass(frozen=True)
class Deviation:
    """The first guess of a game that is not the midpoint of the interval the observations left.

    Attributes:
        episode: The game.
        number: The guess's number in the game (1 = first).
        guess: The guess (None when it is not a number).
        low: Lower end of the interval the earlier observations left.
        high: Its upper end.
        last_observation: The observation that answered the previous guess (0 before the first).
    """

    episode: Episode
    number: int
    guess: float | None
    low: float
    high: float
    last_observation: int

    @property
    def midpoint(self) -> float:
        """The guess the midpoint search makes here."""
        return (self.low + self.high) / 2


def first_deviation(episode: Episode) -> Deviation | None:
    """The first guess farther than `MIDPOINT_SLACK` from the midpoint of the interval left, or None.

    The interval starts as the targets' [-1000, 1000]; answer 1 (too low) moves its lower end up to the
    guess, answer 3 (too high) its upper end down to it. Judged on the replayed observations.
    """
    low, high, last = float(TARGET_LOW), float(TARGET_HIGH), 0
    observations = episode.replay.observations[1 : episode.length + 1]
    for number, (action, observation) in enumerate(zip(episode.actions, observations, strict=False), 1):
        guess = _guess_value(action)
        if guess is None or abs(guess - (low + high) / 2) > MIDPOINT_SLACK:
            return Deviation(episode, number, guess, low, high, last)
        last = int(observation)
        if last == GUESS_TOO_LOW:
            low = max(low, guess)
        elif last == GUESS_TOO_HIGH:
            high = min(high, guess)
    return None


def _guesses_outside(episode: Episode) -> tuple[int, int]:
    """How many of a game's guesses lie outside the interval the earlier observations left, of how many."""
    low, high, outside = float(TARGET_LOW), float(TARGET_HIGH), 0
    observations = episode.replay.observations[1 : episode.length + 1]
    for action, observation in zip(episode.actions, observations, strict=False):
        guess = _guess_value(action)
        if guess is None or not low <= guess <= high:
            outside += 1
            continue
        if int(observation) == GUESS_TOO_LOW:
            low = guess
        elif int(observation) == GUESS_TOO_HIGH:
            high = guess
    return outside, len(episode.actions)


def _observation_after(deviation: Deviation) -> int | None:
    observations = deviation.episode.replay.observations
    return int(observations[deviation.number]) if deviation.number < len(observations) else None


def _linear_step(episode: Episode) -> float | None:
    """The constant step of a game's guesses when they form a linear search of 3 or more guesses."""
    values = [_guess_value(action) for action in episode.actions]
    guesses = [guess for guess in values if guess is not None]
    if len(guesses) < 3 or len(guesses) < len(values):
        return None
    steps = {round(later - earlier, 6) for earlier, later in itertools.pairwise(guesses)}
    step = steps.pop() if len(steps) == 1 else 0.0
    return step or None


def deviation_cause(deviation: Deviation) -> str:
    """The likely mistake behind a deviating guess, as advice."""
    guess, episode = deviation.guess, deviation.episode
    if guess is None:
        return "each guess must be one number (or a one-element list or array)"
    if _observation_after(deviation) == GUESS_EQUAL:
        return "it is exactly the target, which no observation reveals: info['number'] shows the target for display; play from the observations alone"  # noqa: E501
    if deviation.number > 1 and _guess_value(episode.actions[deviation.number - 2]) == guess:
        return (
            f"it repeats your previous guess: observation {deviation.last_observation} did not move an end "
            "of your interval. The game answers 1 (guess below the target: raise the lower end), 2 (equal) "
            "or 3 (above: lower the upper end), not the lab text's 0/1/2"
        )
    step = _linear_step(episode)
    if step is not None:
        return (
            f"your guesses step by {step:g} each time, a linear search that ignores what each observation "
            "says: guess the midpoint of the interval the target is still in, and halve it with every answer"
        )
    if deviation.number == 2 and abs(abs(guess) - GUESS_SPACE / 2) <= MIDPOINT_SLACK:
        return f"it is the midpoint of half of [-{GUESS_SPACE}, {GUESS_SPACE}], the guess space (env.action_space), but the target lies in [{TARGET_LOW}, {TARGET_HIGH}): start from the interval [{TARGET_LOW}, {TARGET_HIGH}]"  # noqa: E501
    wrong_side = (deviation.last_observation == GUESS_TOO_LOW and guess < deviation.low) or (
        deviation.last_observation == GUESS_TOO_HIGH and guess > deviation.high
    )
    if wrong_side:
        return (
            f"after observation {deviation.last_observation} you moved the wrong way: 1 means the guess was "
            "below the target (raise the lower end to it), 3 above (lower the upper end), 2 equal (the lab "
            "text's 0/1/2 codes are not the game's)"
        )
    outside, guesses = _guesses_outside(episode)
    if 2 * outside >= guesses or not deviation.low <= guess <= deviation.high:
        return f"{outside} of the game's {guesses} guesses lie outside the interval the target is still in, as random guesses would: keep the interval, guess its midpoint, and move the end the observation points at"  # noqa: E501
    return "guess the midpoint (low + high) / 2 of the interval the target is still in"


def _strategy_verdict(runs: LengthRuns, measurements: dict[str, PlainValue]) -> Verdict | None:
    deviations = [deviation for episode in runs.episodes if (deviation := first_deviation(episode))]
    measurements["games_off_midpoint"] = len(deviations)
    if not deviations:
        return None
    first = deviations[0]
    shown = "not a number" if first.guess is None else f"{first.guess:g}"
    return Verdict(
        "failed",
        0.0,
        f"guessing_game(): {len(deviations)} of your {len(runs.episodes)} replayed games left the midpoint search (game {first.episode.call_index + 1}: guess {first.number} was {shown}, but the observations so far leave the target in [{first.low:g}, {first.high:g}], whose midpoint is {first.midpoint:g}); {deviation_cause(first)}.",  # noqa: E501
        measurements,
    )


def _counting_verdict(runs: LengthRuns, measurements: dict[str, PlainValue]) -> Verdict | None:
    if not runs.uncounted_steps:
        return None
    return Verdict(
        "failed",
        0.0,
        f"guessing_game(): every count you returned is {runs.uncounted_steps} short of the guesses its replayed game took (off by one: the winning guess, or a guess before the counting loop, was not counted). Return the number of env.step() calls, the last one included.",  # noqa: E501
        measurements,
    )


def _stopping_hint(records: Sequence[CallRecord]) -> str:
    episodes = played_episodes(records)
    if not any(episode.replay.steps_after_done > 0 for episode in episodes):
        return ""
    return " In GuessingGame-v0 the game is won and over (done is True, reward 1) as soon as a guess is within 10 of the target; observation 2 (exactly equal) almost never comes, so stop on `done`."  # noqa: E501


@dataclass(frozen=True)
class GuessingGameCheck:
    """guessing_game() called many times: returns its replayed game's guesses; midpoint play; exact total."""

    def plan(
        self, settings: GuessingGameConfig, functions: Mapping[str, FunctionInfo], seed: int
    ) -> list[Call]:
        """The configured number of guessing_game() calls."""
        return one_game_calls("guessing_game", settings.calls, EPISODE_STEPS)

    @paused_gc
    def judge(self, settings: GuessingGameConfig, records: Sequence[CallRecord]) -> Verdict:
        """Judge counts against the replays, each guess against the midpoint, the total against the oracle."""
        runs = judge_lengths("guessing_game", settings.game_rules(), records)
        if isinstance(runs, Verdict):
            if runs.status != "failed":
                return runs
            hint = _stopping_hint(records)
            return Verdict(runs.status, runs.fraction, runs.feedback + hint, runs.measurements)
        measurements = runs.measurements()
        problem = _strategy_verdict(runs, measurements) or _counting_verdict(runs, measurements)
        if problem is not None:
            return problem
        oracle = midpoint_guess_counts()
        acceptance = total_acceptance(len(runs.lengths), settings.count_alpha)
        total = sum(runs.lengths)
        measurements.update(
            expected_mean=oracle.mean,
            total_guesses=total,
            accepted_total=[acceptance.low, acceptance.high],
            false_fail=acceptance.false_fail,
        )
        measured = f"your {len(runs.lengths)} replayed games took {total} guesses ({runs.mean:.2f} per game)"
        bar = (
            f"the midpoint search takes {oracle.mean:.4g} guesses per game on average (exact), so "
            f"{acceptance.games} games take {acceptance.low} to {acceptance.high} in all, except with "
            f"{chance_text(acceptance.false_fail)}"
        )
        if not acceptance.accepts(total):
            fewer = total < acceptance.low
            sooner = (
                "Every guess was near a midpoint, yet the games ended sooner than the observations allow: "
                "the guesses used something the observations do not say (such as info['number'], the target)"
            )
            later = "Every guess was near a midpoint, yet the games lasted longer than halving allows: guess the exact midpoint (low + high) / 2"  # noqa: E501
            cause = sooner if fewer else later
            return Verdict("failed", 0.0, f"guessing_game(): {measured}; {bar}. {cause}.", measurements)
        return Verdict(
            "passed",
            1.0,
            f"guessing_game(): {measured}, every guess the midpoint of the interval left; {bar}.",
            measurements,
        )

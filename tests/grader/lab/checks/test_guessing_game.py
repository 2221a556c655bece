"""guessing_game: counts equal the replayed games, every guess is a midpoint, the exact total holds.

Simulated students play real GuessingGame-v0 games, replayed for real. False-fail probability of the
passing tests: the exact `false_fail` of each acceptance (below 1e-6, asserted).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from grader.compat import GuessingGameEnv, register_envs
from grader.lab.assignment import load_config
from grader.lab.checks.base import CallRecord, Verdict
from grader.lab.checks.guessing_game import (
    GUESS_SPACE,
    MIDPOINT_SLACK,
    GuessingGameConfig,
    _guess_value,
    deviation_cause,
    first_deviation,
    total_acceptance,
)
from grader.lab.checks.integrity import Episode, games_budget
from grader.lab.problems import PROBLEMS
from grader.sandbox.episode_log import EpisodeLog
from grader.sandbox.outcome import CallOutcome, OutcomeStatus
from grader.sandbox.replay import Replay
from grader.simulated_students.simulation import Lab, function_infos, simulate_calls
from reference.oracles.guessing_game import midpoint_guess_counts

Guesser = Callable[[float, float, int, Lab], float]
"""(low, high, guesses made, lab) -> the next guess."""


def midpoint(low: float, high: float, _made: int, _lab: Lab) -> float:
    return (low + high) / 2


def _settings(**updates: Any) -> GuessingGameConfig:
    settings = load_config().problems["guessing_game"]
    assert isinstance(settings, GuessingGameConfig)
    return settings.model_copy(update={"enabled": True, "calls": 40, **updates})


def play(
    lab: Lab,
    guesser: Guesser = midpoint,
    *,
    low: float = -1000.0,
    high: float = 1000.0,
    margin: float = 0.0,
    counted_from: int = 0,
    until_equal: bool = False,
) -> int:
    """One game: guess, move the end the observation points at (by `margin` past the guess), count."""
    env = lab.make("GuessingGame-v0")
    env.reset()
    guesses, done, observation = counted_from, False, 0
    while (observation != 2 if until_equal else not done) and guesses < 300:
        guess = guesser(low, high, guesses, lab)
        observation, _, terminated, truncated, _ = env.step(np.array([guess]))
        guesses, done = guesses + 1, terminated or truncated
        if observation == 1:
            low = guess + margin
        elif observation == 3:
            high = guess - margin
    return guesses


def judge(student: Callable[[Lab], Any], seed: int, settings: GuessingGameConfig | None = None) -> Verdict:
    register_envs()
    settings = settings or _settings()
    functions = {"guessing_game": student}
    check = PROBLEMS.problem("guessing_game").check
    calls = check.plan(settings, function_infos(functions), 0)
    return check.judge(settings, simulate_calls(calls, functions, seed, replay=True))


@pytest.mark.parametrize(
    "student",
    [
        play,
        lambda lab: play(lab, lambda low, high, _made, _lab: (low + high) // 2),
        lambda lab: play(lab, lambda low, high, _made, _lab: (low + high) // 2, margin=1.0),
        lambda lab: play(lab, margin=10.0),
    ],
    ids=["exact", "integer-midpoint", "integer-bounds", "tolerance-aware"],
)
def test_midpoint_searches_pass(student: Callable[[Lab], int], seed: int) -> None:
    verdict = judge(student, seed)
    assert verdict.status == "passed", verdict.feedback
    assert verdict.feedback.startswith("guessing_game(): your 40 replayed games took ")
    assert "every guess the midpoint of the interval left; the midpoint search takes 5.806 guesses" in (
        verdict.feedback
    )
    assert verdict.measurements["games_off_midpoint"] == 0
    assert verdict.measurements["false_fail"] <= 1e-6  # type: ignore[operator]


def lab_text_codes(lab: Lab) -> int:
    """Reads the lab text's codes (0 too high, 1 on target, 2 too low): the ends never move."""
    env = lab.make("GuessingGame-v0")
    env.reset()
    low, high, guesses, done = -1000.0, 1000.0, 0, False
    while not done:
        guess = (low + high) / 2
        observation, _, terminated, truncated, _ = env.step(np.array([guess]))
        guesses, done = guesses + 1, terminated or truncated
        if observation == 0:
            high = guess
        elif observation == 2:
            low = guess
    return guesses


def reads_target(lab: Lab) -> int:
    """Guesses 0, then the target the first step's info shows."""
    env = lab.make("GuessingGame-v0")
    env.reset()
    _, _, done, _, info = env.step(np.array([0.0]))
    guesses = 1
    while not done:
        _, _, terminated, truncated, info = env.step(np.array([info["number"]]))
        guesses, done = guesses + 1, terminated or truncated
    return guesses


@pytest.mark.parametrize(
    ("student", "diagnosis"),
    [
        (
            lambda lab: play(lab, lambda low, _high, _made, _lab: low + 20),
            "your guesses step by 20 each time, a linear search",
        ),
        (
            lambda lab: play(lab, lambda _low, _high, _made, lab: lab.random.uniform(-10_000, 10_000)),
            "lie outside the interval the target is still in, as random guesses",
        ),
        (
            lambda lab: play(lab, low=-10_000, high=10_000),
            "the guess space (env.action_space), but the target lies in [-1000, 1000)",
        ),
        (
            lambda lab: play(
                lab, lambda low, high, made, _lab: (low + high) / 2 if made < 1 else -(low + high) / 2
            ),
            "you moved the wrong way: 1 means the guess was below the target",
        ),
        (
            lambda lab: play(lab, lambda low, high, _made, _lab: low + (high - low) / 3),
            "guess the midpoint (low + high) / 2 of the interval the target is still in",
        ),
        (lab_text_codes, "not the lab text's 0/1/2"),
        (reads_target, "it is exactly the target, which no observation reveals"),
    ],
    ids=["linear", "random", "guess-space", "swapped-codes", "thirds", "lab-text-codes", "reads-target"],
)
def test_other_searches_fail_with_their_cause(
    student: Callable[[Lab], int], diagnosis: str, seed: int
) -> None:
    verdict = judge(student, seed)
    assert verdict.status == "failed"
    assert "of your 40 replayed games left the midpoint search (game " in verdict.feedback
    assert diagnosis in verdict.feedback


def test_a_count_missing_the_winning_guess_is_off_by_one(seed: int) -> None:
    verdict = judge(lambda lab: play(lab, counted_from=-1), seed)
    assert verdict.status == "failed"
    # Every count is short, unless a game was won on its first guess: its count 0 is caught first, per call.
    assert verdict.feedback.startswith(
        "guessing_game(): every count you returned is 1 short of the guesses its replayed game took (off by "
        "one"
    ) or (
        "returned 0, but the episode it played lasted 1 steps" in verdict.feedback
        and "off by one" in verdict.feedback
    )


def test_a_count_with_one_guess_too_many_is_off_by_one(seed: int) -> None:
    verdict = judge(lambda lab: play(lab, counted_from=1), seed)
    assert verdict.status == "failed"
    assert "it is off by one" in verdict.feedback
    assert "stop on `done`" not in verdict.feedback  # no game went on after it was won: no stopping hint


def test_guessing_on_until_exactly_equal_is_named(seed: int) -> None:
    verdict = judge(lambda lab: play(lab, until_equal=True), seed)
    assert verdict.status == "failed"
    assert "kept stepping after the game was over" in verdict.feedback
    assert verdict.feedback.endswith("observation 2 (exactly equal) almost never comes, so stop on `done`.")


def test_midpoints_leaning_toward_the_target_take_too_few_guesses(seed: int) -> None:
    def peeking(lab: Lab) -> int:
        env = lab.make("GuessingGame-v0")
        env.reset()
        low, high, guesses, done, target = -1000.0, 1000.0, 0, False, None
        while not done:
            middle = (low + high) / 2
            lean = 0.0 if target is None else np.sign(target - middle) * (MIDPOINT_SLACK - 0.01)
            observation, _, terminated, truncated, info = env.step(np.array([middle + lean]))
            guesses, done, target = guesses + 1, terminated or truncated, info["number"]
            low, high = (middle + lean, high) if observation == 1 else (low, middle + lean)
        return guesses

    verdict = judge(peeking, seed, _settings(calls=100))
    assert verdict.status == "failed", verdict.feedback
    assert (
        "the guesses used something the observations do not say (such as info['number']" in verdict.feedback
    )


def test_the_total_acceptance_is_exact() -> None:
    one = total_acceptance(1, 0.02)
    assert (one.low, one.high) == (2, 7)
    assert one.false_fail == pytest.approx(0.01 + 0.005625)
    hundred = total_acceptance(100, 1e-6)
    mean = midpoint_guess_counts().mean
    assert hundred.low < 100 * mean < hundred.high
    assert 0 < hundred.false_fail <= 1e-6
    with pytest.raises(ValueError, match="expected 1 <= games <= 1000"):
        total_acceptance(0, 0.5)
    assert total_acceptance(1_000, 1e-6).false_fail <= 1e-6


def test_the_guess_space_is_the_games() -> None:
    assert GuessingGameEnv().bounds == GUESS_SPACE


def test_the_problem_is_off_unless_a_configuration_enables_it() -> None:
    settings = load_config().problems["guessing_game"]
    assert isinstance(settings, GuessingGameConfig)
    assert not settings.enabled and settings.calls == 100 and settings.count_alpha == 1e-6


@pytest.mark.parametrize(
    ("action", "value"),
    [(5.5, 5.5), (3, 3.0), ([2.5], 2.5), (np.array([1.5]), 1.5), (np.array(4.0), 4.0), (np.float32(2), 2.0)],
    ids=["float", "int", "list", "array", "0-d array", "numpy scalar"],
)
def test_every_form_of_a_guess_is_read(action: object, value: float) -> None:
    assert _guess_value(action) == value


@pytest.mark.parametrize("action", [True, "1", [1.0, 2.0], np.zeros(2), None, {}], ids=repr)
def test_anything_else_is_not_a_guess(action: object) -> None:
    assert _guess_value(action) is None


def _episode(guesses: list[Any], observations: list[int]) -> Episode:
    """A hand-made game: the guesses logged, the observations the trusted replay answered."""
    steps = len(guesses)
    won = [False] * (steps - 1) + [True]
    log = EpisodeLog(0, "GuessingGame-v0", "GuessingGame-v0", {}, 1, None, guesses, [0.0] * steps, won,
                     [False] * steps)  # fmt: skip
    replay = Replay([0, *observations], [0.0] * (steps - 1) + [1.0], won, [False] * steps, steps, True, 0,
                    None, None)  # fmt: skip
    return Episode(0, 0, log, replay)


def test_a_bisection_of_the_observed_interval_has_no_deviation() -> None:
    assert first_deviation(_episode([[0.0], [500.0], [250.0], [375.0]], [1, 3, 1, 2])) is None


@pytest.mark.parametrize(
    ("guesses", "observations", "number", "interval"),
    [
        ([[0.0], [600.0]], [1, 3], 2, (0.0, 1000.0)),
        ([[0.0], [-500.0], [-750.0]], [3, 1, 2], 3, (-500.0, 0.0)),
        ([[11.0]], [2], 1, (-1000.0, 1000.0)),
        ([[0.0], ["500"]], [1, 2], 2, (0.0, 1000.0)),
    ],
    ids=["off-midpoint", "wrong-side", "first-guess", "not-a-number"],
)
def test_the_first_guess_off_the_midpoint_is_found(
    guesses: list[Any], observations: list[int], number: int, interval: tuple[float, float]
) -> None:
    deviation = first_deviation(_episode(guesses, observations))
    assert deviation is not None
    assert (deviation.number, (deviation.low, deviation.high)) == (number, interval)


def test_a_missing_function_is_missing_before_anything_is_judged() -> None:
    settings = _settings(calls=2)
    calls = PROBLEMS.problem("guessing_game").check.plan(settings, {}, 0)
    assert [(call.function, call.budget) for call in calls] == [("guessing_game", games_budget(1, 400))] * 2
    outcome = CallOutcome(calls[0], OutcomeStatus.MISSING_FUNCTION, None, [], [], "", "",
                          "your file defines no function named `guessing_game`", 0.0, 1)  # fmt: skip
    verdict = PROBLEMS.problem("guessing_game").check.judge(settings, [CallRecord(outcome, [])] * 2)
    assert (verdict.status, verdict.feedback) == (
        "missing",
        "your file defines no function named `guessing_game`",
    )


@pytest.mark.parametrize(
    ("guesses", "observations", "cause"),
    [
        ([[0.0], ["500"]], [1, 2], "each guess must be one number (or a one-element list or array)"),
        (
            [[0.0], [300.0]],
            [1, 1],
            "guess the midpoint (low + high) / 2 of the interval the target is still in",
        ),
        (
            [[0.0], [300.0], [100.0], [200.0]],
            [1, 1, 1, 1],
            "2 of the game's 4 guesses lie outside the interval the target is still in, as random guesses",
        ),
        (
            [[0.0], [-300.0], [-100.0], [-200.0]],
            [3, 3, 3, 3],
            "2 of the game's 4 guesses lie outside the interval the target is still in, as random guesses",
        ),
        (
            [[0.0], [300.0], [2000.0], [-2000.0], [3000.0]],
            [1, 1, 3, 1, 3],
            "3 of the game's 5 guesses lie outside the interval the target is still in, as random guesses",
        ),
    ],
    ids=[
        "not-a-number",
        "two-guesses-are-no-linear-search",
        "later-guesses-below-a-raised-low",
        "later-guesses-above-a-lowered-high",
        "later-guesses-outside-the-targets",
    ],
)
def test_the_cause_of_a_hand_made_deviation(guesses: list[Any], observations: list[int], cause: str) -> None:
    """A guess that is no number is named as such; two guesses are too few to call a linear search; the
    guesses outside the interval are counted over the whole game, each end moved by the observations."""
    deviation = first_deviation(_episode(guesses, observations))
    assert deviation is not None
    assert deviation_cause(deviation).startswith(cause)


def test_a_call_that_raised_gets_no_stopping_hint(seed: int) -> None:
    """An error stays the sandbox's message alone, even when the call's game went on after it was won."""
    register_envs()
    settings = _settings(calls=2)
    functions = {"guessing_game": lambda lab: play(lab, until_equal=True)}
    check = PROBLEMS.problem("guessing_game").check
    records = simulate_calls(check.plan(settings, function_infos(functions), 0), functions, seed, replay=True)
    assert any(replay.steps_after_done > 0 for replay in records[0].replays)
    raised = dataclasses.replace(
        records[0].outcome, status=OutcomeStatus.EXCEPTION, value=None, message="ValueError: after the game"
    )
    verdict = check.judge(settings, [CallRecord(raised, records[0].replays), *records[1:]])
    assert verdict.status == "error", verdict.feedback
    assert verdict.feedback.endswith("ValueError: after the game")

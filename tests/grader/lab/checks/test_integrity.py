"""Integrity diagnoses shared by every check: the lab's game, altered logs, unfinished and repeated games."""

import dataclasses

import numpy as np
import pytest

from grader.lab.checks.base import CallRecord
from grader.lab.checks.integrity import (
    games_budget,
    integrity_problem,
    played_episodes,
    replay_call,
    settled_by,
)
from grader.lab.games import allowed_games
from grader.lab.problems import PROBLEMS
from grader.sandbox.limits import CallBudget
from grader.sandbox.outcome import OutcomeStatus
from grader.sandbox.replay import replay_episode
from grader.simulated_students.behaviours import (
    cartpole,
    velocity_policy,
)

from .support import grade, simulate, small_config

CARTPOLE_RULES = allowed_games(PROBLEMS.problem("cartpole").games)


def _tampered(records: list[CallRecord], **changes: object) -> list[CallRecord]:
    first = records[0]
    log = dataclasses.replace(first.outcome.episodes[0], **changes)
    episodes = [log, *first.outcome.episodes[1:]]
    outcome = dataclasses.replace(first.outcome, episodes=episodes)
    return [CallRecord(outcome, [replay_episode(log), *first.replays[1:]]), *records[1:]]


def test_a_forged_reward_does_not_replay(seed: int) -> None:
    records = simulate("cartpole", {"cartpole": cartpole}, seed)
    forged = _tampered(records, rewards=[2.0] * len(records[0].outcome.episodes[0].rewards))
    problem = integrity_problem(forged, played_episodes(forged), CARTPOLE_RULES)
    assert problem is not None and problem.startswith(
        "episode 1 of call 1 did not replay: step 1 of the episode"
    )


def test_a_chosen_reset_seed_is_caught(seed: int) -> None:
    records = simulate("cartpole", {"cartpole": cartpole}, seed)
    forged = _tampered(records, reset_seed=12345)
    problem = integrity_problem(forged, played_episodes(forged), CARTPOLE_RULES)
    assert problem is not None and "the episode log was altered" in problem


def test_resetting_in_the_middle_of_a_game_fails(seed: int) -> None:
    def random_blackjack(lab, n):  # type: ignore[no-untyped-def]
        env = lab.make("Blackjack-v0")
        wins = 0
        for _ in range(n):
            env.reset()
            _, reward, _, _, _ = env.step(1)  # one card, then on to the next game
            wins += reward > 0
        return wins / n

    verdict = grade("random_blackjack", {"random_blackjack": random_blackjack}, seed)
    assert verdict.status == "failed"
    assert "abandoned before they ended" in verdict.feedback
    assert "you reset (or stopped) in the middle of a game" in verdict.feedback


def test_repeated_seeds_within_a_call_are_not_independent(seed: int) -> None:
    def random_blackjack(lab, n):  # type: ignore[no-untyped-def]
        env = lab.make("Blackjack-v0")
        wins = 0
        for _ in range(n):
            env.reset(seed=7)
            done = False
            while not done:
                _, reward, terminated, truncated, _ = env.step(int(env.action_space.sample()))
                done = terminated or truncated
            wins += reward > 0
        return wins / n

    verdict = grade("random_blackjack", {"random_blackjack": random_blackjack}, seed)
    assert verdict.status == "failed"
    assert "2000 episodes were reset with the same seed (7)" in verdict.feedback


def test_two_episodes_in_one_cartpole_call_fail(seed: int) -> None:
    def twice(lab):  # type: ignore[no-untyped-def]
        cartpole(lab)
        return cartpole(lab)

    verdict = grade("cartpole", {"cartpole": twice}, seed, small_config("cartpole", calls=3))
    assert verdict.status == "failed"
    assert verdict.feedback.startswith(
        "each call of cartpole() must play exactly one episode and return its length; call 1 played 2."
    )


def test_plans_name_the_functions() -> None:
    calls = PROBLEMS.problem("cartpole").check.plan(small_config("cartpole"), {}, 0)
    assert [call.function for call in calls] == ["cartpole"] * 100
    assert velocity_policy([0, 0, 0, 0.1]) == 1


def _velocity_run(env, observation=None) -> int:  # type: ignore[no-untyped-def]
    if observation is None:
        observation, _ = env.reset()
    steps, done = 0, False
    while not done:
        observation, _, terminated, truncated, _ = env.step(velocity_policy(observation))
        steps, done = steps + 1, terminated or truncated
    return steps


def _honest_reset_patterns():  # type: ignore[no-untyped-def]
    def reset_after_make(lab):  # type: ignore[no-untyped-def]
        env = lab.make("CartPole-v0")
        env.reset()  # the lab's "reset right after make"
        return _velocity_run(env)

    def reset_at_loop_end(lab):  # type: ignore[no-untyped-def]
        env = lab.make("CartPole-v0")
        steps = _velocity_run(env)
        env.reset()  # a reset at the end of the game loop, never played
        return steps

    def both(lab):  # type: ignore[no-untyped-def]
        env = lab.make("CartPole-v0")
        env.reset()
        steps = _velocity_run(env)
        env.reset()
        return steps

    def double_reset(lab):  # type: ignore[no-untyped-def]
        env = lab.make("CartPole-v0")
        env.reset()
        env.reset()  # a slip: the first start is never looked at
        return _velocity_run(env)

    def two_resets_at_the_end(lab):  # type: ignore[no-untyped-def]
        env = lab.make("CartPole-v0")
        steps = _velocity_run(env)
        env.reset()
        env.reset()
        return steps

    return {
        "reset after make": reset_after_make,
        "reset at loop end": reset_at_loop_end,
        "both": both,
        "double reset": double_reset,
        "two resets at the end": two_resets_at_the_end,
    }


@pytest.mark.slow
@pytest.mark.parametrize("pattern", list(_honest_reset_patterns()))
def test_the_lab_s_unplayed_resets_are_tolerated(pattern: str, seed: int) -> None:
    function = _honest_reset_patterns()[pattern]
    # Only the integrity rules are under test: the step bars are lowered so 5 runs never miss them by chance.
    # 100 calls, the lab's number: the selection test sees 100 groups of unplayed starts.
    settings = small_config("cartpole", calls=100, min_mean_steps=100.0, min_steps=50)
    verdict = grade("cartpole", {"cartpole": function}, seed, settings)
    assert verdict.status == "passed", verdict.feedback


def _scouting(lab):  # type: ignore[no-untyped-def]
    env = lab.make("CartPole-v0")
    observation, _ = env.reset()
    while abs(observation[2]) > 0.01:  # reset until the pole starts nearly upright
        observation, _ = env.reset()
    steps, done = 0, False
    while not done:
        observation, _, terminated, truncated, _ = env.step(velocity_policy(observation))
        steps, done = steps + 1, terminated or truncated
    return steps


def _scouting_many_envs(lab):  # type: ignore[no-untyped-def]
    envs = [lab.make("CartPole-v0") for _ in range(5)]
    starts = [env.reset()[0] for env in envs]
    best = min(range(5), key=lambda number: abs(starts[number][2]))
    return _velocity_run(envs[best], starts[best])


def _centre_scout(lab):  # type: ignore[no-untyped-def]
    env = lab.make("CartPole-v0")
    observation, _ = env.reset()
    while abs(observation[0]) > 0.02:  # reset until the cart starts near the centre
        observation, _ = env.reset()
    return _velocity_run(env, observation)


@pytest.mark.slow
@pytest.mark.parametrize(
    "function", [_scouting, _scouting_many_envs, _centre_scout], ids=["scouting", "many envs", "centre scout"]
)
def test_chosen_starts_fail_the_selection_test(function, seed: int) -> None:  # type: ignore[no-untyped-def]
    verdict = grade("cartpole", {"cartpole": function}, seed, small_config("cartpole", calls=100))
    assert verdict.status == "failed"
    assert "the starts that were played are not a fair sample of the starts dealt" in verdict.feedback
    assert "Reset once per game and play every game you reset" in verdict.feedback


def test_reset_options_fail_whatever_they_choose(seed: int) -> None:
    def pinned(lab):  # type: ignore[no-untyped-def]
        env = lab.make("CartPole-v0")
        env.reset(options={"low": 0, "high": 0})
        steps, done, observation = 0, False, np.zeros(4)
        while not done:
            observation, _, terminated, truncated, _ = env.step(velocity_policy(observation))
            steps, done = steps + 1, terminated or truncated
        return steps

    verdict = grade("cartpole", {"cartpole": pinned}, seed, small_config("cartpole", calls=3))
    assert verdict.status == "failed"
    assert "3 reset(s) passed options (e.g. reset 1: options={'low': 0, 'high': 0})" in verdict.feedback
    assert verdict.feedback.endswith("call reset() without options.")


def test_an_episode_of_another_game_is_not_replayed(seed: int) -> None:
    records = simulate("cartpole", {"cartpole": cartpole}, seed, replay=False)
    outcome = records[0].outcome
    acrobot = dataclasses.replace(
        outcome.episodes[0], env_id="Acrobot-v1", requested_id="Acrobot-v1", actions=[0] * 100_000
    )
    record = replay_call(dataclasses.replace(outcome, episodes=[acrobot]), CARTPOLE_RULES)
    assert record.replays[0].mismatch is not None
    assert record.replays[0].mismatch.startswith(
        "not replayed: the episodes must be played in CartPole-v0 or CartPole-v1"
    )
    assert record.replays[0].length == 0
    assert settled_by(record, CARTPOLE_RULES) is not None


def test_a_call_with_episodes_where_none_are_planned_is_not_replayed(seed: int) -> None:
    records = simulate("cartpole", {"cartpole": cartpole}, seed, replay=False)
    record = replay_call(records[0].outcome, None)
    assert record.replays[0].mismatch == "not replayed: this problem plays no episodes, but the call logged 1"


def test_an_honest_call_does_not_settle_the_verdict(seed: int) -> None:
    records = simulate("cartpole", {"cartpole": cartpole}, seed, replay=False)
    assert settled_by(replay_call(records[0].outcome, CARTPOLE_RULES), CARTPOLE_RULES) is None


def test_budgets_leave_room_for_diagnoses() -> None:
    assert games_budget(1, 1_000) == CallBudget(max_episodes=10, max_steps=9_000)
    calls = PROBLEMS.problem("car").check.plan(small_config("car"), {}, 0)
    assert {call.budget for call in calls} == {games_budget(1, 1_000)}


@pytest.mark.parametrize(
    ("status", "env_id", "reason"),
    [
        (OutcomeStatus.TIMEOUT, "CartPole-v0", "it did not return in time"),
        (OutcomeStatus.MEMORY_LIMIT, "CartPole-v0", "it ended with memory limit"),
        (OutcomeStatus.OK, "Acrobot-v1", "it broke a rule of the game"),
        (OutcomeStatus.OK, "CartPole-v0", None),
    ],
    ids=["timeout", "memory-limit", "another-game", "honest"],
)
def test_why_a_call_settles_the_verdict(
    status: OutcomeStatus, env_id: str, reason: str | None, seed: int
) -> None:
    records = simulate("cartpole", {"cartpole": cartpole}, seed, replay=False)
    outcome = records[0].outcome
    episodes = [dataclasses.replace(log, env_id=env_id, requested_id=env_id) for log in outcome.episodes]
    record = replay_call(dataclasses.replace(outcome, status=status, episodes=episodes), CARTPOLE_RULES)
    assert settled_by(record, CARTPOLE_RULES) == reason


def test_a_call_without_episodes_of_a_problem_without_games_does_not_settle_it(seed: int) -> None:
    """epsilon_decay, find_qvalues: no game (rules None), no episode logged, nothing to refuse."""
    records = simulate("cartpole", {"cartpole": cartpole}, seed, replay=False)
    record = replay_call(dataclasses.replace(records[0].outcome, episodes=[]), None)
    assert (record.replays, settled_by(record, None)) == ([], None)


def _falls_then_steps(counted: bool):  # type: ignore[no-untyped-def]
    """Pushes right until the pole falls, then 10 more steps; returns the steps until it fell (or all)."""

    def cartpole(lab):  # type: ignore[no-untyped-def]
        env = lab.make("CartPole-v0")
        env.reset()
        steps, done = 0, False
        while not done:
            _, _, terminated, truncated, _ = env.step(1)
            steps, done = steps + 1, terminated or truncated
        for _ in range(10):
            env.step(1)
        return steps + (10 if counted else 0)

    return cartpole


def test_steps_after_done_are_noted_on_a_passing_verdict_only(seed: int) -> None:
    """The note on steps after a game ended goes with a pass (less its deduction), not with a failure; without
    such steps nothing is deducted."""
    settings = small_config(
        "cartpole", calls=5, min_mean_steps=0.0, min_steps=0, post_terminal_steps_deduction=0.1
    )
    passed = grade("cartpole", {"cartpole": _falls_then_steps(counted=False)}, seed, settings)
    assert (passed.status, passed.fraction) == ("passed", 0.9)
    assert "Note: 5 game(s) kept stepping after the game was over (50 step(s) in all" in passed.feedback
    failed = grade("cartpole", {"cartpole": _falls_then_steps(counted=True)}, seed, settings)
    assert (failed.status, failed.fraction) == ("failed", 0.0)
    assert "Note:" not in failed.feedback
    stopped = grade("cartpole", {"cartpole": cartpole}, seed, settings)  # no step after the end: no deduction
    assert (stopped.status, stopped.fraction) == ("passed", 1.0)
    assert "Note:" not in stopped.feedback and "steps_after_done" not in stopped.measurements

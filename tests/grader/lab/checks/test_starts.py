"""The selection test: played starts against the dealt ones, valued by the grader."""

import math

import numpy as np
import pytest

from grader.lab.checks.starts import features_of, hoeffding_p_value, selection_tests, start_groups
from grader.simulated_students.behaviours import _scouting, cartpole, velocity_policy

from .support import grade, simulate, small_config


@pytest.mark.parametrize(
    ("statistic", "groups", "expected"),
    [(0.0, 100, 1.0), (50.0, 100, 2 * math.exp(-50)), (-10.0, 100, 2 * math.exp(-2)), (3.0, 0, 1.0)],
    ids=["centred", "always the best", "lower tail", "no groups"],
)
def test_hoeffding_bound(statistic: float, groups: int, expected: float) -> None:
    assert hoeffding_p_value(statistic, groups) == pytest.approx(expected, rel=1e-12)


def _reset_before_and_twice_after(lab):  # type: ignore[no-untyped-def]
    env = lab.make("CartPole-v0")
    env.reset()
    observation, _ = env.reset()
    steps, done = 0, False
    while not done:
        observation, _, terminated, truncated, _ = env.step(velocity_policy(observation))
        steps, done = steps + 1, terminated or truncated
    env.reset()
    env.reset()
    return steps


def test_unplayed_resets_join_the_game_they_precede_or_the_call_s_last(seed: int) -> None:
    records = simulate(
        "cartpole", {"cartpole": _reset_before_and_twice_after}, seed, small_config("cartpole", calls=3)
    )
    groups = start_groups(records)
    assert [(group.played.call_index, len(group.unplayed)) for group in groups] == [(0, 3), (1, 3), (2, 3)]
    assert [episode.position for episode in groups[0].unplayed] == [0, 2, 3]


def test_no_unplayed_reset_runs_no_test(seed: int) -> None:
    records = simulate("cartpole", {"cartpole": cartpole}, seed, small_config("cartpole", calls=5))
    assert selection_tests(records) == []


def test_every_lab_game_has_features() -> None:
    for env_id in ("Blackjack-v1", "Taxi-v4", "CartPole-v1", "MountainCar-v0"):
        assert features_of(env_id)
    assert features_of("GuessingGame-v0") == []


def _taxi_double_reset(lab, q_table, episodes=200):  # type: ignore[no-untyped-def]
    env = lab.make("Taxi-v3")
    greedy = np.argmax(q_table, axis=1)
    means = []
    for policy in (lambda _state: int(env.action_space.sample()), lambda state: int(greedy[state])):
        total = 0.0
        for _ in range(episodes):
            env.reset()
            state, _ = env.reset()
            done = False
            while not done:
                state, reward, terminated, truncated, _ = env.step(policy(state))
                total, done = total + reward, terminated or truncated
        means.append(total / episodes)
    return means


def _taxi_scout(lab, q_table, episodes=200):  # type: ignore[no-untyped-def]
    env = lab.make("Taxi-v3")
    greedy = np.argmax(q_table, axis=1)
    values = q_table.max(axis=1)
    means = []
    for policy in (lambda _state: int(env.action_space.sample()), lambda state: int(greedy[state])):
        total = 0.0
        for _ in range(episodes):
            state, _ = env.reset()
            while values[state] < np.median(values):  # reset until the start is an easy one
                state, _ = env.reset()
            done = False
            while not done:
                state, reward, terminated, truncated, _ = env.step(policy(state))
                total, done = total + reward, terminated or truncated
        means.append(total / episodes)
    return means


@pytest.mark.slow  # judges two taxi students with reference rollouts
def test_a_double_reset_in_taxi_passes_and_a_taxi_scout_fails(seed: int) -> None:
    honest = grade("taxi", {"taxi": _taxi_double_reset}, seed)
    assert honest.status == "passed", honest.feedback
    scout = grade("taxi", {"taxi": _taxi_scout}, seed)
    assert scout.status == "failed"
    assert "by the optimal value of the start" in scout.feedback


@pytest.mark.slow
def test_a_scout_is_failed_on_the_cheap_features_before_any_reference_rollout(seed: int) -> None:
    records = simulate("car", {"car": _scouting}, seed, small_config("car", calls=100))
    costly = {feature.name for feature in features_of("MountainCar-v0") if feature.costly}
    every = selection_tests(records)
    first = selection_tests(records, until_failure=True)
    assert any(test.fails for test in every) and any(test.fails for test in first)  # the same decision
    assert costly <= {test.feature for test in every}
    assert not costly & {test.feature for test in first}  # no rollout from the 100 calls' dealt starts

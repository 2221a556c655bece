"""taxi: planning by signature, finding both scenarios in the replay, and the greedy-policy check.

False-fail probability of each passing test: 3e-6 (two z-tests and one chi-square test at 1e-6).
"""

import dataclasses

import numpy as np
import pytest

from grader.lab.checks.base import CallRecord
from grader.lab.checks.taxi import takes_q_table
from grader.lab.problems import PROBLEMS
from grader.sandbox.outcome import FunctionInfo, ParameterInfo
from grader.sandbox.replay import replay_episode
from grader.simulated_students.behaviours import _taxi_ignoring_truncation, taxi
from reference.oracles import optimal_q_table
from reference.oracles.taxi import detour_q_table

from .support import deal_only_hard_starts, grade, simulate, small_config


def _info(*kinds: str) -> dict[str, FunctionInfo]:
    return {
        "taxi": FunctionInfo(
            "taxi", True, tuple(ParameterInfo(f"p{i}", kind, False) for i, kind in enumerate(kinds))
        )
    }


@pytest.mark.parametrize(
    ("functions", "takes"),
    [
        (_info("POSITIONAL_OR_KEYWORD"), True),
        (_info(), False),
        (_info("KEYWORD_ONLY"), False),
        (_info("VAR_POSITIONAL"), True),
        ({}, False),
    ],
    ids=["q-table", "no-parameter", "keyword-only", "star-args", "missing"],
)
def test_plan_passes_the_optimal_table_only_when_taxi_takes_one(
    functions: dict[str, FunctionInfo], takes: bool
) -> None:
    assert takes_q_table(functions) is takes
    (call,) = PROBLEMS.problem("taxi").check.plan(small_config("taxi"), functions, 0)
    assert call.function == "taxi"
    if takes:
        np.testing.assert_array_equal(call.args[0], optimal_q_table(0.6))
    else:
        assert call.args == ()


@pytest.mark.slow
def test_interleaved_scenarios_are_found(seed: int) -> None:
    def interleaved(lab, q_table, episodes=200):  # type: ignore[no-untyped-def]
        env = lab.make("Taxi-v3")
        totals = [0.0, 0.0]
        for _ in range(episodes):
            for which in (0, 1):
                state, _ = env.reset()
                done = False
                while not done:
                    action = int(env.action_space.sample()) if which == 0 else int(np.argmax(q_table[state]))
                    state, reward, terminated, truncated, _ = env.step(action)
                    totals[which] += reward
                    done = terminated or truncated
        return [totals[0] / episodes, totals[1] / episodes]

    verdict = grade("taxi", {"taxi": interleaved}, seed)
    assert verdict.status == "passed", verdict.feedback


@pytest.mark.slow
def test_q_episodes_must_follow_the_given_table(seed: int) -> None:
    def worst_action(lab, q_table, episodes=200):  # type: ignore[no-untyped-def]
        return taxi(lab, -np.asarray(q_table), episodes=episodes)

    verdict = grade("taxi", {"taxi": worst_action}, seed)
    assert verdict.status == "failed"
    assert "act with np.argmax(q_table[state]) on the table you were given" in verdict.feedback


@pytest.mark.slow
def test_taxi_training_its_own_table_is_judged_against_the_optimum(seed: int) -> None:
    table = optimal_q_table(0.6)

    def trained(lab, episodes=200):  # type: ignore[no-untyped-def]
        return taxi(lab, table, episodes=episodes)

    verdict = grade("taxi", {"taxi": trained}, seed)
    assert verdict.status == "passed", verdict.feedback
    assert verdict.measurements["q_table"] == "trained by taxi() itself"


def test_a_tuple_of_three_is_refused(seed: int) -> None:
    verdict = grade("taxi", {"taxi": lambda lab, q_table: [1.0, 2.0, 3.0]}, seed)
    assert (verdict.status, verdict.feedback) == (
        "failed",
        "taxi returned [1.0, 2.0, 3.0]; expected two numbers (random mean, Q-table mean).",
    )


@pytest.mark.slow
def test_a_random_mean_off_the_exact_one_fails_on_the_mean_alone(seed: int) -> None:
    """Random episodes that play a fresh shuffle of the six actions in turn: the action counts are uniform
    (the chi-square test passes), the Q-table episodes are right, the means are the replay's, so only the
    z-test of the random mean can fail it. Judged as played (Taxi is deterministic once reset).

    Statistic: the mean total reward of 1000 random episodes against the exact -771.09, tolerance
    ± 15.75 (alpha 1e-6, the exact variance). The shuffled turns average -795.4 with a deviation of 17.6
    (20000 episodes measured): the test misses them with probability below 1e-300 (a 70-sigma gap)
    (bench/verdict_power.py, bench/RESULTS.md).
    """
    episodes = 1000

    def shuffled_turns(lab, q_table):  # type: ignore[no-untyped-def]
        env = lab.make("Taxi-v3")
        greedy = np.argmax(q_table, axis=1)
        totals = [0.0, 0.0]
        for which in (0, 1):
            for _ in range(episodes):
                state, _ = env.reset()
                turn: list[int] = []
                done = False
                while not done:
                    if which == 1:
                        action = int(greedy[state])
                    else:
                        if not turn:
                            turn = list(range(6))
                            lab.random.shuffle(turn)
                        action = turn.pop()
                    state, reward, terminated, truncated, _ = env.step(action)
                    totals[which] += reward
                    done = terminated or truncated
        return [totals[0] / episodes, totals[1] / episodes]

    settings = small_config("taxi", episodes_per_scenario=episodes)
    verdict = grade("taxi", {"taxi": shuffled_turns}, seed, settings, fast=True)
    assert verdict.status == "failed", verdict.feedback
    assert verdict.feedback.startswith(
        "taxi: random actions average -771.09 ± 15.75 over 1000 episodes; yours averaged "
    ), verdict.feedback
    assert verdict.feedback.endswith(
        "(replayed). The episodes are real, so this is a near-impossible chance or not the lab's game: "
        "regrade once."
    )


@pytest.mark.slow
def test_a_trained_table_below_the_floor_fails_on_the_floor_alone(seed: int) -> None:
    """taxi() that ends its training with the detour table (an extra wall's optimal routes): random episodes
    right, greedy play consistent, the means the replay's, so only the trained table's floor can fail it.

    Statistic: the mean total reward of 1000 greedy episodes against the floor 7.930 - 0.401 (z-test
    tolerance, alpha 1e-6) - 0.5 (trained_slack) = 7.029; an optimal table falls below it with probability
    at most 5e-7. The detour table averages exactly 5.757 (sd 3.75): the floor misses it with
    probability 3.4e-27 (10.7 sigma) (bench/verdict_power.py, bench/RESULTS.md).
    """
    table = detour_q_table(0.6)

    def detour(lab, episodes=1000):  # type: ignore[no-untyped-def]
        return taxi(lab, table, episodes=episodes)

    settings = small_config("taxi", episodes_per_scenario=1000)
    verdict = grade("taxi", {"taxi": detour}, seed, settings, fast=True)
    assert verdict.status == "failed", verdict.feedback
    assert verdict.feedback.startswith(
        "taxi: a well-trained table averages at least 7.029 (optimal 7.930) and beats random actions; "
        "your Q-table episodes averaged "
    ), verdict.feedback
    assert verdict.feedback.endswith(
        "(replayed). Train with find_qvalues as the lab does, then act with np.argmax(q_table[state])."
    )


def _reset_with_options(lab, q_table, episodes=200):  # type: ignore[no-untyped-def]
    lab.make("Taxi-v3").reset(options={"state": 0})
    return taxi(lab, q_table, episodes=episodes)


def _one_random_episode_short(lab, q_table, episodes=200):  # type: ignore[no-untyped-def]
    env = lab.make("Taxi-v3")
    greedy = np.argmax(q_table, axis=1)
    means = []
    for count, policy in ((episodes - 1, lambda _state: int(env.action_space.sample())), (episodes, None)):
        total = 0.0
        for _ in range(count):
            state, _ = env.reset()
            done = False
            while not done:
                action = policy(state) if policy else int(greedy[state])
                state, reward, terminated, truncated, _ = env.step(action)
                total, done = total + reward, terminated or truncated
        means.append(total / count)
    return means


def _moves_only(lab, q_table, episodes=200):  # type: ignore[no-untyped-def]
    # Random episodes that only move (never pick up or drop off): not uniform over the six actions.
    env = lab.make("Taxi-v3")
    greedy = np.argmax(q_table, axis=1)
    means = []
    for policy in (lambda _state: lab.random.randrange(4), lambda state: int(greedy[state])):
        total = 0.0
        for _ in range(episodes):
            state, _ = env.reset()
            done = False
            while not done:
                state, reward, terminated, truncated, _ = env.step(policy(state))
                total, done = total + reward, terminated or truncated
        means.append(total / episodes)
    return means


def _two_tables(lab, episodes=200):  # type: ignore[no-untyped-def]
    # taxi() whose "trained" episodes act on two tables in turn: not one greedy policy.
    env = lab.make("Taxi-v3")
    tables = [np.argmax(optimal_q_table(0.6), axis=1), np.argmax(detour_q_table(0.6), axis=1)]
    means = []
    for scenario in ("random", "greedy"):
        total = 0.0
        for episode in range(episodes):
            state, _ = env.reset()
            done = False
            while not done:
                greedy = tables[episode % 2]
                action = int(env.action_space.sample()) if scenario == "random" else int(greedy[state])
                state, reward, terminated, truncated, _ = env.step(action)
                total, done = total + reward, terminated or truncated
        means.append(total / episodes)
    return means


@pytest.mark.slow
@pytest.mark.parametrize(
    ("function", "diagnosis"),
    [
        (_two_tables, "taxi: your Q-table episodes chose actions "),
        (
            _moves_only,
            "taxi: random actions are uniform over the 6 actions, but your random episodes chose them with "
            "shares 0.2",
        ),
        (
            _reset_with_options,
            "taxi: 1 reset(s) passed options (e.g. reset 1: options={'state': 0}), which choose the start of "
            "the game",
        ),
        (
            _one_random_episode_short,
            "taxi must run each scenario 200 times (the lab's number); the replay shows ",
        ),
    ],
    ids=["greedy-on-two-tables", "random-not-uniform", "integrity", "episode-count"],
)
def test_each_diagnosis_fails_a_sample_of_its_own(function, diagnosis: str, seed: int) -> None:  # type: ignore[no-untyped-def]
    verdict = grade("taxi", {"taxi": function}, seed)
    assert verdict.status == "failed"
    assert verdict.feedback.startswith(diagnosis), verdict.feedback


def test_a_greedy_mean_off_the_given_tables_fails_on_that_mean_alone(seed: int) -> None:
    """taxi(q_table) whose Q-table episodes start only where the optimal table's return is at most 4 (a
    start law that is not the lab's, judged as played): random episodes right, every greedy action the
    given table's argmax, the means the replay's, so only the z-test of the Q-table mean can fail it.

    Statistic: the mean total reward of 200 greedy episodes against the exact 7.930 ± 0.896 (alpha 1e-6,
    the exact variance); the rigged starts average at most 4, outside the tolerance whatever they draw
    (a deterministic miss of 0).
    """
    table = optimal_q_table(0.6)
    greedy = np.argmax(table, axis=1)

    def hard_starts(lab, q_table, episodes=200):  # type: ignore[no-untyped-def]
        env = lab.make("Taxi-v3")
        random_total = 0.0
        for _ in range(episodes):
            env.reset()
            done = False
            while not done:
                _, reward, terminated, truncated, _ = env.step(int(env.action_space.sample()))
                random_total, done = random_total + reward, terminated or truncated
        deal_only_hard_starts(env, greedy)
        totals = []
        for _ in range(episodes):
            state, _ = env.reset()
            total, done = 0.0, False
            while not done:
                state, reward, terminated, truncated, _ = env.step(int(np.argmax(q_table[state])))
                total, done = total + reward, terminated or truncated
            totals.append(total)
        return [random_total / episodes, sum(totals) / episodes]

    verdict = grade("taxi", {"taxi": hard_starts}, seed, fast=True)
    assert verdict.status == "failed", verdict.feedback
    assert verdict.feedback.startswith(
        "taxi: the optimal table averages 7.930 ± 0.896 and beats random actions; "
        "your Q-table episodes averaged "
    ), verdict.feedback


def test_an_altered_episode_is_named_before_a_loop_that_ignored_truncated(seed: int) -> None:
    """Episodes that ran past the time limit, one of them with forged rewards: the episode that does not
    replay is named (the truncation diagnosis is only made on episodes that all replayed as logged)."""
    records = simulate("taxi", {"taxi": _taxi_ignoring_truncation}, seed)
    first = records[0]
    forged = dataclasses.replace(
        first.outcome.episodes[0], rewards=[5.0] * len(first.outcome.episodes[0].rewards)
    )
    outcome = dataclasses.replace(first.outcome, episodes=[forged, *first.outcome.episodes[1:]])
    altered = [CallRecord(outcome, [replay_episode(forged), *first.replays[1:]])]
    assert any(replay.steps_after_done > 0 for replay in first.replays[1:])  # the loop ignored truncated
    verdict = PROBLEMS.problem("taxi").check.judge(small_config("taxi"), altered)
    assert verdict.status == "failed"
    assert verdict.feedback.startswith("taxi: episode 1 of call 1 did not replay")

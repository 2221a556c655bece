"""taxi(q_table, q_table_decay) (edition rl1): honest greedy play passes; each typical mistake is named."""

from typing import Any

import numpy as np
import pytest

from grader.lab.assignment import load_config
from grader.lab.checks.base import Verdict
from grader.lab.checks.taxi_tables import TaxiTablesConfig, grader_tables
from grader.lab.editions.rl1 import RL1
from grader.simulated_students import taxi_tables as students
from grader.simulated_students.simulation import simulate_calls
from reference.oracles import greedy_policy_return

from .support import deal_only_hard_starts

PROBLEM = RL1.registry.problem("taxi")


def _judge(function: Any, seed: int) -> Verdict:
    settings = load_config(RL1.default_config).problems["taxi"]
    assert isinstance(settings, TaxiTablesConfig)
    calls = PROBLEM.check.plan(settings, {}, 0)
    return PROBLEM.check.judge(settings, simulate_calls(calls, {"taxi": function}, seed))


def test_the_grader_tables_differ_clearly_and_always_end() -> None:
    detour, optimal = (greedy_policy_return(table) for table in grader_tables(0.6))
    # Regression snapshots of the exact oracle (the greedy returns are checked by simulation in
    # tests/reference/oracles/test_taxi_oracle.py); what this test holds is that they differ clearly.
    assert (round(detour.mean, 3), round(optimal.mean, 3)) == (5.757, 7.93)
    assert greedy_policy_return(grader_tables(0.6)[0], 1000).mean == pytest.approx(detour.mean)


def test_honest_greedy_play_passes(seed: int) -> None:
    verdict = _judge(students.honest, seed)
    assert verdict.status == "passed", verdict.feedback
    assert "every action was greedy on its table" in verdict.feedback


@pytest.mark.slow  # trains every mistaken table, tens of seconds each
@pytest.mark.parametrize(("name", "mistake"), students.MISTAKES.items(), ids=list(students.MISTAKES))
def test_each_mistake_fails_and_is_named(name: str, mistake: tuple[Any, str], seed: int) -> None:
    function, words = mistake
    verdict = _judge(function, seed)
    assert verdict.status == "failed", name
    assert words in verdict.feedback, verdict.feedback


def test_a_stub_is_missing(seed: int) -> None:
    def stub(_lab: Any, q_table: Any, q_table_decay: Any) -> None:
        raise NotImplementedError("Problem 6 incomplete")

    assert _judge(stub, seed).status == "missing"


def test_a_mean_off_its_tables_exact_one_fails_on_the_means_alone(seed: int) -> None:
    """q_table_decay's episodes dealt only the starts where its greedy return is at most 4 (a start law that
    is not the lab's, judged as played): every action greedy on its table, the means the replay's and in
    order, so only the z-tests of the means can fail it.

    Statistic: each table's mean total reward over 1000 greedy episodes against its exact mean (5.757 and
    7.930, alpha 1e-6 each, exact variances); the rigged starts average at most 4, far outside the optimal
    table's tolerance whatever they draw (a deterministic miss of 0).
    """

    def hard_starts(lab: Any, q_table: Any, q_table_decay: Any) -> tuple[float, float]:
        first = students._play(lab, q_table, students.EPISODES)
        env = lab.make("Taxi-v3")
        greedy = np.argmax(q_table_decay, axis=1)
        deal_only_hard_starts(env, greedy)
        totals = []
        for _ in range(students.EPISODES):
            state, _ = env.reset()
            total, done = 0.0, False
            while not done:
                state, reward, terminated, truncated, _ = env.step(int(greedy[state]))
                total, done = total + reward, terminated or truncated
            totals.append(total)
        return first, float(np.mean(totals))

    verdict = _judge(hard_starts, seed)
    assert verdict.status == "failed", verdict.feedback
    assert verdict.feedback.startswith("taxi: "), verdict.feedback
    assert "beyond the tolerance (false-fail probability 1e-06 each)" in verdict.feedback, verdict.feedback


@pytest.mark.parametrize("value", ["means", (5.7,), (5.7, None)], ids=["str", "one", "none"])
def test_a_call_that_returns_no_pair_of_numbers_fails(value: Any, seed: int) -> None:
    def returns(lab: Any, q_table: Any, q_table_decay: Any) -> Any:
        students.honest(lab, q_table, q_table_decay)
        return value

    verdict = _judge(returns, seed)
    assert verdict.status == "failed"
    assert "expected two numbers (mean total reward with q_table, with q_table_decay)" in verdict.feedback


def test_a_game_abandoned_before_the_tables_episodes_fails_the_integrity_check(seed: int) -> None:
    def abandons(lab: Any, q_table: Any, q_table_decay: Any) -> tuple[float, float]:
        env = lab.make("Taxi-v3")
        env.reset()
        env.step(0)
        return students.honest(lab, q_table, q_table_decay)

    verdict = _judge(abandons, seed)
    assert verdict.status == "failed"
    assert verdict.feedback.startswith("taxi: 1 game(s) were abandoned before they ended")

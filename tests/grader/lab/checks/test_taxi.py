"""taxi: planning by signature, finding both scenarios in the replay, and the greedy-policy check.

False-fail probability of each passing test: 3e-6 (two z-tests and one chi-square test at 1e-6).
"""

import numpy as np
import pytest

from grader.lab.checks.taxi import takes_q_table
from grader.lab.problems import PROBLEMS
from grader.sandbox.outcome import FunctionInfo, ParameterInfo
from grader.simulated_students.behaviours import taxi
from reference.oracles import optimal_q_table

from .support import grade, small_config


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
    (call,) = PROBLEMS.problem("taxi").check.plan(small_config("taxi"), functions)
    assert call.function == "taxi"
    if takes:
        np.testing.assert_array_equal(call.args[0], optimal_q_table(0.6))
    else:
        assert call.args == ()


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


def test_q_episodes_must_follow_the_given_table(seed: int) -> None:
    def worst_action(lab, q_table, episodes=200):  # type: ignore[no-untyped-def]
        return taxi(lab, -np.asarray(q_table), episodes=episodes)

    verdict = grade("taxi", {"taxi": worst_action}, seed)
    assert verdict.status == "failed"
    assert "act with np.argmax(q_table[state]) on the table you were given" in verdict.feedback


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

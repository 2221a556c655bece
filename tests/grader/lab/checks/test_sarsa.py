"""sarsa0(env, alpha, gamma, epsilon, N, decay) (edition rl1): honest learners pass; each mistake is named.

The behaviour test's false-fail probability is 1e-6 per call (two calls per judgement), so the honest
cases here fail falsely with probability below 1e-5 in all.
"""

from typing import Any

import numpy as np
import pytest

from grader.lab.assignment import load_config
from grader.lab.checks.base import Verdict
from grader.lab.checks.sarsa import SarsaConfig, returned_table
from grader.lab.editions.rl1 import RL1
from grader.sandbox.outcome import ENV_NAME_OR_OBJECT, EnvArgument
from grader.simulated_students import sarsa as students
from grader.simulated_students.simulation import Lab, simulate_calls

PROBLEM = RL1.registry.problem("sarsa0")


def _settings(**updates: Any) -> SarsaConfig:
    """The default settings with fewer episodes (the verdicts do not depend on them; the tests run faster)."""
    settings = load_config(RL1.default_config).problems["sarsa0"]
    assert isinstance(settings, SarsaConfig)
    return settings.model_copy(update={"episodes": 25, "decay_episodes": 10, **updates})


def _judge(function: Any, seed: int, decay: Any = students.epsilon_decay, **updates: Any) -> Verdict:
    settings = _settings(**updates)
    calls = PROBLEM.check.plan(settings, {}, 0)
    functions = {"sarsa0": function, "epsilon_decay": decay}
    return PROBLEM.check.judge(settings, simulate_calls(calls, functions, seed))


@pytest.mark.parametrize("name", list(students.HONEST))
def test_honest_learners_pass(name: str, seed: int) -> None:
    verdict = _judge(students.HONEST[name], seed)
    assert verdict.status == "passed", verdict.feedback
    assert "every update of your table is SARSA(0)'s" in verdict.feedback
    form = "object" if name == "object_form" else "name"
    assert verdict.measurements["env_form"] == form
    assert FORM_WORDS[form] in verdict.feedback


FORM_WORDS = {
    "name": "The grader called sarsa0 with the environment's name, 'Taxi-v3', as the template's `env = gym.make(env)` expects.",  # noqa: E501
    "object": "The grader called sarsa0 with an environment object, gym.make('Taxi-v3')",
}


def test_the_plan_passes_the_environments_name_first() -> None:
    call = PROBLEM.check.plan(_settings(), {}, 0)[0]
    (env,) = [argument for argument in call.args if isinstance(argument, EnvArgument)]
    assert (env.env_id, env.form, repr(env)) == ("Taxi-v3", ENV_NAME_OR_OBJECT, "'Taxi-v3'")


def test_a_template_shaped_learner_that_fails_after_making_the_env_keeps_the_names_error(seed: int) -> None:
    def broken(lab: Lab, env: Any, *args: Any) -> Any:
        env = lab.make(env)
        raise ValueError("after gym.make")

    verdict = _judge(broken, seed)
    assert verdict.status == "error"
    assert "ValueError: after gym.make" in verdict.feedback
    assert FORM_WORDS["name"] in verdict.feedback


@pytest.mark.parametrize(("name", "mistake"), students.MISTAKES.items(), ids=list(students.MISTAKES))
def test_each_mistake_fails_and_is_named(name: str, mistake: tuple[Any, str], seed: int) -> None:
    function, words = mistake
    verdict = _judge(function, seed)
    assert verdict.status == "failed", name
    assert words in verdict.feedback, verdict.feedback


def test_a_q_learning_update_names_the_first_wrong_cell(seed: int) -> None:
    verdict = _judge(students.MISTAKES["q_learning"][0], seed)
    assert verdict.feedback.startswith("sarsa0, the call with epsilon constant (N=25): at episode ")
    assert "SARSA(0) from the transitions you played gives" in verdict.feedback


def epsilon_decay_over_n_plus_1(
    lab: Lab, episode: int, n: int, start: float = 1.0, end: float = 1e-6
) -> float:
    """A wrong decay (divided by N + 1), graded in problem 5 and not again in sarsa0.

    Not the 0-based decay: it ends at epsilon 1e-6, and a near-greedy last episode on a table trained 10
    episodes can circle for millions of steps before it delivers (3.2 million at one seed of this test), which
    the sandbox's step budget would cut. That is a risk of such a schedule, not of this rule."""
    return start - (episode - 1) * (start - end) / (n + 1)


@pytest.mark.slow  # trains sarsa0 for real, minutes
def test_a_wrong_epsilon_decay_is_not_counted_again(seed: int) -> None:
    """The decay call is judged against the student's own schedule: problem 5 counts the mistake."""
    learner = students.learner(schedule=epsilon_decay_over_n_plus_1)
    verdict = _judge(learner, seed, decay=epsilon_decay_over_n_plus_1)
    assert verdict.status == "passed", verdict.feedback


def test_a_missing_epsilon_decay_leaves_the_constant_call_graded(seed: int) -> None:
    settings = _settings()
    calls = PROBLEM.check.plan(settings, {}, 0)
    records = simulate_calls(calls[:2], {"sarsa0": students.HONEST["lab_loop"]}, seed)
    verdict = PROBLEM.check.judge(settings, records)
    assert verdict.status == "passed", verdict.feedback
    assert "The decay=True call was not made" in verdict.feedback


@pytest.mark.parametrize(
    ("value", "found"),
    [
        (np.zeros((500, 5)), "an array of shape (500, 5)"),
        (np.full((500, 6), np.nan), "NaN or infinite"),
        ("table", "'table'"),
        ([[0.0] * 6] * 499, "[[0.0"),
        (np.zeros((500, 6), dtype=bool), "dtype bool"),
        ([[0.0] * 6] * 499 + [[0.0] * 5], "[[0.0"),
        ([["a"] * 6] + [[0.0] * 6] * 499, "[['a'"),
    ],
    ids=["shape", "nan", "str", "short-list", "bool", "short-row", "text-cells"],
)
def test_a_returned_value_that_is_no_table_is_refused(value: Any, found: str) -> None:
    table, _, wrong = returned_table(value)
    assert table is None
    assert found in wrong


def test_a_list_table_and_penalties_are_read() -> None:
    table, penalties, wrong = returned_table(([[1, 2, 3, 4, 5, 6]] * 500, 7))
    assert table is not None and table.shape == (500, 6) and penalties == 7 and wrong == ""


def test_an_epsilon_decay_returning_no_number_is_not_counted_again(seed: int) -> None:
    """sarsa0 crashes on the student's None epsilon; the decay call is dropped, the constant one graded."""

    def no_number(lab: Any, episode: int, n: int) -> None:
        return None

    def crashes_on_decay(
        lab: Any, env: Any, alpha: float, gamma: float, epsilon: float, n: int, decay: bool
    ) -> Any:
        if decay:
            raise TypeError("'<' not supported between instances of 'float' and 'NoneType'")
        return students.HONEST["lab_loop"](lab, env, alpha, gamma, epsilon, n, decay)

    verdict = _judge(crashes_on_decay, seed, decay=no_number)
    assert verdict.status == "passed", verdict.feedback
    assert "The decay=True call is not counted" in verdict.feedback


@pytest.mark.parametrize(
    ("name", "status", "words"),
    [
        ("lab_loop", "passed", "the decay=True call (N=10): "),
        ("ignores_decay", "failed", "you explored less than the decayed schedule asks"),
    ],
)
def test_with_the_grader_s_schedule_the_decay_call_s_exploration_is_judged(
    name: str, status: str, words: str, seed: int
) -> None:
    """decay_schedule = "grader": the decay call is judged against the lab's formula (no student values)."""
    learner = students.HONEST.get(name) or students.MISTAKES[name][0]
    verdict = _judge(learner, seed, decay_schedule="grader")
    assert verdict.status == status, verdict.feedback
    assert words in verdict.feedback
    assert "nan" not in verdict.feedback


def test_a_call_that_returns_no_table_fails_with_what_it_returned(seed: int) -> None:
    def returns_a_name(lab: Lab, *args: Any) -> Any:
        students.HONEST["lab_loop"](lab, *args)
        return "q_table"

    verdict = _judge(returns_a_name, seed)
    assert (verdict.status, verdict.feedback) == (
        "failed",
        "sarsa0 must return the Q-table, a finite 500 x 6 array (one row per Taxi state), or (table, "
        "penalties); the call with epsilon constant (N=25) returned 'q_table'. (The grader called sarsa0 "
        "with the environment's name, 'Taxi-v3', as the template's `env = gym.make(env)` expects.)",
    )


def test_a_game_abandoned_before_training_fails_the_integrity_check(seed: int) -> None:
    def abandons_a_game(lab: Lab, env: Any, *args: Any) -> Any:
        game = lab.make(env)
        game.reset()
        game.step(0)  # then on to training, the game left unfinished
        return students.HONEST["lab_loop"](lab, env, *args)

    verdict = _judge(abandons_a_game, seed)
    assert verdict.status == "failed"
    assert verdict.feedback.startswith(
        "sarsa0, the call with epsilon constant (N=25): 1 game(s) were abandoned before they ended"
    )


def test_a_missing_sarsa0_is_missing_with_the_sandbox_s_message_alone(seed: int) -> None:
    settings = _settings()
    calls = PROBLEM.check.plan(settings, {}, 0)
    verdict = PROBLEM.check.judge(
        settings, simulate_calls(calls, {"epsilon_decay": students.epsilon_decay}, seed)
    )
    assert verdict.status == "missing"
    assert "The grader called sarsa0" not in verdict.feedback


def test_exploring_more_than_epsilon_is_named(seed: int) -> None:
    def explores_at_half(lab: Lab, env: Any, alpha: float, gamma: float, _epsilon: float, *rest: Any) -> Any:
        return students.HONEST["lab_loop"](lab, env, alpha, gamma, 0.5, *rest)

    verdict = _judge(explores_at_half, seed)
    assert verdict.status == "failed"
    assert "you explored more than epsilon asks" in verdict.feedback


def test_a_decay_call_without_the_student_s_schedule_is_judged_on_its_updates_alone(seed: int) -> None:
    """epsilon_decay returns no number but sarsa0 decays on its own: the decay call's table is verified,
    its exploration is not judged (no schedule to judge it against)."""

    def no_number(lab: Any, episode: int, n: int) -> None:
        return None

    verdict = _judge(students.HONEST["lab_loop"], seed, decay=no_number)
    assert verdict.status == "passed", verdict.feedback
    assert verdict.measurements["decay_updates"] > 0
    assert np.isnan(verdict.measurements["decay_tolerance"])

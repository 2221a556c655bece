"""compare() (edition rl1): after the notebook's cells, honest play passes and each mistake is named."""

import dataclasses
from typing import Any

import numpy as np
import pytest

from grader.lab.assignment import load_config
from grader.lab.checks.base import CallRecord, Verdict
from grader.lab.checks.compare import NOT_GRADABLE, CompareConfig, NotebookTable
from grader.lab.checks.compare_tables import bound_tables
from grader.lab.editions.rl1 import RL1
from grader.sandbox.child.cells import RUN_CELLS, NotAttemptedError, NotebookCellError
from grader.sandbox.outcome import IMPORT_TIMEOUT, OutcomeStatus
from grader.simulated_students import compare as students
from grader.simulated_students.simulation import simulate_calls
from grader.submission.notebook.cells import RAN_CELLS
from reference.oracles import greedy_policy_return

from .support import deal_only_hard_starts

PROBLEM = RL1.registry.problem("compare")


def _settings(**fields: Any) -> CompareConfig:
    settings = load_config(RL1.default_config).problems["compare"]
    assert isinstance(settings, CompareConfig)
    data = {**settings.model_dump(), "points": 1.0, "run_cells": True, **fields}
    return CompareConfig.model_validate(data).for_problem("compare", PROBLEM.games)


def _judge(function: Any, seed: int, cells: Any = students.binds, **fields: Any) -> Verdict:
    settings = _settings(**fields)
    calls = PROBLEM.check.plan(settings, {}, 0)
    return PROBLEM.check.judge(settings, simulate_calls(calls, {RUN_CELLS: cells, "compare": function}, seed))


def test_the_plan_runs_the_cells_with_their_own_limit_then_records_compare() -> None:
    cells, compare = PROBLEM.check.plan(_settings(cells_seconds=123.0, bind_tables=False), {}, 0)
    assert (cells.function, cells.seconds, cells.record_episodes) == (RUN_CELLS, 123.0, False)
    assert cells.kwargs == {"then": "compare"}  # a missing or stub compare() runs no cell
    assert (compare.function, compare.seconds, compare.record_episodes) == ("compare", None, True)


def test_by_default_the_cells_call_carries_the_seeds_tables_to_bind() -> None:
    cells, _ = PROBLEM.check.plan(_settings(cells_seconds=123.0), {}, 7)
    assert (cells.function, cells.seconds, cells.kwargs["then"]) == (RUN_CELLS, 123.0, "compare")
    assert cells.kwargs["bind"] is bound_tables(7)  # the fallback runs the cells within the same limit
    assert CompareConfig.model_fields["bind_tables"].default is True


def test_the_default_configuration_runs_the_cells_for_its_points() -> None:
    settings = load_config(RL1.default_config).problems["compare"]
    assert isinstance(settings, CompareConfig)
    assert (settings.run_cells, settings.points) == (True, 1.0)
    assert CompareConfig.model_fields["run_cells"].default is True


def test_without_run_cells_compare_is_not_gradable_and_worth_nothing() -> None:
    settings = _settings(run_cells=False)
    assert (settings.run_cells, settings.points) == (False, 0.0)
    assert PROBLEM.check.plan(settings, {}, 0) == []
    verdict = PROBLEM.check.judge(settings, [])
    assert (verdict.status, verdict.fraction, verdict.feedback) == ("skipped", 0.0, NOT_GRADABLE)


def test_with_run_cells_the_configured_points_stand() -> None:
    assert _settings(points=2.0).points == 2.0


def test_accepted_envs_are_taxis() -> None:
    with pytest.raises(ValueError, match="accepted_envs must be a non-empty list of"):
        _settings(accepted_envs=["CartPole-v1"])


@pytest.mark.parametrize("function", [students.honest, students.sarsa_first], ids=["honest", "sarsa_first"])
def test_honest_play_on_bound_tables_passes_and_says_what_was_bound(function: Any, seed: int) -> None:
    verdict = _judge(function, seed)
    assert verdict.status == "passed", verdict.feedback
    assert verdict.feedback.startswith(
        "Bound the grader's own Taxi tables (drawn from the grading seed, exact greedy returns known) to the globals compare() reads instead of running your training"  # noqa: E501
    )
    assert (
        '`q_table_decay` <- the Q-learning table (as your `q_table_decay, _ = qlearn("Taxi-v3", decay=True)` in cell 20 sets it)'  # noqa: E501
        in verdict.feedback
    )
    assert "`sarsa_table_decay` (bound for sarsa0(decay=True, N=70000))" in verdict.feedback
    assert verdict.measurements["tables_bound"] == 3  # q_table's too: a training statement sets it
    assert verdict.measurements["cells_run"] == 0
    assert verdict.measurements[RAN_CELLS] is True


@pytest.mark.parametrize("function", [students.honest, students.sarsa_first], ids=["honest", "sarsa_first"])
def test_honest_play_after_every_cell_ran_passes_and_says_what_ran(function: Any, seed: int) -> None:
    verdict = _judge(function, seed, students.cells, bind_tables=False)
    assert verdict.status == "passed", verdict.feedback
    assert verdict.feedback.startswith(
        "Ran your notebook's 4 code cells in the sandbox (within the limit of 1800 s), then called compare()"
    )
    assert "`q_table_decay` (from qlearn(decay=True, N=70000))" in verdict.feedback
    assert verdict.measurements[RAN_CELLS] is True


def test_the_bound_tables_are_the_plans_whatever_the_child_sends(seed: int) -> None:
    def forged(lab: Any, *args: Any, bind: Any, **kwargs: Any) -> dict[str, Any]:
        value = students.binds(lab, *args, bind=bind, **kwargs)
        return {**value, "tables": [{"names": ["x"], "learner": "qlearn", "table": np.zeros((500, 6))}]}

    settings = _settings()
    calls = PROBLEM.check.plan(settings, {}, 5)
    records = simulate_calls(calls, {RUN_CELLS: forged, "compare": students.honest}, seed)
    verdict = PROBLEM.check.judge(settings, records)
    assert verdict.status == "passed", verdict.feedback
    assert verdict.measurements["exact_q_mean"] == pytest.approx(
        greedy_policy_return(bound_tables(5)["qlearn"]["decay"]).mean
    )


def test_a_fallback_says_why_the_cells_ran(seed: int) -> None:
    def fell_back(lab: Any, *args: Any, **kwargs: Any) -> dict[str, Any]:
        return {
            **students.cells(lab),
            "fallback": "compare() calls qlearn() itself, so it trains its own tables",
        }

    verdict = _judge(students.honest, seed, fell_back)
    assert verdict.status == "passed", verdict.feedback
    assert verdict.feedback.startswith(
        "The grader's tables could not stand in for your training: compare() calls qlearn() itself, so it trains its own tables. "  # noqa: E501
        "Ran your notebook's 4 code cells in the sandbox"
    )
    assert verdict.measurements["tables_bound"] == 0


@pytest.mark.slow  # trains every mistaken table, tens of seconds each
@pytest.mark.parametrize("bind", [True, False], ids=["bound", "cells_ran"])
@pytest.mark.parametrize(("name", "mistake"), students.MISTAKES.items(), ids=list(students.MISTAKES))
def test_each_mistake_fails_and_is_named(name: str, mistake: tuple[Any, str], bind: bool, seed: int) -> None:
    function, words = mistake
    verdict = _judge(function, seed, students.binds if bind else students.cells, bind_tables=bind)
    assert verdict.status == "failed", name
    assert words in verdict.feedback, verdict.feedback


def _raising(error: BaseException) -> Any:
    def cells(_lab: Any, *_args: Any, **_kwargs: Any) -> None:
        raise error

    return cells


@pytest.mark.parametrize(
    ("error", "status", "words"),
    [
        (NotebookCellError("cell 8 (line 5) raised NameError: name 'sarsa' is not defined"), "error",
         "as Restart & Run All does: cell 8 (line 5) raised NameError: name 'sarsa' is not defined, so the run stopped there"),  # noqa: E501
        (NotebookCellError("cell 9 (line 2) raised NotImplementedError: Problem 7 incomplete"), "missing",
         "cell 9 (line 2) raised NotImplementedError: Problem 7 incomplete, so compare() was not called: not attempted yet"),  # noqa: E501
        (NotAttemptedError("`compare` is still the template's stub (its body only raises NotImplementedError), so the cells were not run"), "missing",  # noqa: E501
         "so the cells were not run: not attempted yet"),
    ],
    ids=["cell_error", "stub_in_a_cell", "compare_a_stub"],
)  # fmt: skip
def test_a_failing_cell_is_the_result(error: BaseException, status: str, words: str, seed: int) -> None:
    verdict = _judge(students.honest, seed, cells=_raising(error))
    assert (verdict.status, verdict.fraction) == (status, 0.0)
    assert words in verdict.feedback, verdict.feedback


def test_cells_out_of_time_are_a_timeout() -> None:
    settings = _settings(cells_seconds=30.0)
    calls = PROBLEM.check.plan(settings, {}, 0)
    records = simulate_calls(calls[:1], {RUN_CELLS: students.cells}, 1)
    outcome = records[0].outcome
    timed_out = type(records[0])(
        type(outcome)(**{**outcome.__dict__, "status": OutcomeStatus.TIMEOUT, "value": None}), []
    )
    verdict = PROBLEM.check.judge(settings, [timed_out])
    assert verdict.status == "timeout"
    assert "did not finish within 30 seconds" in verdict.feedback


def test_a_notebook_without_tables_fails_with_what_to_do(seed: int) -> None:
    def no_tables(_lab: Any, *_args: Any, **_kwargs: Any) -> dict[str, Any]:
        return {"cells": [{"cell": 2, "seconds": 0.1}], "tables": []}

    verdict = _judge(students.honest, seed, cells=no_tables)
    assert verdict.status == "failed"
    assert "left no Taxi Q-table" in verdict.feedback


def test_a_forged_cells_value_is_read_defensively(seed: int) -> None:
    def forged(_lab: Any, *_args: Any, **_kwargs: Any) -> Any:
        return {"cells": "many", "tables": [{"table": [[1, 2]]}, 5, {"table": "x" * 10}]}

    verdict = _judge(students.honest, seed, cells=forged)
    assert verdict.status == "failed"
    assert "left no Taxi Q-table" in verdict.feedback


def _untrained(cell: int) -> Any:
    def cells(_lab: Any, *_args: Any, **_kwargs: Any) -> dict[str, Any]:
        return {"cells": [{"cell": cell, "seconds": 0.5}], "tables": []}

    return cells


def _reads_missing_globals(_lab: Any) -> Any:
    raise NameError("name 'q_table_decay' is not defined")


@pytest.mark.parametrize(
    ("cell", "words"),
    [
        (0, "Run as a script, your file left no Taxi Q-table for compare() to play"),
        (3, "Your notebook's cells left no Taxi Q-table for compare() to play"),
    ],
    ids=["module", "notebook"],
)
def test_a_submission_that_trains_no_table_fails_saying_where_to_train(
    cell: int, words: str, seed: int
) -> None:
    verdict = _judge(_reads_missing_globals, seed, cells=_untrained(cell))
    assert verdict.status == "failed"
    assert "compare() raised NameError: name 'q_table_decay' is not defined" in verdict.feedback
    assert words in verdict.feedback
    assert 'sarsa_table_decay = sarsa0("Taxi-v3", decay=True)' in verdict.feedback


def test_a_mean_off_its_tables_exact_one_fails_on_the_means_alone(seed: int) -> None:
    """The SARSA table's episodes dealt only the starts where its greedy return is at most 4 (a start law
    that is not the lab's, judged as played): both tables the notebook's, every action greedy, the means the
    replay's and in order, so only the z-tests of the means can fail it.

    Statistic: each table's mean total reward over 1000 greedy episodes against its exact greedy return
    (alpha 1e-6 each, exact variances); the rigged starts average at most 4, below the SARSA table's
    tolerance whatever they draw (a deterministic miss of 0).
    """

    def hard_starts(lab: Any) -> tuple[float, float]:
        q_table, sarsa_table = students._tables()
        first = students._play(lab, q_table, students.EPISODES)
        env = lab.make("Taxi-v3")
        greedy = np.argmax(sarsa_table, axis=1)
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
    assert verdict.feedback.endswith(
        "a mean beyond its tolerance (false-fail probability 1e-06 each) means the episodes were not played "
        "from env.reset() without a seed until they ended."
    ), verdict.feedback


def _records(compare: Any, seed: int, cells: Any = students.cells) -> tuple[CompareConfig, list[CallRecord]]:
    settings = _settings()
    calls = PROBLEM.check.plan(settings, {}, 0)
    return settings, simulate_calls(calls, {RUN_CELLS: cells, "compare": compare}, seed)


def test_cells_without_a_compare_call_are_an_error(seed: int) -> None:
    settings, records = _records(students.honest, seed)
    verdict = PROBLEM.check.judge(settings, records[:1])
    assert verdict.status == "error"
    assert verdict.feedback.endswith("then called compare(); compare() was not called.")


def test_a_compare_over_its_game_budget_is_told_to_play_the_trained_tables(seed: int) -> None:
    settings, records = _records(students.honest, seed)
    outcome = dataclasses.replace(records[1].outcome, status=OutcomeStatus.EPISODE_LIMIT, value=None)
    verdict = PROBLEM.check.judge(settings, [records[0], CallRecord(outcome, records[1].replays)])
    assert verdict.status == "failed"
    assert "training inside compare() plays thousands of games (the cells left `q_table_decay`" in (
        verdict.feedback
    )


def test_a_compare_that_raises_with_tables_left_is_an_error(seed: int) -> None:
    def raises(_lab: Any) -> Any:
        raise ValueError("no means today")

    verdict = _judge(raises, seed)
    assert verdict.status == "error"
    assert "ValueError: no means today" in verdict.feedback
    assert "left no Taxi Q-table" not in verdict.feedback


@pytest.mark.parametrize("value", ["means", (1.0,), (1.0, None)], ids=["str", "one", "none"])
def test_a_compare_that_returns_no_pair_of_numbers_fails(value: Any, seed: int) -> None:
    def returns(lab: Any) -> Any:
        students.honest(lab)
        return value

    verdict = _judge(returns, seed)
    assert verdict.status == "failed"
    assert "expected two numbers (mean total reward with the Q-learning table, with the SARSA table)" in (
        verdict.feedback
    )


def test_a_game_abandoned_in_compare_fails_the_integrity_check(seed: int) -> None:
    def abandons(lab: Any) -> tuple[float, float]:
        env = lab.make("Taxi-v3")
        env.reset()
        env.step(0)
        return students.honest(lab)

    verdict = _judge(abandons, seed)
    assert verdict.status == "failed"
    assert "1 game(s) were abandoned before they ended" in verdict.feedback


@pytest.mark.parametrize(
    "value",
    [
        ["not", "a", "dict"],
        {"cells": [{"cell": 2}], "tables": [{"names": ["q"], "table": np.full((500, 6), np.nan)}]},
    ],
    ids=["not-a-dict", "nan-table"],
)
def test_cells_values_that_leave_no_usable_table(value: Any, seed: int) -> None:
    verdict = _judge(students.honest, seed, cells=lambda *_args, **_kwargs: value)
    assert verdict.status == "failed"
    assert "your cells left no Taxi Q-table (a 500 x 6 array)" in verdict.feedback


def test_a_file_that_does_not_import_in_time_keeps_the_runner_s_message() -> None:
    settings = _settings()
    calls = PROBLEM.check.plan(settings, {}, 0)
    records = simulate_calls(calls[:1], {RUN_CELLS: students.cells}, 1)
    message = f"{IMPORT_TIMEOUT} 60 s: move the training under `if __name__ == '__main__':`"
    outcome = dataclasses.replace(
        records[0].outcome, status=OutcomeStatus.TIMEOUT, value=None, message=message
    )
    verdict = PROBLEM.check.judge(settings, [CallRecord(outcome, [])])
    assert (verdict.status, verdict.feedback) == ("timeout", message)


@pytest.mark.parametrize(
    ("names", "learner", "decay", "episodes", "label"),
    [
        (("q_table",), None, None, None, "`q_table`"),
        ((), None, True, 10, "a table"),
        (("a", "b"), "sarsa0", None, None, "`a` / `b` (from sarsa0())"),
        (("q",), "qlearn", False, 5, "`q` (from qlearn(decay=False, N=5))"),
    ],
    ids=["name-only", "nameless", "learner-only", "learner-and-arguments"],
)
def test_a_table_is_labelled_by_its_names_and_learner_call(
    names: tuple[str, ...], learner: str | None, decay: bool | None, episodes: int | None, label: str
) -> None:
    table = NotebookTable(names, learner, decay, episodes, np.zeros((500, 6)))
    assert table.label == label


def test_two_decayed_tables_of_one_learner_are_no_constant_epsilon_table(seed: int) -> None:
    """A notebook that kept a copy of its decayed Q-learning table (two decay=True tables of qlearn)."""

    def cells_with_a_copy(*args: Any, **kwargs: Any) -> dict[str, Any]:
        value = students.cells(*args, **kwargs)
        copy = {**value["tables"][0], "names": ["q_table_decay_copy"]}
        return {**value, "tables": [*value["tables"], copy]}

    verdict = _judge(students.honest, seed, cells=cells_with_a_copy)
    assert verdict.status == "passed", verdict.feedback


@pytest.mark.slow  # grades a notebook three times through the sandbox
def test_bound_tables_make_the_same_report_for_the_same_bytes_and_seed(tmp_path: Any) -> None:
    from pathlib import Path

    from grader.grading.grade import grade_files
    from grader.grading.plan import GradingPlan
    from grader.sandbox import IsolationPolicy

    notebook = Path(__file__).parents[4] / "submissions" / "editions" / "compare_honest.ipynb"
    plan = GradingPlan.load(RL1.default_config, ["compare"])

    def grade(seed: int) -> Any:
        (report,) = grade_files([notebook], plan, seed=seed, workers=1, policy=IsolationPolicy.ALLOW_FALLBACK)
        return report

    first, again, other = grade(5), grade(5), grade(6)
    assert first.problems[0].status == "passed", first.problems[0].feedback
    assert first.graded_view() == again.graded_view()
    assert first.problems[0].measurements["tables_bound"] == 2
    exact = first.problems[0].measurements["exact_q_mean"], other.problems[0].measurements["exact_q_mean"]
    assert exact[0] != exact[1]  # another seed, other tables

"""compare() (edition rl1): after the notebook's cells, honest play passes and each mistake is named."""

from typing import Any

import numpy as np
import pytest

from grader.lab.assignment import load_config
from grader.lab.checks.base import Verdict
from grader.lab.checks.compare import NOT_GRADABLE, CompareConfig
from grader.lab.editions.rl1 import RL1
from grader.sandbox.child.cells import RUN_CELLS, NotAttemptedError, NotebookCellError
from grader.sandbox.outcome import OutcomeStatus
from grader.simulated_students import compare as students
from grader.simulated_students.simulation import simulate_calls
from grader.submission.notebook.cells import RAN_CELLS

from .support import deal_only_hard_starts

PROBLEM = RL1.registry.problem("compare")


def _settings(**fields: Any) -> CompareConfig:
    settings = load_config(RL1.default_config).problems["compare"]
    assert isinstance(settings, CompareConfig)
    data = {**settings.model_dump(), "points": 1.0, "run_cells": True, **fields}
    return CompareConfig.model_validate(data).for_problem("compare", PROBLEM.games)


def _judge(function: Any, seed: int, cells: Any = students.cells) -> Verdict:
    settings = _settings()
    calls = PROBLEM.check.plan(settings, {}, 0)
    return PROBLEM.check.judge(settings, simulate_calls(calls, {RUN_CELLS: cells, "compare": function}, seed))


def test_the_plan_runs_the_cells_with_their_own_limit_then_records_compare() -> None:
    cells, compare = PROBLEM.check.plan(_settings(cells_seconds=123.0), {}, 0)
    assert (cells.function, cells.seconds, cells.record_episodes) == (RUN_CELLS, 123.0, False)
    assert cells.kwargs == {"then": "compare"}  # a missing or stub compare() runs no cell
    assert (compare.function, compare.seconds, compare.record_episodes) == ("compare", None, True)


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
def test_honest_play_passes_and_says_what_ran(function: Any, seed: int) -> None:
    verdict = _judge(function, seed)
    assert verdict.status == "passed", verdict.feedback
    assert verdict.feedback.startswith(
        "Ran your notebook's 4 code cells in the sandbox (within the limit of 1800 s), then called compare()"
    )
    assert "`q_table_decay` (from qlearn(decay=True, N=70000))" in verdict.feedback
    assert verdict.measurements[RAN_CELLS] is True


@pytest.mark.slow  # trains every mistaken table, tens of seconds each
@pytest.mark.parametrize(("name", "mistake"), students.MISTAKES.items(), ids=list(students.MISTAKES))
def test_each_mistake_fails_and_is_named(name: str, mistake: tuple[Any, str], seed: int) -> None:
    function, words = mistake
    verdict = _judge(function, seed)
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
